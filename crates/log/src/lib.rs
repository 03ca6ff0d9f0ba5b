//! MCAP logs of a Ricochet simulation run, ready for Foxglove.
//!
//! This crate owns:
//! - writing MCAP logs ([`LogWriter`]), into a temporary file renamed into
//!   place when complete, and reading them back ([`read_log`], or streamed
//!   message by message from a file with [`LogFile`]), refusing files that are
//!   cut short or damaged;
//! - the Foxglove message types ([`foxglove`]), serialized as JSON exactly as
//!   the Foxglove schemas require;
//! - the vendored Foxglove JSON Schemas (`schemas/`, from
//!   `@foxglove/schemas` 2.1.0), embedded in every log so it opens in
//!   Foxglove offline.
//!
//! Logs are deterministic: the same calls give byte-identical files. So this
//! crate must never:
//! - read a wall clock (every time in a log is simulation time passed in by
//!   the caller), or anything else about the host;
//! - let `HashMap`/`HashSet` iteration order feed its output (it uses
//!   `BTreeMap` and `Vec`; `mcap` writes its summary in id order);
//! - compute any physics: it records what the simulation hands it.

pub mod foxglove;

mod error;
mod reader;
mod writer;

pub use error::LogError;
pub use reader::{ChannelInfo, LogFile, LogMessage, Messages, read_log, read_log_file};
pub use writer::{ChannelId, LogWriter};
