//! Serving a Ricochet simulation live to Foxglove (or Lichtblick) over the Foxglove
//! WebSocket protocol, in real time, with inputs, services and seeks coming back.
//!
//! This crate owns:
//! - the protocol (`protocol.rs`: both subprotocols, foxglove.websocket.v1 and
//!   foxglove.sdk.v1), the connections and their bounds (`server.rs`), and the hub the
//!   simulation and the connections share (`hub.rs`: channels, queues, inputs, calls);
//! - the services a client calls (`services.rs`: `/reset`, `/load`, `/step`, `/query`, ...),
//!   scene queries (`query.rs`) and Lichtblick's clicked point (`click.rs`);
//! - the real-time loop ([`serve`]: a fixed-timestep schedule, seeks, `/step`, pauses),
//!   recording the session as it goes ([`Options::record`]).
//! - rooms ([`serve_rooms`], `rooms.rs`, `room.rs`): many sessions of a game at once, each
//!   its own simulation, game, recording and clients at `ws://HOST:PORT/rooms/NAME`, made
//!   by a [`RoomMaker`], stepped on a bounded pool of threads (the client protocol:
//!   `docs/protocol.md`).
//!
//! Its files import in one direction: the entry points (`realtime.rs`) → the transport
//! (`server.rs`) → the room registry (`rooms.rs`, reached through `door.rs`) → a room
//! (`room.rs`, or the plain session `serving.rs`) → the frame loop every mode shares
//! (`ricochet_record::session::GameSession`); `sink.rs`, `hub.rs`, `protocol.rs` and
//! `common.rs` are at the bottom.
//!
//! The messages are `ricochet-record`'s, the same a log holds; the inputs are its sessions'.
//! This crate never lets the wall clock reach a message (it only paces the frames), never
//! computes physics, and never prints, parses command lines or installs signal handlers:
//! notes go to [`Options::note`], and the caller's flag stops it.
//!
//! ```no_run
//! use std::sync::atomic::AtomicBool;
//! # fn level() -> ricochet_sim::Scenario { ricochet_sim::Scenario::default() }
//! let listener = ricochet_serve::Listener::bind("127.0.0.1:8765".parse().unwrap()).unwrap();
//! let options = ricochet_serve::Options { frames: Some(600), ..Default::default() };
//! let stop = AtomicBool::new(false);
//! let served = ricochet_serve::serve(listener, level(), String::new(), &options, &stop).unwrap();
//! println!("served frames 0 to {}", served.next_frame - 1);
//! ```

mod click;
mod common;
mod door;
mod hub;
mod load_path;
mod protocol;
mod query;
mod queue;
mod realtime;
mod room;
mod rooms;
mod scenario_rooms;
mod server;
mod services;
mod serving;
mod sink;

pub use common::{DEFAULT_BIND, Listener, MAX_CLIENTS, Note, SPEEDS, ServeError};
pub use door::MAX_ROOM_NAME;
pub use hub::{CLIENT_BUDGET, STATE_RATE};
pub use load_path::MAX_SCENARIO_BYTES;
pub use realtime::{Options, Served, cpu_seconds, serve, serve_rooms};
pub use rooms::{MAX_ROOM_INPUTS, MAX_THREADS, RoomMaker, RoomOptions, ServedRooms};
pub use scenario_rooms::ScenarioRooms;
pub use sink::RECORDED_INPUT;
