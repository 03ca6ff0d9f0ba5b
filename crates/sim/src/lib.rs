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
//! # Embedding it in a game
//!
//! A scene built in code, stepped, sent an input, and its contacts and events read. Bodies
//! are addressed by [`Entity`] (index and generation): a removed body's id never names
//! another body.
//!
//! ```
//! use ricochet_sim::prelude::*;
//!
//! let mut layers = Layers::new(vec!["ball".into(), "wall".into()]);
//! layers.set(0, 1, Response::Report);
//! let mut sim = Simulation::from_def(WorldDef { layers, ..WorldDef::default() })?;
//! let ball = sim.spawn(&BodyDef {
//!     shape: Shape::circle(0.5)?,
//!     ..BodyDef::default()
//! });
//! let wall = sim.spawn(&BodyDef {
//!     layer: 1,
//!     kind: BodyKind::Static,
//!     shape: Shape::aabb(Vec2::new(0.5, 5.0))?,
//!     position: Vec2::new(3.25, 0.0), // its left face at x = 2.75
//!     ..BodyDef::default()
//! });
//! sim.step(); // frame 0: the initial state
//! sim.apply(ball, Action::SetVelocity(Vec2::new(60.0, 0.0)))?;
//! let out = sim.step(); // the input is applied, then the ball moves 1 unit
//! assert_eq!(out.events[0], GameEvent::Input {
//!     body: ball,
//!     input: ScriptInput::Velocity(Vec2::new(60.0, 0.0)),
//! });
//! let x = sim.position(ball).unwrap().x; // 60 units/s for 1/60 s
//! assert!((x - 1.0).abs() < 1e-15);
//! let out = sim.step(); // the ball (radius 0.5) at x = 2 reaches 2.5: no contact yet
//! assert!(out.contacts.is_empty());
//! let out = sim.step(); // at x = 3 it overlaps the face at 2.75 by 0.5 + (3 - 2.75)
//! let c = &out.contacts[0];
//! assert_eq!((c.a, c.b, c.normal), (ball, wall, Vec2::new(1.0, 0.0)));
//! assert!((c.depth - 0.75).abs() < 1e-12);
//! // Its first frame of contact: the pair begins to touch (`docs/touches.md`).
//! assert!(matches!(out.events[0], GameEvent::TouchBegin { a, b, .. } if (a, b) == (ball, wall)));
//! assert_eq!(sim.touching(), [(ball, wall)]);
//! let out = sim.step(); // still overlapping (`report` lets it through): no new event
//! assert!(out.events.is_empty() && sim.touching() == [(ball, wall)]);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # Frame numbering
//!
//! [`Simulation::frame`] is the frame the *next* [`Simulation::step`] runs, and the output
//! of a step names the frame it ran. The first step runs frame 0, the initial state: its
//! script events run and its contacts are found, but nothing moves. An input sent between
//! two steps ([`Simulation::apply`], [`Simulation::set_target_pose`]) lands in the next
//! step's frame, at its start. So after `k` steps the world holds the end of frame `k - 1`,
//! and `frame()` is `k`: what a save taken then holds, and where a restored run goes on.
//!
//! ```
//! use ricochet_sim::prelude::*;
//!
//! let mut sim = Simulation::from_def(WorldDef::default())?;
//! let ball = sim.spawn(&BodyDef::default());
//! assert_eq!(sim.frame(), 0); // nothing has run
//! assert_eq!(sim.step().frame, 0); // frame 0: the initial state, nothing moves
//! sim.apply(ball, Action::SetVelocity(Vec2::new(60.0, 0.0)))?;
//! assert_eq!(sim.frame(), 1); // the input lands in frame 1 ...
//! let out = sim.step();
//! assert_eq!(out.frame, 1); // ... which applies it, then moves the ball 1 unit
//! assert!(matches!(out.events[0], GameEvent::Input { body, .. } if body == ball));
//! assert_eq!(sim.position(ball), Some(Vec2::new(1.0, 0.0)));
//! assert_eq!(sim.frame(), 2); // the world now holds the end of frame 1
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # Tiles and moving platforms
//!
//! [`Simulation::spawn_tiles`] spawns a tile map given as data ([`TileRows`]: rows of
//! identical static bodies, an entity each, ids in row order). A kinematic body is moved by
//! the game with [`Simulation::set_target_pose`] (it gets the velocity that takes it there
//! in the next step); a box standing on it is carried by its motion from the step after
//! the one that found it standing there ([`Simulation::carrier`]).
//!
//! # Scene queries
//!
//! Between two steps a game asks the world: [`Simulation::cast_ray`] (the first body hit,
//! a [`RayHit`]), [`Simulation::cast_ray_all`] (every one, by distance then id),
//! [`Simulation::cast_shape`] (where a moved shape first touches, a [`ShapeHit`]),
//! [`Simulation::overlap_point`], [`Simulation::overlap_aabb`] and
//! [`Simulation::overlap_shape`] (the bodies inside, in id order). A [`QueryFilter`] picks
//! layers and leaves one body out. They are exact, as the collision geometry is; bodies are
//! solid (a ray starting inside one hits it at distance 0 with a zero normal); touching is
//! not overlapping (a point on a body's edge is not in it, a box that only touches a body
//! does not overlap it), while a ray that grazes a body hits it; in a wrap world every
//! image is seen and a ray leaving one edge goes on from the other. Bad input (a zero or
//! non-finite direction, a negative distance) answers nothing, never a panic.
//!
//! # A game's rules
//!
//! A game with players implements [`Game`] (joins, leaves, its own typed inputs, rules
//! before and after each step, the state its players see) and runs in a [`GameLoop`], the
//! one frame loop that `ricochet-record` (recording, golden checks, replays) and
//! `ricochet-serve` (rooms) drive too. [`ScenarioGame`] is the game of a scenario file.
//! README's "Embed the simulation in a game" has a whole one.
//!
//! # Lag compensation
//!
//! A server checks a player's shot against the world as that player saw it, some frames
//! ago. [`Simulation::keep_history`] keeps the last `n` frames (at most [`MAX_HISTORY`]),
//! and [`Simulation::past`] returns one as a [`Past`], with the same queries: exactly what
//! they return on the scene restored from a snapshot taken right after that frame's step.
//! A frame not kept is a [`HistoryError`], never an answer from another frame.
//!
//! ```
//! use ricochet_sim::prelude::*;
//!
//! let mut sim = Simulation::from_def(WorldDef::default())?;
//! let ball = sim.spawn(&BodyDef {
//!     shape: Shape::circle(0.5)?,
//!     velocity: Vec2::new(60.0, 0.0), // 1 unit a frame; frame 0 does not move it
//!     ..BodyDef::default()
//! });
//! sim.keep_history(32)?; // from the next step on
//! for _ in 0..10 {
//!     sim.step(); // at the end of frame f the ball is at x = f
//! }
//! let shot = |q: &dyn Fn(Vec2, Vec2, f64, &QueryFilter) -> Option<RayHit>| {
//!     q(Vec2::new(-10.0, 0.0), Vec2::new(1.0, 0.0), 100.0, &QueryFilter::all()).unwrap()
//! };
//! // A player who saw frame 4 shot at the ball's left side, at x = 4 - 0.5 ...
//! let then = sim.past(4)?;
//! let hit = shot(&|o, d, m, f| then.cast_ray(o, d, m, f));
//! assert_eq!((hit.entity, hit.point), (ball, Vec2::new(3.5, 0.0)));
//! // ... where the world now (the end of frame 9) has it at x = 8.5.
//! let now = shot(&|o, d, m, f| sim.cast_ray(o, d, m, f));
//! assert_eq!(now.point, Vec2::new(8.5, 0.0));
//! assert!(matches!(
//!     sim.past(10),
//!     Err(HistoryError::NotKept { frame: 10, oldest: 0, newest: 9 })
//! ));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # Snapshots and rollback
//!
//! [`Simulation::snapshot`] holds everything the next step reads (every body, the pending
//! inputs and targets, the touching pairs, the script cursor, the id generations) and the
//! game's [`BodyDef::user_data`]; [`Snapshot::to_bytes`] and [`Snapshot::from_bytes`] make
//! it bytes (versioned and hashed: damaged bytes are a [`SnapshotError`]).
//! [`Simulation::restore`] puts any simulation of the same scene back in that state: the
//! same world settings, layers, templates and script, which a snapshot references by a
//! hash; the bodies come from the snapshot, so a peer that built the scene anew can restore
//! it. [`Simulation::checksum`] hashes exactly the state a step reads (not the user data):
//! equal checksums step identically, which is what rollback netcode compares.
//! `examples/rollback.rs` runs a `ggrs` `SyncTestSession` on them.
//!
//! Scenario files load into the same definitions ([`load_scenario`], feature `toml`, on by
//! default); `examples/asteroids_in_code.rs` builds an Asteroids scene and reads a
//! destruction as a typed [`GameEvent`]. README's "Embed the simulation in a game" has more
//! examples, each run as a doctest of this crate.

mod action;
pub mod broad_phase;
mod check;
mod control;
mod def;
mod entity;
mod event;
mod game;
mod history;
mod interned;
mod limits;
#[cfg(feature = "toml")]
mod load;
mod output;
mod parallel;
mod pipeline;
mod prefetch;
pub mod prelude;
mod query;
mod reads;
mod scenario;
mod snapshot;
mod stage_set;
mod stages;
mod world;

pub use action::{Action, Event, ScriptAction};
pub use check::ScenarioError;
pub use control::{ControlError, NonFinite};
pub use def::{
    ActiveRegion, BodyDef, BodyKind, Controller, DEFAULT_MAX_CLIMB_ANGLE, Doomed, LayerId, Layers,
    MAX_CLIMB_ANGLE_LIMIT, MAX_CONTROLLER_VALUE, MAX_FRAMES, MAX_MASS, MIN_MASS, Platform,
    Response, RunLengthError, Split, WorldBounds, WorldDef, controller_out_of_range, shape_reach,
};
pub use entity::{Entity, EntityAllocator};
pub use event::{FireOutcome, GameEvent, JumpOutcome, Removal, ScriptInput};
pub use game::{Game, GameLoop, Overflowed, Player};
#[cfg(feature = "toml")]
pub use game::{MAX_INPUT_VALUE, ScenarioGame};
pub use history::{HistoryError, Past};
pub use limits::MAX_HISTORY;
#[cfg(feature = "toml")]
pub use load::file::ActionFile;
#[cfg(feature = "toml")]
pub use load::{load_scenario, load_scenario_and_map};
pub use output::{ContactRecord, FrameOutput, Phase, RemovedBody, Stats};
pub use pipeline::Simulation;
pub use query::{QueryFilter, RayHit, ShapeHit};
pub use scenario::{Scenario, TileRows, TiledDef};
pub use snapshot::{SNAPSHOT_VERSION, Snapshot, SnapshotError};
pub use stage_set::{Stage, StageSet};
pub use stages::SLOP;
pub use world::{Disturbed, Inputs, Motion, World};

/// The geometry crate, for what the prelude does not re-export (the narrow phase, ...).
pub use ricochet_geom as geom;
pub use ricochet_geom::{Bounds, Pose, Primitive, Shape, ShapeError, Vec2};

/// README.md's rust snippets (its "Embed the simulation in a game" section), run as this
/// crate's doctests so that what a newcomer copies compiles and does what it says.
#[cfg(doctest)]
#[doc = include_str!("../../../README.md")]
pub struct ReadmeDoctests;
