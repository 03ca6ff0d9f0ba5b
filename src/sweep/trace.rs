//! One run of a sweep: the scenario stepped from frame 0 to its last frame by
//! [`Simulation`], as `ricochet run` steps it, keeping what the error measures need per frame
//! (named bodies' positions, the energy, the touching pairs, the touch events), the final
//! digest, and the wall time per step (timed on runs that keep nothing).

use std::time::Instant;

use ricochet_geom::Vec2;
use ricochet_sim::{BodyKind, Entity, FrameOutput, GameEvent, Scenario, Simulation};

use super::time::Ratio;

/// A touch beginning or ending, by the bodies' names (sorted).
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct Touch {
    /// `true` for a begin, `false` for an end.
    pub begin: bool,
    /// The two names, in order.
    pub names: (String, String),
}

/// What one frame's end holds.
#[derive(Clone, Debug, Default)]
pub struct Sample {
    /// Every moving (dynamic or kinematic) body whose name no other living body has, by
    /// name: such a body is the same body in two runs whatever ids their spawns took.
    pub bodies: Vec<(String, Vec2)>,
    /// Mechanical energy of the dynamic bodies: `Σ m v²/2 − m s (g · p)` (`s` the body's
    /// gravity scale); constant forces and controllers are not in it.
    pub energy: f64,
    /// The pairs in contact in the frame, by names (each sorted), sorted: those with a
    /// contact record in it (a `destroy` pair's last frame too) and those still touching
    /// at its end.
    pub touching: Vec<(String, String)>,
}

/// A whole run.
#[derive(Clone, Debug)]
pub struct Trace {
    /// Its timestep.
    pub dt: Ratio,
    /// Frame `k`'s sample at index `k` (frame 0 is the initial state).
    pub samples: Vec<Sample>,
    /// The touch events, with the frame they happened in, in order.
    pub touches: Vec<(u64, Touch)>,
    /// [`ricochet_sim::World::digest`] at the end.
    pub digest: u64,
    /// Median wall seconds per step over the timed runs.
    pub step_seconds: f64,
}

fn pair(a: &str, b: &str) -> (String, String) {
    if a <= b {
        (a.to_owned(), b.to_owned())
    } else {
        (b.to_owned(), a.to_owned())
    }
}

fn sample(sim: &Simulation, out: &FrameOutput) -> Sample {
    let world = sim.world();
    let g = sim.scenario().world.gravity;
    let mut energy = 0.0;
    let mut named: Vec<(String, Vec2)> = Vec::new();
    let mut counts: std::collections::BTreeMap<&str, u32> = std::collections::BTreeMap::new();
    for &e in &world.entity {
        let name = sim.name(e).unwrap_or("");
        *counts.entry(name).or_default() += 1;
    }
    for &e in &world.entity {
        let (Some(kind), Some(p), Some(name)) = (sim.kind(e), sim.position(e), sim.name(e)) else {
            continue;
        };
        if kind == BodyKind::Dynamic {
            let (m, v, s) = (
                sim.mass(e).unwrap_or(0.0),
                sim.velocity(e).unwrap_or(Vec2::ZERO),
                sim.gravity_scale(e).unwrap_or(1.0),
            );
            energy += 0.5 * m * v.length_squared() - m * s * (g.x * p.x + g.y * p.y);
        }
        if kind != BodyKind::Static && counts.get(name) == Some(&1) {
            named.push((name.to_owned(), p));
        }
    }
    named.sort_by(|a, b| a.0.cmp(&b.0));
    let mut touching: Vec<(String, String)> = sim
        .touching()
        .iter()
        .copied()
        .chain(out.contacts.iter().map(|c| (c.a, c.b)))
        .map(|(a, b)| pair(&name_of(sim, out, a), &name_of(sim, out, b)))
        .collect();
    touching.sort();
    // A pair is in contact or not: once per frame, whatever its records.
    touching.dedup();
    Sample {
        bodies: named,
        energy,
        touching,
    }
}

/// A body's name; one removed this frame is only in `removed`, and a contact or a touch's
/// end can name it.
fn name_of(sim: &Simulation, out: &FrameOutput, e: Entity) -> String {
    sim.name(e).map_or_else(
        || {
            out.removed
                .iter()
                .find(|r| r.entity == e)
                .map(|r| r.name.clone())
                .unwrap_or_default()
        },
        str::to_owned,
    )
}

/// Runs `scenario` (frames 0 to `scenario.frames`) `timed` times for the wall time, then
/// once more keeping every frame's sample.
#[must_use]
pub fn run(scenario: &Scenario, dt: Ratio, timed: u32) -> Trace {
    let mut times = Vec::new();
    for _ in 0..timed {
        let mut sim = Simulation::new(scenario);
        let start = Instant::now();
        for _ in 0..=scenario.frames {
            std::hint::black_box(sim.step());
        }
        times.push(start.elapsed().as_secs_f64() / (scenario.frames + 1) as f64);
    }
    times.sort_by(f64::total_cmp);
    let step_seconds = times.get(times.len() / 2).copied().unwrap_or(f64::NAN);

    let mut sim = Simulation::new(scenario);
    let mut samples = Vec::with_capacity(usize::try_from(scenario.frames + 1).unwrap_or(0));
    let mut touches = Vec::new();
    for _ in 0..=scenario.frames {
        let out = sim.step();
        let name = |e: Entity| name_of(&sim, &out, e);
        for ev in &out.events {
            let (begin, a, b) = match ev {
                GameEvent::TouchBegin { a, b, .. } => (true, a, b),
                GameEvent::TouchEnd { a, b } => (false, a, b),
                _ => continue,
            };
            touches.push((
                out.frame,
                Touch {
                    begin,
                    names: pair(&name(*a), &name(*b)),
                },
            ));
        }
        samples.push(sample(&sim, &out));
    }
    Trace {
        dt,
        samples,
        touches,
        digest: sim.world().digest(),
        step_seconds,
    }
}
