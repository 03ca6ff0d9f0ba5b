//! The crate's error type.

use std::path::PathBuf;

/// Everything that can go wrong writing or reading a log.
#[derive(Debug, thiserror::Error)]
pub enum LogError {
    /// The log file could not be created (missing directory, no permission, ...).
    #[error("cannot create log file {path}: {source}")]
    Create {
        /// The file that was to be created.
        path: PathBuf,
        /// Why it failed.
        source: std::io::Error,
    },
    /// Writing to an open log failed (disk full, I/O error, unknown channel, ...).
    #[error("cannot write log file {path}: {source}")]
    Write {
        /// The log file being written.
        path: PathBuf,
        /// Why it failed.
        source: mcap::McapError,
    },
    /// A log file could not be read from disk.
    #[error("cannot read log file {path}: {source}")]
    Read {
        /// The file that was to be read.
        path: PathBuf,
        /// Why it failed.
        source: std::io::Error,
    },
    /// The log ends early: it was cut short, or its writer never finished it.
    #[error("truncated log: {detail}")]
    Truncated {
        /// What is missing.
        detail: String,
    },
    /// The log is damaged or is not an MCAP file written by this crate.
    #[error("corrupt log: {detail}")]
    Corrupt {
        /// What is wrong.
        detail: String,
    },
    /// A message could not be encoded as JSON.
    #[error("message JSON: {0}")]
    Json(#[from] serde_json::Error),
}
