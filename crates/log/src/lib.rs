//! MCAP logs of a Ricochet simulation run, ready for Foxglove.
//!
//! This crate owns:
//! - writing MCAP logs ([`LogWriter`]), encoding and compressing on a writer thread,
//!   into a temporary file renamed into place when complete, and reading them back
//!   ([`read_log`], or streamed message by message from a file with [`LogFile`]),
//!   refusing files that are cut short or damaged;
//! - the message types ([`messages`]): the official Foxglove protobuf types and
//!   Ricochet's own (`proto/ricochet.proto`), with the FileDescriptorSets every log
//!   embeds as its schemas (MCAP's protobuf profile), so it opens in Foxglove offline;
//! - rebuilding every body's full state at every frame from `/bodies` deltas
//!   ([`BodyStates`]);
//! - decoding any message of a log to JSON from the schema in the log ([`LogMessage`]);
//! - comparing two logs ([`diff`]): the first divergence (frame, topic, body, field, both
//!   values) and the count per topic, as `ricochet diff` and golden checks print them.
//!
//! Logs are deterministic: the same calls give byte-identical files, written on the
//! writer thread or inline. So this crate must never:
//! - read a wall clock (every time in a log is simulation time passed in by
//!   the caller), or anything else about the host;
//! - let `HashMap`/`HashSet` iteration order feed its output (it uses
//!   `BTreeMap` and `Vec`, protobuf maps are `BTreeMap`s; `mcap` writes its summary
//!   in id order);
//! - compute any physics: it records what the simulation hands it.

pub mod diff;
pub mod messages;

mod backlog;
mod bodies;
mod decode;
mod error;
mod escape;
mod log_file;
mod reader;
mod sink;
mod stream;
mod writer;

pub use bodies::BodyStates;
pub use error::LogError;
pub use escape::escape_controls;
pub use log_file::{ChannelInfo, LogFile, RawMessage};
pub use messages::Schema;
pub use reader::{LogMessage, read_log, read_log_file};
pub use sink::{ChannelId, MessageSink};
pub use stream::Messages;
pub use writer::{LogWriter, SHARE_ENCODING_FROM, Threading};
