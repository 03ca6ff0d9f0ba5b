//! Reading a whole log back from its bytes, refusing files that are cut short or damaged,
//! and what reading a log file streamed (`log_file.rs`) shares with it: the footer, the
//! checks of both ends, and how damage is named.

use std::collections::BTreeMap;
use std::path::Path;

use mcap::McapError;
use mcap::read::{MessageStream, Options, Summary};

use crate::LogError;
use crate::LogFile;
use crate::decode::Decoder;

/// One message of a log, with its payload decoded to JSON (protobuf through the schema the
/// log embeds, with the `.proto` field names).
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
    /// The payload, decoded to JSON.
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
    let end = bytes.len() - mcap::MAGIC.len();
    let footer = Footer::parse(
        &bytes[end.saturating_sub(FOOTER_LEN)..end],
        bytes.len() as u64,
    )?;
    let covered = usize::try_from(footer.summary_start)
        .ok()
        .and_then(|start| bytes.get(start..end - 4))
        .ok_or_else(|| corrupt("the footer's summary start is past the footer"))?;
    footer.check_crc(crc32fast::hash(covered))?;
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
    let mut decoder = Decoder::default();
    raw.into_iter().map(|m| decode(&mut decoder, m)).collect()
}

pub(crate) fn decode(
    decoder: &mut Decoder,
    message: mcap::Message<'_>,
) -> Result<LogMessage, LogError> {
    let data = decoder.decode(&message).map_err(|error| {
        corrupt(&format!(
            "message {} on {}: {error}",
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

/// Reads every message of the log file at `path`, with the checks of
/// [`read_log`], streaming the file (see [`LogFile`]) rather than loading it.
pub fn read_log_file(path: &Path) -> Result<Vec<LogMessage>, LogError> {
    LogFile::open(path)?.messages()?.collect()
}

/// Prefixes a truncated or corrupt log's detail with its path.
pub(crate) fn at(path: &Path) -> impl Fn(LogError) -> LogError + '_ {
    move |error| match error {
        LogError::Truncated { detail } => LogError::Truncated {
            detail: format!("{}: {detail}", path.display()),
        },
        LogError::Corrupt { detail } => LogError::Corrupt {
            detail: format!("{}: {detail}", path.display()),
        },
        other => other,
    }
}

/// Length of the footer record: opcode, length, summary start, summary offset
/// start, summary CRC.
pub(crate) const FOOTER_LEN: usize = 1 + 8 + 8 + 8 + 4;

/// Refuse records longer than this while streaming (a damaged length must
/// not become a huge allocation). A Ricochet chunk is about 1 MiB.
pub(crate) const RECORD_LIMIT: usize = 1 << 30;

/// The footer record's fields.
pub(crate) struct Footer {
    pub(crate) summary_start: u64,
    pub(crate) summary_crc: u32,
}

impl Footer {
    /// Parses the [`FOOTER_LEN`] bytes before the end magic of a file of
    /// `file_len` bytes.
    pub(crate) fn parse(bytes: &[u8], file_len: u64) -> Result<Footer, LogError> {
        let u64_at = |i: usize| u64::from_le_bytes(bytes[i..i + 8].try_into().unwrap_or([0; 8]));
        if bytes.len() != FOOTER_LEN || bytes[0] != mcap::records::op::FOOTER || u64_at(1) != 20 {
            return Err(corrupt("no footer record before the end magic"));
        }
        let footer = Footer {
            summary_start: u64_at(9),
            summary_crc: u32::from_le_bytes(bytes[25..29].try_into().unwrap_or([0; 4])),
        };
        let footer_start = file_len - (mcap::MAGIC.len() + FOOTER_LEN) as u64;
        if footer.summary_start == 0 {
            return Err(corrupt("no summary section; a finished log always has one"));
        }
        if footer.summary_start < mcap::MAGIC.len() as u64 || footer.summary_start > footer_start {
            return Err(corrupt(&format!(
                "the footer puts the summary at byte {}, outside the file",
                footer.summary_start
            )));
        }
        Ok(footer)
    }

    /// Compares the CRC computed over the summary section and the footer's
    /// first fields with the footer's (0 means "not computed").
    pub(crate) fn check_crc(&self, calculated: u32) -> Result<(), LogError> {
        if self.summary_crc != 0 && self.summary_crc != calculated {
            return Err(corrupt(&format!(
                "the summary section is damaged: its CRC is {calculated:#010x}, \
                 the footer says {:#010x}",
                self.summary_crc
            )));
        }
        Ok(())
    }
}

/// Checks the magic bytes at both ends. A finished log ends with them, so a
/// file without them was cut short (or its writer never called `finish`).
pub(crate) fn check_magic(bytes: &[u8]) -> Result<(), LogError> {
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
pub(crate) fn classify(error: McapError, part: &str) -> LogError {
    match error {
        McapError::UnexpectedEof | McapError::UnexpectedEoc => {
            truncated(&format!("{part} ends early: {error}"))
        }
        other => corrupt(&format!("{part}: {other}")),
    }
}

pub(crate) fn truncated(detail: &str) -> LogError {
    LogError::Truncated {
        detail: detail.to_owned(),
    }
}

pub(crate) fn corrupt(detail: &str) -> LogError {
    LogError::Corrupt {
        detail: detail.to_owned(),
    }
}
