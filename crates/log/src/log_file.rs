//! A log file read as a stream: opened with every check but the data section's, then its
//! messages one at a time (decoded, or raw to compare bytes), so memory does not grow with
//! the log's length.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::Path;
use std::sync::mpsc;

use mcap::McapError;
use mcap::read::Summary;
use mcap::sans_io::{LinearReaderOptions, SummaryReadEvent, SummaryReader, SummaryReaderOptions};

use crate::LogError;
use crate::decode::{Decoder, descriptor};
use crate::reader::{
    FOOTER_LEN, Footer, RECORD_LIMIT, at, check_magic, classify, corrupt, truncated,
};
use crate::stream::{AHEAD, Messages, read_ahead};

/// One message of a log, not yet decoded: what [`Messages::next_raw`] yields.
pub struct RawMessage {
    pub(crate) inner: mcap::Message<'static>,
}

impl RawMessage {
    /// Topic of the message's channel.
    pub fn topic(&self) -> &str {
        &self.inner.channel.topic
    }

    /// Log time, nanoseconds of simulation time.
    pub fn log_time(&self) -> u64 {
        self.inner.log_time
    }

    /// The encoded payload.
    pub fn bytes(&self) -> &[u8] {
        &self.inner.data
    }
}

/// One channel of a log, from its summary.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ChannelInfo {
    /// Topic.
    pub topic: String,
    /// Name of the channel's schema, or empty without one.
    pub schema_name: String,
    /// Encoding of the schema (`jsonschema`), or empty without one.
    pub schema_encoding: String,
    /// The schema's data (for protobuf, its FileDescriptorSet), or empty without one.
    pub schema_data: Vec<u8>,
    /// Encoding of the messages (`json`).
    pub message_encoding: String,
    /// How many messages the channel holds, by the summary's statistics.
    pub messages: u64,
}

/// A log file opened for streaming: its two ends, footer, header and summary
/// (with the summary's CRC) are checked when it is opened, and its messages
/// are read one at a time by [`messages`](Self::messages), so memory does not
/// grow with the log's length.
#[derive(Debug)]
pub struct LogFile {
    /// The path it was opened by, for messages.
    path: std::path::PathBuf,
    /// What its messages are read from.
    source: Source,
    library: String,
    /// By channel id.
    channels: BTreeMap<u16, ChannelInfo>,
    total: u64,
    /// The attachments: name, offset and length of the record (opcode and length included).
    attachments: Vec<(String, u64, u64)>,
    /// Where its summary starts: what is before it is the header and the data section.
    summary_start: u64,
}

impl LogFile {
    /// Opens the log at `path` and checks everything but its data section:
    /// the magic at both ends, the footer, the summary's CRC, the summary
    /// (schemas, channels, statistics) and the header. A file cut short is
    /// [`LogError::Truncated`], other damage [`LogError::Corrupt`].
    pub fn open(path: &Path) -> Result<LogFile, LogError> {
        Self::open_inner(path).map_err(at(path))
    }

    fn open_inner(path: &Path) -> Result<LogFile, LogError> {
        let read_error = |source| LogError::Read {
            path: path.to_path_buf(),
            source,
        };
        let mut file = File::open(path).map_err(read_error)?;
        let meta = file.metadata().map_err(read_error)?;
        if !meta.is_file() {
            // A pipe (`<(zcat log.mcap.gz)`) can be read once only: copied to a temporary
            // file first, which is then streamed as many times as needed.
            let mut copy = tempfile::NamedTempFile::new().map_err(read_error)?;
            std::io::copy(&mut file, &mut copy).map_err(read_error)?;
            let copy = copy.into_temp_path();
            let mut log = Self::open_inner(&copy)?;
            log.path = path.to_path_buf();
            log.source = Source::Copy(copy);
            return Ok(log);
        }
        let len = meta.len();
        let magic = mcap::MAGIC.len() as u64;
        // The first bytes and the last ones, as `check_magic` wants them.
        if len < 2 * magic {
            let mut all = Vec::new();
            file.read_to_end(&mut all).map_err(read_error)?;
            check_magic(&all)?;
            return Err(truncated("too short to be a log"));
        }
        let mut head = vec![0; magic as usize];
        file.read_exact(&mut head).map_err(read_error)?;
        let tail_len = len.min(magic + FOOTER_LEN as u64);
        let mut tail = vec![0; tail_len as usize];
        file.seek(SeekFrom::Start(len - tail_len))
            .map_err(read_error)?;
        file.read_exact(&mut tail).map_err(read_error)?;
        if head != mcap::MAGIC {
            return Err(corrupt(
                "does not start with the MCAP magic: not an MCAP file",
            ));
        }
        if tail[tail.len() - magic as usize..] != *mcap::MAGIC {
            return Err(truncated(&format!(
                "{len} bytes that do not end with the MCAP magic: the file was cut short, \
                 or its writer stopped before finishing it"
            )));
        }
        if tail.len() < magic as usize + FOOTER_LEN {
            return Err(corrupt("too short to hold a footer"));
        }
        let footer = Footer::parse(&tail[..FOOTER_LEN], len)?;

        // The summary's CRC covers it and the footer up to the CRC field.
        let crc_end = len - magic - 4;
        file.seek(SeekFrom::Start(footer.summary_start))
            .map_err(read_error)?;
        let mut hasher = crc32fast::Hasher::new();
        let mut covered = (&mut file).take(crc_end - footer.summary_start);
        let mut buf = vec![0; 64 * 1024];
        loop {
            let n = covered.read(&mut buf).map_err(read_error)?;
            if n == 0 {
                break;
            }
            hasher.update(&buf[..n]);
        }
        footer.check_crc(hasher.finalize())?;

        let summary = read_summary(&mut file, len).map_err(|e| classify(e, "summary"))?;
        let summary =
            summary.ok_or_else(|| corrupt("no summary section; a finished log always has one"))?;
        let stats = summary
            .stats
            .ok_or_else(|| corrupt("no statistics record; a finished log always has one"))?;
        let mut channels = BTreeMap::new();
        for (id, channel) in &summary.channels {
            let (schema_name, schema_encoding, schema_data) = channel
                .schema
                .as_ref()
                .map(|s| (s.name.clone(), s.encoding.clone(), s.data.to_vec()))
                .unwrap_or_default();
            // A protobuf channel's messages are only as readable as its schema: one that
            // does not decode, or does not define the type it names, damages every message
            // (checked here, not at the first message, so that a reader that compares bytes
            // without decoding them can't take the channel as sound).
            if channel.message_encoding == "protobuf" {
                let why = if channel.schema.is_none() {
                    Some("a protobuf channel without a schema".to_owned())
                } else if schema_encoding != "protobuf" {
                    Some(format!(
                        "protobuf messages with a {schema_encoding:?} schema, not a protobuf one"
                    ))
                } else {
                    descriptor(&schema_name, &schema_data).err()
                };
                if let Some(why) = why {
                    return Err(corrupt(&format!("channel {}: {why}", channel.topic)));
                }
            }
            channels.insert(
                *id,
                ChannelInfo {
                    topic: channel.topic.clone(),
                    schema_name,
                    schema_encoding,
                    schema_data,
                    message_encoding: channel.message_encoding.clone(),
                    messages: stats.channel_message_counts.get(id).copied().unwrap_or(0),
                },
            );
        }
        let counted: u64 = channels.values().map(|c| c.messages).sum();
        if counted != stats.message_count
            || stats
                .channel_message_counts
                .keys()
                .any(|id| !channels.contains_key(id))
        {
            return Err(corrupt(&format!(
                "the statistics count {} messages, but {counted} on the summary's channels",
                stats.message_count
            )));
        }
        let library = read_library(&mut file, len)?;
        let attachments = summary
            .attachment_indexes
            .iter()
            .map(|a| (a.name.clone(), a.offset, a.length))
            .collect();
        Ok(LogFile {
            attachments,
            path: path.to_path_buf(),
            source: Source::File(path.to_path_buf()),
            library,
            channels,
            total: stats.message_count,
            summary_start: footer.summary_start,
        })
    }

    /// The names of its attachments, in the order the summary indexes them (a name may
    /// come more than once).
    pub fn attachment_names(&self) -> impl Iterator<Item = &str> {
        self.attachments.iter().map(|a| a.0.as_str())
    }

    /// The data of the first attachment named `name`, if the log has one; its CRC checked.
    pub fn attachment(&self, name: &str) -> Result<Option<Vec<u8>>, LogError> {
        let Some(&(_, offset, length)) = self.attachments.iter().find(|a| a.0 == name) else {
            return Ok(None);
        };
        let from: &Path = match &self.source {
            Source::File(p) => p,
            Source::Copy(t) => t,
        };
        let read_error = |source| LogError::Read {
            path: self.path.clone(),
            source,
        };
        let mut file = File::open(from).map_err(read_error)?;
        let length = usize::try_from(length)
            .ok()
            .filter(|l| (9..RECORD_LIMIT).contains(l))
            .ok_or_else(|| at(&self.path)(corrupt("an attachment's index gives a bad length")))?;
        let mut record = vec![0; length];
        file.seek(SeekFrom::Start(offset))
            .and_then(|_| file.read_exact(&mut record))
            .map_err(read_error)?;
        match mcap::parse_record(record[0], &record[9..]) {
            Ok(mcap::records::Record::Attachment { data, crc, .. }) => {
                if crc != 0 {
                    let mut hasher = crc32fast::Hasher::new();
                    hasher.update(&record[9..record.len() - 4]);
                    if hasher.finalize() != crc {
                        return Err(at(&self.path)(corrupt(&format!(
                            "attachment {name}: its CRC does not match"
                        ))));
                    }
                }
                Ok(Some(data.into_owned()))
            }
            _ => Err(at(&self.path)(corrupt(&format!(
                "attachment {name}: no attachment record where the index points"
            )))),
        }
    }

    /// Whether `other` holds the same messages on the same channels as this log because it
    /// holds the same bytes: the same channels in its summary (ids, topics, schemas, message
    /// counts), and the same bytes from its start to its summary (magic, header, and the
    /// whole data section: its chunks, with their CRCs, and the data section's CRC). Reading
    /// this log's messages then checks both (two logs compared with themselves, or a golden
    /// log with a fresh recording that matches it, are read once). Reads both files in blocks,
    /// up to the first byte that differs.
    pub(crate) fn same_data(&self, other: &LogFile) -> Result<bool, LogError> {
        if self.channels != other.channels || self.summary_start != other.summary_start {
            return Ok(false);
        }
        let (mut fa, mut fb) = (self.open_source()?, other.open_source()?);
        let error_a = |source| LogError::Read {
            path: self.path.clone(),
            source,
        };
        let error_b = |source| LogError::Read {
            path: other.path.clone(),
            source,
        };
        let mut left = self.summary_start;
        let (mut ba, mut bb) = (vec![0; 1 << 20], vec![0; 1 << 20]);
        while left > 0 {
            let n = left.min(ba.len() as u64) as usize;
            fa.read_exact(&mut ba[..n]).map_err(error_a)?;
            fb.read_exact(&mut bb[..n]).map_err(error_b)?;
            if ba[..n] != bb[..n] {
                return Ok(false);
            }
            left -= n as u64;
        }
        Ok(true)
    }

    /// The file its data is read from: itself, or the copy of what a pipe held.
    fn open_source(&self) -> Result<File, LogError> {
        let from: &Path = match &self.source {
            Source::File(p) => p,
            Source::Copy(t) => t,
        };
        File::open(from).map_err(|source| LogError::Read {
            path: self.path.clone(),
            source,
        })
    }

    /// The `library` its header names as the writer (`ricochet 0.1.0`).
    pub fn library(&self) -> &str {
        &self.library
    }

    /// Its channels, in channel id order.
    pub fn channels(&self) -> impl Iterator<Item = &ChannelInfo> {
        self.channels.values()
    }

    /// How many messages it holds, by its statistics.
    pub fn message_count(&self) -> u64 {
        self.total
    }

    /// Every message, in file order, decoded one at a time.
    pub fn messages(&self) -> Result<Messages, LogError> {
        self.stream(None)
    }

    /// The messages on `topic`, in file order. The whole file is still read
    /// and checked (the data section holds every topic).
    pub fn topic_messages(&self, topic: &str) -> Result<Messages, LogError> {
        self.stream(Some(topic.to_owned()))
    }

    fn stream(&self, topic: Option<String>) -> Result<Messages, LogError> {
        let from: &Path = match &self.source {
            Source::File(p) => p,
            Source::Copy(t) => t,
        };
        let read_error = |source| LogError::Read {
            path: self.path.clone(),
            source,
        };
        let file = File::open(from).map_err(read_error)?;
        let options = LinearReaderOptions::default()
            .with_prevalidate_chunk_crcs(true)
            .with_validate_data_section_crc(true)
            .with_validate_summary_section_crc(true)
            .with_check_finishes_after_end_magic(true)
            .with_record_length_limit(RECORD_LIMIT);
        let reader = mcap::io::MessageReader::new_with_options(BufReader::new(file), options);
        // Reading (decompressing and checking the CRCs) is most of the work of comparing
        // two logs byte for byte: each log is read on a thread of its own, a few messages
        // ahead of its reader, so two logs are read at the same time on two cores.
        let (sender, incoming) = mpsc::sync_channel(AHEAD);
        let reading = std::thread::Builder::new()
            .name("log reader".to_owned())
            .spawn(move || read_ahead(reader, &sender))
            .map_err(read_error)?;
        Ok(Messages {
            incoming: Some(incoming),
            reading: Some(reading),
            topic,
            path: self.path.clone(),
            expected: self
                .channels
                .iter()
                .filter(|(_, c)| c.messages > 0)
                .map(|(id, c)| (*id, c.messages))
                .collect(),
            counts: BTreeMap::new(),
            done: false,
            decoder: Decoder::default(),
        })
    }
}

/// Where a [`LogFile`]'s messages are read from.
#[derive(Debug)]
enum Source {
    /// The file itself.
    File(std::path::PathBuf),
    /// A copy of what a pipe held, deleted with the `LogFile`.
    Copy(tempfile::TempPath),
}

/// Reads the summary section through mcap's sans-io summary reader.
fn read_summary(file: &mut File, len: u64) -> Result<Option<Summary>, McapError> {
    let options = SummaryReaderOptions::default()
        .with_file_size(len)
        .with_record_length_limit(RECORD_LIMIT);
    let mut reader = SummaryReader::new_with_options(options);
    while let Some(event) = reader.next_event() {
        match event? {
            SummaryReadEvent::ReadRequest(need) => {
                let n = file.read(reader.insert(need))?;
                reader.notify_read(n);
            }
            SummaryReadEvent::SeekRequest(to) => reader.notify_seeked(file.seek(to)?),
        }
    }
    Ok(reader.finish())
}

/// Reads the `library` field of the header record, right after the magic.
fn read_library(file: &mut File, len: u64) -> Result<String, LogError> {
    let no_header = || corrupt("no header record after the magic");
    let magic = mcap::MAGIC.len() as u64;
    let mut op_len = [0; 9];
    file.seek(SeekFrom::Start(magic))
        .and_then(|_| file.read_exact(&mut op_len))
        .map_err(|_| no_header())?;
    let record_len = u64::from_le_bytes(op_len[1..].try_into().unwrap_or([0; 8]));
    if op_len[0] != mcap::records::op::HEADER || record_len > len.saturating_sub(magic + 9) {
        return Err(no_header());
    }
    let mut data = vec![0; record_len as usize];
    file.read_exact(&mut data).map_err(|_| no_header())?;
    match mcap::parse_record(mcap::records::op::HEADER, &data) {
        Ok(mcap::records::Record::Header(header)) => Ok(header.library),
        _ => Err(no_header()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A log of `payloads` on one `/stats` channel (their content does not matter here).
    fn write(path: &Path, payloads: &[&[u8]]) -> LogFile {
        let mut w = mcap::WriteOptions::new()
            .library("ricochet test")
            .create(std::io::BufWriter::new(File::create(path).unwrap()))
            .unwrap();
        let schema = crate::Schema::ricochet("ricochet.Stats");
        let sid = w
            .add_schema(&schema.name, &schema.encoding, &schema.data)
            .unwrap();
        let ch = w
            .add_channel(sid, "/stats", "protobuf", &Default::default())
            .unwrap();
        for (i, payload) in payloads.iter().enumerate() {
            let header = mcap::records::MessageHeader {
                channel_id: ch,
                sequence: i as u32,
                log_time: i as u64,
                publish_time: i as u64,
            };
            w.write_to_known_channel(&header, payload).unwrap();
        }
        w.finish().unwrap();
        LogFile::open(path).unwrap()
    }

    #[test]
    fn same_data_is_the_same_channels_and_bytes_up_to_the_summary() {
        let dir = tempfile::tempdir().unwrap();
        let at = |name: &str| dir.path().join(name);
        let a = write(&at("a"), &[b"\x08\x01", b"\x08\x02"]);
        let same = write(&at("same"), &[b"\x08\x01", b"\x08\x02"]);
        // One byte of one message differs: the same channels, other bytes.
        let other = write(&at("other"), &[b"\x08\x01", b"\x08\x03"]);
        // One message fewer: other counts in the summary.
        let fewer = write(&at("fewer"), &[b"\x08\x01"]);
        assert!(a.same_data(&same).unwrap() && same.same_data(&a).unwrap());
        assert!(!a.same_data(&other).unwrap() && !other.same_data(&a).unwrap());
        assert!(!a.same_data(&fewer).unwrap() && !fewer.same_data(&a).unwrap());
    }
}
