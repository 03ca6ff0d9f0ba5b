//! Reading a log back, refusing files that are cut short or damaged.

use std::collections::BTreeMap;
use std::path::Path;

use mcap::McapError;
use mcap::read::{MessageStream, Options, Summary};

use crate::LogError;

/// One message of a log, with its JSON payload parsed.
#[derive(Debug, Clone, PartialEq)]
pub struct LogMessage {
    /// Topic of the message's channel.
    pub topic: String,
    /// Name of the channel's schema (e.g. `foxglove.SceneUpdate`), or empty
    /// for a channel without a schema.
    pub schema_name: String,
    /// Log time, nanoseconds of simulation time.
    pub log_time: u64,
    /// Publish time, nanoseconds of simulation time.
    pub publish_time: u64,
    /// Sequence number within the channel.
    pub sequence: u32,
    /// The JSON payload.
    pub data: serde_json::Value,
}

/// Reads every message of an MCAP log, in file order (which, for logs written
/// by [`LogWriter`](crate::LogWriter) with nondecreasing times, is log-time
/// order).
///
/// A log must be complete: it must begin and end with the MCAP magic, have a
/// summary with statistics, and hold exactly the messages its statistics
/// count, per channel, in chunks whose CRCs match. A file cut short is
/// [`LogError::Truncated`]; any other damage is [`LogError::Corrupt`]. It
/// never returns a partial list.
pub fn read_log(bytes: &[u8]) -> Result<Vec<LogMessage>, LogError> {
    check_magic(bytes)?;
    let summary = Summary::read(bytes)
        .map_err(|error| classify(error, "summary"))?
        .ok_or_else(|| corrupt("no summary section; a finished log always has one"))?;
    let stats = summary
        .stats
        .ok_or_else(|| corrupt("no statistics record; a finished log always has one"))?;

    let stream = MessageStream::new_with_options(bytes, Options::ValidateChunkCrcs.into())
        .map_err(|error| classify(error, "data section"))?;
    // Read the whole data section before decoding any payload, so that a
    // damaged chunk is reported by its CRC rather than as bad JSON.
    let mut raw = Vec::new();
    let mut counts = BTreeMap::<u16, u64>::new();
    for message in stream {
        let message = message.map_err(|error| classify(error, "data section"))?;
        *counts.entry(message.channel.id).or_insert(0) += 1;
        raw.push(message);
    }

    let mut expected = stats.channel_message_counts.clone();
    expected.retain(|_, count| *count > 0);
    if raw.len() as u64 != stats.message_count || counts != expected {
        return Err(corrupt(&format!(
            "the data section holds {} messages {counts:?} (per channel id) \
             but the summary counts {} {expected:?}",
            raw.len(),
            stats.message_count,
        )));
    }
    raw.into_iter().map(decode).collect()
}

fn decode(message: mcap::Message<'_>) -> Result<LogMessage, LogError> {
    let data = serde_json::from_slice(&message.data).map_err(|error| {
        corrupt(&format!(
            "message {} on {} is not JSON: {error}",
            message.sequence, message.channel.topic
        ))
    })?;
    Ok(LogMessage {
        topic: message.channel.topic.clone(),
        schema_name: message
            .channel
            .schema
            .as_ref()
            .map(|schema| schema.name.clone())
            .unwrap_or_default(),
        log_time: message.log_time,
        publish_time: message.publish_time,
        sequence: message.sequence,
        data,
    })
}

/// Reads the file at `path` and then [`read_log`]s it.
pub fn read_log_file(path: &Path) -> Result<Vec<LogMessage>, LogError> {
    let bytes = std::fs::read(path).map_err(|source| LogError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    read_log(&bytes).map_err(|error| match error {
        LogError::Truncated { detail } => LogError::Truncated {
            detail: format!("{}: {detail}", path.display()),
        },
        LogError::Corrupt { detail } => LogError::Corrupt {
            detail: format!("{}: {detail}", path.display()),
        },
        other => other,
    })
}

/// Checks the magic bytes at both ends. A finished log ends with them, so a
/// file without them was cut short (or its writer never called `finish`).
fn check_magic(bytes: &[u8]) -> Result<(), LogError> {
    let magic = mcap::MAGIC;
    if !bytes.starts_with(magic) {
        return Err(if magic.starts_with(bytes) {
            truncated(&format!(
                "{} bytes, shorter than the MCAP magic",
                bytes.len()
            ))
        } else {
            corrupt("does not start with the MCAP magic: not an MCAP file")
        });
    }
    if bytes.len() < 2 * magic.len() || !bytes.ends_with(magic) {
        return Err(truncated(&format!(
            "{} bytes that do not end with the MCAP magic: the file was cut short, \
             or its writer stopped before finishing it",
            bytes.len()
        )));
    }
    Ok(())
}

/// Sorts an mcap error into truncated (the data ends early) or corrupt.
fn classify(error: McapError, part: &str) -> LogError {
    match error {
        McapError::UnexpectedEof | McapError::UnexpectedEoc => {
            truncated(&format!("{part} ends early: {error}"))
        }
        other => corrupt(&format!("{part}: {other}")),
    }
}

fn truncated(detail: &str) -> LogError {
    LogError::Truncated {
        detail: detail.to_owned(),
    }
}

fn corrupt(detail: &str) -> LogError {
    LogError::Corrupt {
        detail: detail.to_owned(),
    }
}
