//! One simulation of a sweep, stepped from frame 0 to its last frame by [`Simulation`] as
//! `ricochet run` steps it: what the error measures need at a frame (named bodies'
//! positions, the energy, the touching pairs, the touch events), the stop at the first
//! overflow (`Simulation::first_non_finite`, as `run` stops), and the wall time per step
//! (timed on runs that keep nothing). Nothing is kept per frame: the comparison
//! ([`super::compare`]) takes each frame as it comes.

use std::time::Instant;

use ricochet_geom::Vec2;
use ricochet_sim::{BodyKind, Entity, FrameOutput, GameEvent, Scenario, Simulation};
use serde::{Deserialize, Serialize};

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
    /// Mechanical energy of the dynamic bodies ([`energy`]).
    pub energy: f64,
    /// The pairs in contact in the frame, by names (each sorted), sorted: those with a
    /// contact record in it (a `destroy` pair's last frame too) and those still touching
    /// at its end.
    pub touching: Vec<(String, String)>,
}

/// Where and how a run overflowed: it stops there, as `ricochet run` stops, and is not
/// measured.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Overflow {
    /// The frame whose state (or energy) is not finite.
    pub frame: u64,
    /// What is not finite (`ricochet_record::session::describe`'s words).
    pub what: String,
}

fn pair(a: &str, b: &str) -> (String, String) {
    if a <= b {
        (a.to_owned(), b.to_owned())
    } else {
        (b.to_owned(), a.to_owned())
    }
}

/// Mechanical energy of the dynamic bodies: `Σ m v²/2 − m s (g · p)` (`s` the body's
/// gravity scale); constant forces and controllers are not in it.
fn energy(sim: &Simulation) -> f64 {
    let g = sim.scenario().world.gravity;
    let mut energy = 0.0;
    for &e in &sim.world().entity {
        if sim.kind(e) != Some(BodyKind::Dynamic) {
            continue;
        }
        // Only a named body, as the position samples take.
        let (Some(p), Some(_), m, v, s) = (
            sim.position(e),
            sim.name(e),
            sim.mass(e).unwrap_or(0.0),
            sim.velocity(e).unwrap_or(Vec2::ZERO),
            sim.gravity_scale(e).unwrap_or(1.0),
        ) else {
            continue;
        };
        energy += 0.5 * m * v.length_squared() - m * s * (g.x * p.x + g.y * p.y);
    }
    energy
}

fn sample(sim: &Simulation, out: &FrameOutput) -> Sample {
    let world = sim.world();
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
        energy: energy(sim),
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

/// One frame as the comparison sees it.
pub struct Frame {
    /// Its touch events, in order.
    pub touches: Vec<Touch>,
    /// Its sample, when asked for.
    pub sample: Option<Sample>,
}

/// A simulation stepped one frame at a time to `scenario.frames`, stopping at the first
/// overflow.
pub struct Stepper {
    sim: Simulation,
    next: u64,
    last: u64,
    /// The first sample whose energy is not finite, while the state is.
    energy_overflow: Option<Overflow>,
}

impl Stepper {
    /// A run of `scenario` (frames 0 to `scenario.frames`).
    #[must_use]
    pub fn new(scenario: &Scenario) -> Stepper {
        Stepper {
            sim: Simulation::new(scenario),
            next: 0,
            last: scenario.frames,
            energy_overflow: None,
        }
    }

    /// The frame the next [`Stepper::step`] makes, if the run has one.
    #[must_use]
    pub fn next_frame(&self) -> Option<u64> {
        (self.next <= self.last).then_some(self.next)
    }

    /// Steps one frame; with its sample when `sampled`. An overflow of the state is an
    /// error: nothing after it is measured. The energy of a sample overflowing is kept
    /// ([`Stepper::finish`]).
    pub fn step(&mut self, sampled: bool) -> Result<Frame, Overflow> {
        let out = self.sim.step();
        self.next += 1;
        if let Some(bad) = self.sim.first_non_finite_after(&out) {
            return Err(Overflow {
                frame: out.frame,
                what: crate::validate::describe(&self.sim, &bad),
            });
        }
        let sample = sampled.then(|| sample(&self.sim, &out));
        if let Some(s) = sample.as_ref().filter(|s| !s.energy.is_finite())
            && self.energy_overflow.is_none()
        {
            // The measure overflowed, not (yet) the simulation: the run goes on, so that
            // an overflow of its state is named as `ricochet run` names it.
            self.energy_overflow = Some(Overflow {
                frame: out.frame,
                what: format!(
                    "the energy Σ m v²/2 − m s g·p is not finite ({:e})",
                    s.energy
                ),
            });
        }
        let mut touches = Vec::new();
        for ev in &out.events {
            let (begin, a, b) = match ev {
                GameEvent::TouchBegin { a, b, .. } => (true, a, b),
                GameEvent::TouchEnd { a, b } => (false, a, b),
                _ => continue,
            };
            touches.push(Touch {
                begin,
                names: pair(&name_of(&self.sim, &out, *a), &name_of(&self.sim, &out, *b)),
            });
        }
        Ok(Frame { touches, sample })
    }

    /// The run's final digest ([`ricochet_sim::World::digest`]), or where its energy
    /// overflowed: a run whose measure overflowed is not measured either.
    pub fn finish(self) -> Result<u64, Overflow> {
        match self.energy_overflow {
            Some(o) => Err(o),
            None => Ok(self.sim.world().digest()),
        }
    }
}

/// Median wall seconds per step over `timed` runs of `scenario` (frames 0 to
/// `scenario.frames`) that keep nothing; NaN when `timed` is 0.
#[must_use]
pub fn time(scenario: &Scenario, timed: u32) -> f64 {
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
    times.get(times.len() / 2).copied().unwrap_or(f64::NAN)
}
