//! Ricochet's built-in scenes, built in code: one source for the benchmarks, the accuracy
//! study and the tests (as Box2D's `shared/benchmarks.c` serves its samples, benchmark and
//! tests).
//!
//! **Owns:** the benchmark scenes ([`bench`](mod@bench): `asteroids-N`, `platformer-T-A`,
//! `rain-N` and their names; [`crowds`]: the broad-phase study's `crowded-N`, `sparse-N`,
//! `mixed-N`), the accuracy scenes and their exact answers ([`accuracy`]:
//! projectile, spring and orbit, drop, the bullet field), the test scenes of tiles, boxes
//! and balls ([`tiles`]), and the one seeded generator [`Rng`] (SplitMix64). Scenes are
//! [`Scenario`] values built from `WorldDef`, `BodyDef` and
//! `Layers`, identical to the bit to what the same scene written as a scenario file loads.
//!
//! **Never:** steps a simulation, measures or times anything, links rapier, does I/O, or
//! parses scenario text: a test of the parser reads its own files.
//!
//! ```
//! let scene = ricochet_scenes::bench::asteroids(300, 10);
//! assert_eq!(scene.bodies.len(), 300 + ricochet_scenes::bench::BULLETS + 1);
//! let mut sim = ricochet_sim::Simulation::new(&scene);
//! sim.step();
//! ```

pub mod accuracy;
pub mod bench;
pub mod crowds;
mod rng;
pub mod tiles;

pub use rng::Rng;

use ricochet_geom::{Shape, Vec2};
use ricochet_sim::{BodyDef, LayerId, Layers, Response, Scenario, WorldDef};

/// Layers with names and the listed responses; every other pair ignored.
#[must_use]
pub fn layers(names: &[&str], pairs: &[(LayerId, LayerId, Response)]) -> Layers {
    let mut l = Layers::new(names.iter().map(|n| (*n).to_owned()).collect());
    for &(a, b, r) in pairs {
        l.set(a, b, r);
    }
    l
}

/// A scenario without templates or script.
#[must_use]
pub fn scenario(name: &str, world: WorldDef, bodies: Vec<BodyDef>, frames: u64) -> Scenario {
    Scenario {
        name: name.to_owned(),
        world,
        frames,
        templates: std::collections::BTreeMap::new(),
        tiles: Vec::new(),
        bodies,
        script: Vec::new(),
    }
}

/// A dynamic body named `name` of `layer` and `shape` at `at`, moving at `velocity`: the
/// body most hand-built test scenes are made of.
#[must_use]
pub fn moving_body(name: &str, layer: LayerId, shape: Shape, at: Vec2, velocity: Vec2) -> BodyDef {
    BodyDef {
        name: name.to_owned(),
        layer,
        shape,
        position: at,
        velocity,
        ..BodyDef::default()
    }
}
