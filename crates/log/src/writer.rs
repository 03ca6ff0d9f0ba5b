//! Writing a deterministic, chunked, indexed MCAP log.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use mcap::records::MessageHeader;
use serde::Serialize;

use crate::LogError;
use crate::foxglove::{LOG_SCHEMA, LOG_SCHEMA_NAME, SCENE_UPDATE_SCHEMA, SCENE_UPDATE_SCHEMA_NAME};

/// Target uncompressed size of one chunk: 1 MiB, mcap's default. Foxglove
/// loads a log chunk by chunk, so this bounds what it reads to seek.
const CHUNK_SIZE: u64 = 1024 * 1024;

/// A channel of a [`LogWriter`], returned when the channel is added.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct ChannelId(u16);

/// Writes an MCAP log of JSON messages that Foxglove can open.
///
/// The file is a pure function of the calls made: no wall-clock time, host
/// name or thread count reaches it. Chunks are zstd-compressed on the calling
/// thread (multithreaded zstd output differs from single-threaded output), and
/// the summary lists schemas and channels in id order.
///
/// The log is written to a temporary file next to `path` (`.NAME.XXXXXX.tmp`,
/// in the same directory) and renamed onto `path` only by
/// [`finish`](Self::finish), once it is complete: until then an existing file
/// at `path` is untouched, and an interrupted, killed or failed write never
/// leaves a truncated log there. Call `finish` also after an interrupted run:
/// a log finished early is complete and indexed, it just holds fewer messages.
/// A writer dropped without `finish` removes its temporary file (a process
/// killed outright, by `SIGKILL` for example, leaves it behind). A symbolic
/// link at `path` is followed (the file it names is replaced); an existing
/// `path` that is not a regular file (`/dev/null`, a FIFO) is refused.
pub struct LogWriter {
    path: PathBuf,
    mcap: mcap::Writer<BufWriter<File>>,
    /// The temporary file being written; deleted when dropped unless renamed.
    temp: tempfile::TempPath,
    /// Where the temporary file is renamed to: `path`, or the file it links to.
    target: PathBuf,
    /// Next sequence number of each channel.
    sequences: BTreeMap<ChannelId, u32>,
}

impl LogWriter {
    /// Starts the log that [`finish`](Self::finish) will put at `path`, and
    /// writes the MCAP header, naming `library` (e.g. `"ricochet 0.1.0"`) as
    /// the writer.
    ///
    /// The temporary file is created now, in `path`'s directory, so an
    /// unwritable directory fails before any simulation runs; so does a `path`
    /// that is a directory. A file already at `path` is left as it is until
    /// `finish` replaces it.
    pub fn create(path: &Path, library: &str) -> Result<Self, LogError> {
        let create_error = |source| LogError::Create {
            path: path.to_path_buf(),
            source,
        };
        if path.is_dir() {
            return Err(create_error(std::io::Error::new(
                std::io::ErrorKind::IsADirectory,
                "is a directory",
            )));
        }
        // An existing output that is not a regular file (`/dev/null`, a FIFO, a terminal)
        // can't take a renamed file (it would replace the device), nor an MCAP log written
        // in place (the writer seeks back to finish it).
        if std::fs::metadata(path).is_ok_and(|m| !m.is_file()) {
            return Err(create_error(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "is not a regular file; a log is written to a file",
            )));
        }
        // An existing symbolic link is followed: the log replaces the file it points to.
        let target = match std::fs::symlink_metadata(path) {
            Ok(m) if m.file_type().is_symlink() => path.canonicalize().map_err(create_error)?,
            _ => path.to_path_buf(),
        };
        let name = target
            .file_name()
            .ok_or_else(|| {
                create_error(std::io::Error::new(
                    std::io::ErrorKind::InvalidInput,
                    "names no file",
                ))
            })?
            .to_string_lossy()
            .into_owned();
        let dir = match target.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        let prefix = format!(".{name}.");
        let mut builder = tempfile::Builder::new();
        builder.prefix(&prefix).suffix(".tmp");
        #[cfg(unix)]
        {
            // Read and write for all, less the umask: what `File::create` gives.
            use std::os::unix::fs::PermissionsExt;
            builder.permissions(std::fs::Permissions::from_mode(0o666));
        }
        let (file, temp) = builder.tempfile_in(dir).map_err(create_error)?.into_parts();
        let path = path.to_path_buf();
        let options = mcap::WriteOptions::new()
            .library(library)
            .profile("")
            .use_chunks(true)
            .chunk_size(Some(CHUNK_SIZE))
            .compression(Some(mcap::Compression::Zstd))
            .compression_level(0)
            .compression_threads(0);
        let mcap = options
            .create(BufWriter::new(file))
            .map_err(|source| LogError::Write {
                path: path.clone(),
                source,
            })?;
        Ok(Self {
            path,
            mcap,
            temp,
            target,
            sequences: BTreeMap::new(),
        })
    }

    /// Adds a channel on `topic` whose messages are JSON (message encoding
    /// `json`) described by the JSON Schema `schema_json` named
    /// `schema_name` (schema encoding `jsonschema`).
    ///
    /// Adding the same topic and schema again returns the same channel.
    pub fn add_json_channel(
        &mut self,
        topic: &str,
        schema_name: &str,
        schema_json: &str,
    ) -> Result<ChannelId, LogError> {
        let schema_id = self
            .mcap
            .add_schema(schema_name, "jsonschema", schema_json.as_bytes())
            .map_err(|source| self.write_error(source))?;
        let channel_id = self
            .mcap
            .add_channel(schema_id, topic, "json", &BTreeMap::new())
            .map_err(|source| self.write_error(source))?;
        Ok(ChannelId(channel_id))
    }

    /// Adds a `foxglove.SceneUpdate` channel on `topic`, for
    /// [`SceneUpdate`](crate::foxglove::SceneUpdate) messages.
    pub fn add_scene_channel(&mut self, topic: &str) -> Result<ChannelId, LogError> {
        self.add_json_channel(topic, SCENE_UPDATE_SCHEMA_NAME, SCENE_UPDATE_SCHEMA)
    }

    /// Adds a `foxglove.Log` channel on `topic`, for
    /// [`Log`](crate::foxglove::Log) messages.
    pub fn add_log_channel(&mut self, topic: &str) -> Result<ChannelId, LogError> {
        self.add_json_channel(topic, LOG_SCHEMA_NAME, LOG_SCHEMA)
    }

    /// Writes `message` as compact JSON on `channel` at simulation time
    /// `time_ns` (both the log and publish time). Its sequence number is the
    /// count of messages written on `channel` before it.
    ///
    /// Floating-point fields of `message` must be finite: `serde_json`
    /// writes NaN and the infinities as `null`.
    pub fn write<T: Serialize>(
        &mut self,
        channel: ChannelId,
        time_ns: u64,
        message: &T,
    ) -> Result<(), LogError> {
        let data = serde_json::to_vec(message)?;
        let sequence = self.sequences.get(&channel).copied().unwrap_or(0);
        let header = MessageHeader {
            channel_id: channel.0,
            sequence,
            log_time: time_ns,
            publish_time: time_ns,
        };
        self.mcap
            .write_to_known_channel(&header, &data)
            .map_err(|source| self.write_error(source))?;
        self.sequences.insert(channel, sequence.wrapping_add(1));
        Ok(())
    }

    /// Ends the last chunk, writes the summary (schemas, channels,
    /// statistics, chunk indexes), the footer and the closing magic, flushes
    /// and syncs the file, and renames it onto the path given to
    /// [`create`](Self::create), replacing any file there.
    pub fn finish(mut self) -> Result<(), LogError> {
        self.mcap
            .finish()
            .map_err(|source| self.write_error(source))?;
        let Self {
            path,
            mcap,
            temp,
            target,
            ..
        } = self;
        let io_error = |path: &Path, error: std::io::Error| LogError::Write {
            path: path.to_path_buf(),
            source: mcap::McapError::Io(error),
        };
        let mut file = mcap
            .into_inner()
            .into_inner()
            .map_err(|error| io_error(&path, error.into_error()))?;
        file.flush().map_err(|e| io_error(&path, e))?;
        file.sync_all().map_err(|e| io_error(&path, e))?;
        drop(file);
        temp.persist(&target)
            .map_err(|e| io_error(&path, e.error))?;
        Ok(())
    }

    fn write_error(&self, source: mcap::McapError) -> LogError {
        LogError::Write {
            path: self.path.clone(),
            source,
        }
    }
}
