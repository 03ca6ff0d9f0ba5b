//! Shared by the `cull` and `sleep` tests: a busy scene of every kind of body, and running
//! a scene with and without a feature side by side.
//!
//! Both features are optimisations: they must never change what happens to a body that is
//! simulated. So the expected values come from the same scene run without the feature
//! (frame by frame, digest by digest), or from exact arithmetic on the same `f64` operations
//! the stages do (semi-implicit Euler: `x += v * dt`, frame 0 does not move).
#![allow(dead_code, reason = "each test file uses its own part of the helpers")]

use ricochet_sim::broad_phase::{BodyEntry, Interactions};
use ricochet_sim::{
    BodyKind, FrameOutput, GameEvent, Phase, Response, Simulation, StageSet, Stats, load_scenario,
};

pub fn sim(text: &str) -> Simulation {
    let s = load_scenario(text, "rest.toml").unwrap_or_else(|e| panic!("{e}\n{text}"));
    Simulation::new(&s)
}

/// The stats without the stage lists (a run with `cull` or `sleep` lists that stage).
pub fn stats_without_stages(s: &Stats) -> Stats {
    Stats {
        stages_run: StageSet::EMPTY,
        stages_skipped: StageSet::EMPTY,
        ..s.clone()
    }
}

/// `World::active` is documented as the moving bodies that are neither frozen nor asleep.
pub fn active_as_documented(sim: &Simulation) -> Vec<u32> {
    let w = sim.world();
    w.movers()
        .iter()
        .copied()
        .filter(|&i| !w.frozen(i as usize) && !w.asleep(i as usize))
        .collect()
}

/// Steps both simulations `frames + 1` times (frames 0 to `frames`) and asserts that every
/// frame ends with the same world digest, contacts, events and removed bodies.
/// `check` sees each frame's two outputs and simulations (plain first, feature second).
pub fn run_side_by_side(
    plain: &mut Simulation,
    featured: &mut Simulation,
    frames: u64,
    mut check: impl FnMut(&FrameOutput, &FrameOutput, &Simulation, &Simulation),
) {
    for frame in 0..=frames {
        let a = plain.step();
        let b = featured.step();
        assert_eq!(a.frame, frame);
        assert_eq!(b.frame, frame);
        assert_eq!(
            plain.world().digest(),
            featured.world().digest(),
            "frame {frame}: digests differ\nplain: {:?}\nfeatured: {:?}",
            plain.world().position,
            featured.world().position
        );
        assert_eq!(a.contacts, b.contacts, "frame {frame}: contacts differ");
        assert_eq!(a.events, b.events, "frame {frame}: events differ");
        assert_eq!(a.removed, b.removed, "frame {frame}: removed bodies differ");
        check(&a, &b, plain, featured);
    }
}

/// A walled box of mixed shapes under gravity: AABB boxes (per-axis `separate` with the
/// floor and each other), circles, capsules, polygons and OBBs (`separate` along the normal,
/// also against the boxes), a gravity-free `ghost` that reports what it passes through,
/// bullets with a lifetime that are destroyed by what they hit, and script spawns.
/// `world_extra` goes into `[world]` (after `gravity`), `region` after it.
pub fn busy_scene(world_extra: &str, region: &str) -> String {
    format!(
        r#"
hz = 60
layers = ["tile", "box", "ball", "ghost", "bullet"]
collide = [
  {{ a = "box", b = "tile", response = "separate" }},
  {{ a = "box", b = "box", response = "separate" }},
  {{ a = "ball", b = "tile", response = "separate" }},
  {{ a = "ball", b = "ball", response = "separate" }},
  {{ a = "ball", b = "box", response = "separate" }},
  {{ a = "ghost", b = "ball", response = "report" }},
  {{ a = "ghost", b = "box", response = "report" }},
  {{ a = "bullet", b = "ball", response = "destroy", destroy = "a" }},
  {{ a = "bullet", b = "tile", response = "destroy", destroy = "a" }},
]
script = [
  {{ frame = 40, action = "spawn", template = "bullet", position = [-9, 4], velocity = [14, 3] }},
  {{ frame = 90, action = "spawn", template = "bullet", position = [9, 2], velocity = [-16, 1] }},
  {{ frame = 120, action = "apply_impulse", body = "crate", impulse = [6, 9] }},
  {{ frame = 150, action = "spawn", template = "pebble", position = [0.3, 12], velocity = [-2, 0] }},
  {{ frame = 200, action = "set_velocity", body = "ghost", velocity = [-4, 0.5] }},
]

[world]
gravity = [0, -20]
{world_extra}
{region}

[templates.bullet]
layer = "bullet"
shape = {{ kind = "circle", radius = 0.1 }}
gravity_scale = 0
lifetime = 45

[templates.pebble]
layer = "ball"
shape = {{ kind = "circle", radius = 0.3 }}

[[bodies]]
name = "floor"
layer = "tile"
kind = "static"
shape = {{ kind = "aabb", half_extents = [12, 1] }}
position = [0, -1]

[[bodies]]
name = "left wall"
layer = "tile"
kind = "static"
shape = {{ kind = "aabb", half_extents = [1, 15] }}
position = [-13, 14]

[[bodies]]
name = "right wall"
layer = "tile"
kind = "static"
shape = {{ kind = "aabb", half_extents = [1, 15] }}
position = [13, 14]

[[bodies]]
name = "crate"
layer = "box"
shape = {{ kind = "aabb", half_extents = [0.5, 0.5] }}
position = [-3.2, 2.5]
velocity = [1.5, 0]

[[bodies]]
name = "crate_b"
layer = "box"
shape = {{ kind = "aabb", half_extents = [0.6, 0.4] }}
position = [-2.7, 5.1]

[[bodies]]
name = "crate_c"
layer = "box"
shape = {{ kind = "aabb", half_extents = [0.45, 0.7] }}
position = [4.1, 1.3]
velocity = [-3, 2]

[[bodies]]
name = "ball"
layer = "ball"
shape = {{ kind = "circle", radius = 0.5 }}
position = [-6, 6]
velocity = [4, 0]

[[bodies]]
name = "capsule"
layer = "ball"
shape = {{ kind = "capsule", a = [-0.6, 0], b = [0.6, 0], radius = 0.25 }}
position = [2, 8]
velocity = [-1, 0]
angular_velocity = 1.5

[[bodies]]
name = "wedge"
layer = "ball"
shape = {{ kind = "polygon", vertices = [[0.8, -0.4], [0, 0.6], [-0.8, -0.4]] }}
position = [6, 4]
velocity = [-2.5, 3]
angular_velocity = -0.7

[[bodies]]
name = "plank"
layer = "ball"
shape = {{ kind = "obb", half_extents = [0.9, 0.2], angle = 0.3 }}
position = [-1, 11]
velocity = [0.5, -1]

[[bodies]]
name = "ghost"
layer = "ghost"
shape = {{ kind = "circle", radius = 0.8 }}
position = [-10, 1]
velocity = [3, 0]
gravity_scale = 0
"#
    )
}

/// Sums of what a run produced, so a comparison is known to compare something.
#[derive(Default)]
pub struct Totals {
    contacts: usize,
    events: usize,
    removed: usize,
    report_contacts: usize,
    hits: usize,
    per_axis: usize,
    touches: usize,
}

impl Totals {
    pub fn add(&mut self, out: &FrameOutput) {
        self.contacts += out.contacts.len();
        self.events += out.events.len();
        self.removed += out.removed.len();
        self.report_contacts += out
            .contacts
            .iter()
            .filter(|c| c.response == Response::Report)
            .count();
        self.hits += out
            .contacts
            .iter()
            .filter(|c| c.response == Response::Separate && !matches!(c.phase, Phase::X | Phase::Y))
            .count();
        self.touches += out
            .events
            .iter()
            .filter(|e| matches!(e, GameEvent::TouchBegin { .. }))
            .count();
        self.per_axis += out
            .contacts
            .iter()
            .filter(|c| matches!(c.phase, Phase::X | Phase::Y))
            .count();
    }

    /// The busy scene really collides in every way it is meant to.
    pub fn assert_busy(&self) {
        assert!(self.report_contacts > 0, "no `report` contacts");
        assert!(self.hits > 0, "no separation along the normal");
        assert!(self.per_axis > 0, "no per-axis separation");
        assert!(self.removed >= 2, "no bullet was removed");
        assert!(self.touches > 0, "no pair began to touch");
    }
}

/// Dense index of the live body named `name` (the lowest id with that name).
pub fn index(sim: &Simulation, name: &str) -> usize {
    sim.world()
        .find(name)
        .unwrap_or_else(|| panic!("no body named {name}"))
}

/// Every pair a broad phase owes, by its definition written as plainly as possible: each
/// two bodies (by index, `a < b`) of which one is dynamic, of layers that interact, whose
/// boxes overlap (the `broad_phase` and `broad_phase_filter` tests' reference).
pub fn all_pairs(bodies: &[BodyEntry], interactions: &Interactions) -> Vec<(u32, u32)> {
    let mut pairs = Vec::new();
    for (i, a) in bodies.iter().enumerate() {
        for (j, b) in bodies.iter().enumerate().skip(i + 1) {
            let dynamic = a.kind == BodyKind::Dynamic || b.kind == BodyKind::Dynamic;
            if dynamic && interactions.interacts(a.layer, b.layer) && a.bounds.overlaps(&b.bounds) {
                pairs.push((i as u32, j as u32));
            }
        }
    }
    pairs
}
