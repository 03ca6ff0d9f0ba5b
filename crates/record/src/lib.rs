//! Recording a Ricochet simulation: the MCAP log `ricochet run` writes, from a game's own
//! [`Simulation`](ricochet_sim::Simulation).
//!
//! This crate owns:
//! - the [`Recorder`]: one frame at a time onto a log file, or onto any
//!   [`MessageSink`](ricochet_log::MessageSink) (a live stream: `ricochet-serve`), with the
//!   [`channels`] chosen and the scene drawn for Foxglove ([`scene`]);
//! - the words of `/events` ([`events`]): what an input, a spawn, a collision or a click
//!   says in the log panel;
//! - [`session`]: a simulation stepped with inputs from outside (JSON), every input recorded
//!   on `/input`, so that a replay steps it again to the same bytes;
//! - [`golden`]: a game's own golden-log check, for its `cargo test`: the first divergence
//!   from a recorded log, as `ricochet diff` prints it, and `RICOCHET_BLESS=1` to re-record.
//!
//! Logs are deterministic: the same simulation gives byte-identical files. So this crate
//! never reads a wall clock (a frame's time is `frame * dt`), never lets `HashMap`
//! iteration reach a message, and computes no physics: it records what the simulation
//! hands it. It never prints, parses command lines or picks file names: that is the
//! `ricochet` binary's.
//!
//! ```no_run
//! use ricochet_record::{Recorder, channels::Channels};
//! # fn demo(scenario: &ricochet_sim::Scenario) -> Result<(), ricochet_log::LogError> {
//! let mut sim = ricochet_sim::Simulation::new(scenario);
//! let mut log = Recorder::create("level1.mcap".as_ref(), scenario.world.dt, Channels::default())?;
//! for _ in 0..=600 {
//!     let out = sim.step();
//!     log.record(&sim, &out)?;
//! }
//! log.finish()?;
//! # Ok(()) }
//! ```

mod bodies;
pub mod channels;
pub mod events;
pub mod golden;
mod pace;
mod recorder;
pub mod replay;
pub mod scene;
pub mod session;

pub use bodies::{KEYFRAME_BYTES_PER_FRAME, KEYFRAME_INTERVAL};
pub use channels::Channels;
pub use pace::DRAW_BYTES_PER_FRAME;
pub use recorder::{INLINE_ENV, LIBRARY, Level, Recorder, log_writer};
