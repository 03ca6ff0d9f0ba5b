//! Ricochet's simulation: the world, scenario files, and the fixed stage pipeline.
//!
//! **Owns:** the struct-of-arrays [`World`] with generational [`Entity`] ids, the validated
//! definitions a scenario loads into ([`WorldDef`], [`BodyDef`], [`Layers`]), loading and
//! checking scenario files ([`load_scenario`], errors with `file:line:column`), and the
//! [`Simulation`] that runs the stages in one fixed order and reports each frame as a
//! [`FrameOutput`].
//!
//! **Never:** does I/O, reads the clock, formats logs, uses hash-ordered collections, or
//! calls platform trigonometry. Geometry comes from `ricochet-geom`; what a frame produced
//! goes back to the caller, which decides how to record it.
//!
//! ```
//! let text = r#"
//! hz = 60
//! layers = ["ball"]
//! [[bodies]]
//! layer = "ball"
//! shape = { kind = "circle", radius = 0.5 }
//! velocity = [1, 0]
//! "#;
//! let scenario = ricochet_sim::load_scenario(text, "ball.toml").unwrap();
//! let mut sim = ricochet_sim::Simulation::new(&scenario);
//! for _ in 0..=60 {
//!     sim.step();
//! }
//! // One second at 1 unit/s, in 60 steps of 1/60 s.
//! assert!((sim.world.position[0].x - 1.0).abs() < 1e-12);
//! ```

pub mod broad_phase;
mod control;
mod def;
mod entity;
mod event;
#[cfg(feature = "toml")]
mod load;
mod output;
mod pipeline;
mod scenario;
mod stage_set;
mod stages;
mod world;

pub use control::ControlError;
pub use def::{
    Action, ActiveRegion, BodyDef, BodyKind, Controller, Doomed, Event, LayerId, Layers,
    MAX_FRAMES, Response, RunLengthError, Split, WorldBounds, WorldDef,
};
pub use entity::{Entity, EntityAllocator};
pub use event::{FireOutcome, GameEvent, JumpOutcome, Removal, ScriptInput};
#[cfg(feature = "toml")]
pub use load::{ScenarioError, load_scenario};
pub use output::{ContactRecord, FrameOutput, Phase, RemovedBody, Stats};
pub use pipeline::Simulation;
pub use scenario::Scenario;
pub use stage_set::{Stage, StageSet};
pub use stages::SLOP;
pub use world::{Inputs, World};
