//! Writing a deterministic, chunked, indexed MCAP log, encoding and compressing on a
//! writer thread (the caller sharing the encoding when that thread falls behind).

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc;
use std::thread::JoinHandle;

use mcap::records::MessageHeader;
use serde::Serialize;

use crate::LogError;
use crate::backlog::{Backlog, CloseOnDrop};
use crate::messages::Schema;
use crate::sink::ChannelId;

/// Target uncompressed size of one chunk: 1 MiB, mcap's default. Foxglove
/// loads a log chunk by chunk, so this bounds what it reads to seek.
const CHUNK_SIZE: u64 = 1024 * 1024;

/// Messages queued for the writer thread before [`LogWriter::write`] waits: bounds the
/// memory a fast simulation can fill while the thread compresses, with [`QUEUE_BYTES`].
/// A frame is a few messages, so the caller can run some 250 frames ahead: it no longer
/// waits for the thread after a frame that hands it much (the first, a drawing).
const QUEUE: usize = 1024;

/// Bytes of encoded messages (a big scene's drawings: 1.5 MB for 10,000 bodies) queued for
/// the writer thread before [`LogWriter::write`] waits (see `backlog.rs`).
const QUEUE_BYTES: usize = 64 << 20;

/// Jobs queued for the writer thread from which [`LogWriter::write`] encodes the message
/// on the caller's thread by default (see [`LogWriter::share_encoding_from`]).
pub const SHARE_ENCODING_FROM: usize = 32;

/// Where a [`LogWriter`] encodes and compresses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Threading {
    /// On a writer thread of its own (the default): the caller only builds messages.
    #[default]
    Thread,
    /// On the calling thread. The file is byte-identical to [`Threading::Thread`]'s.
    Inline,
}

/// A message to encode: already bytes (JSON), or a protobuf message encoded where the
/// MCAP writer runs.
enum Payload {
    Bytes(Vec<u8>),
    Proto(Box<dyn Encodable>),
}

/// A protobuf message that can be sent to the writer thread.
trait Encodable: Send {
    fn encode_into(&self, buf: &mut Vec<u8>);
}

impl<M: prost::Message + Send> Encodable for M {
    fn encode_into(&self, buf: &mut Vec<u8>) {
        // A Vec grows as needed: encoding into one never runs out of room.
        self.encode_raw(buf);
    }
}

/// One call on the MCAP writer, in the order the [`LogWriter`] received it.
enum Job {
    Channel {
        topic: String,
        schema: Schema,
        message_encoding: &'static str,
        reply: mpsc::Sender<Result<u16, mcap::McapError>>,
    },
    Message {
        header: MessageHeader,
        payload: Payload,
    },
    Attachment {
        name: String,
        media_type: String,
        data: Vec<u8>,
    },
}

impl Job {
    /// The bytes of the encoded message it carries, counted in the writer's backlog (a
    /// message still to encode is counted as a job only).
    fn encoded_bytes(&self) -> usize {
        match self {
            Job::Message {
                payload: Payload::Bytes(b),
                ..
            } => b.len(),
            _ => 0,
        }
    }
}

/// The MCAP writer and its encode buffer: runs the jobs, on whichever thread owns it.
struct Sink {
    mcap: mcap::Writer<BufWriter<File>>,
    buf: Vec<u8>,
}

impl Sink {
    fn run(&mut self, job: Job) -> Result<(), mcap::McapError> {
        match job {
            Job::Channel {
                topic,
                schema,
                message_encoding,
                reply,
            } => {
                let id = self.add_channel(&topic, &schema, message_encoding);
                // The caller waits on the reply (and reports an error); it is gone only if
                // it gave up.
                let _ = reply.send(id);
                Ok(())
            }
            Job::Message { header, payload } => {
                let data = match &payload {
                    Payload::Bytes(b) => b.as_slice(),
                    Payload::Proto(m) => {
                        self.buf.clear();
                        m.encode_into(&mut self.buf);
                        self.buf.as_slice()
                    }
                };
                self.mcap.write_to_known_channel(&header, data)
            }
            Job::Attachment {
                name,
                media_type,
                data,
            } => self.mcap.attach(&mcap::Attachment {
                log_time: 0,
                create_time: 0,
                name,
                media_type,
                data: std::borrow::Cow::Owned(data),
            }),
        }
    }

    fn add_channel(
        &mut self,
        topic: &str,
        schema: &Schema,
        message_encoding: &str,
    ) -> Result<u16, mcap::McapError> {
        let schema_id = self
            .mcap
            .add_schema(&schema.name, &schema.encoding, &schema.data)?;
        self.mcap
            .add_channel(schema_id, topic, message_encoding, &BTreeMap::new())
    }
}

/// The sink, on this thread or on the writer thread.
enum Engine {
    Inline(Box<Sink>),
    Thread {
        jobs: mpsc::SyncSender<Job>,
        thread: JoinHandle<Result<Sink, mcap::McapError>>,
        /// Jobs sent and not yet run (the thread counts them down).
        queued: Arc<AtomicUsize>,
        /// From this many queued jobs, [`LogWriter::write`] encodes on the caller's thread.
        share_from: usize,
        /// The bytes of encoded messages queued.
        backlog: Arc<Backlog>,
    },
    /// Between a failure and the error's report.
    Failed,
}

/// Writes an MCAP log of protobuf (or JSON) messages that Foxglove can open.
///
/// The file is a pure function of the calls made: no wall-clock time, host
/// name or thread count reaches it. Messages are encoded and chunks
/// LZ4-compressed on one writer thread (or inline, see [`Threading`]), in the
/// order the calls were made, so the bytes are the same either way; when the
/// writer thread falls behind, the caller encodes messages itself (see
/// [`share_encoding_from`](Self::share_encoding_from)), with the same bytes
/// again. The compressor itself runs single-threaded. The summary lists schemas and
/// channels in id order.
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
    engine: Engine,
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
    /// the writer. Encodes on a writer thread; see [`create_with`](Self::create_with).
    ///
    /// The temporary file is created now, in `path`'s directory, so an
    /// unwritable directory fails before any simulation runs; so does a `path`
    /// that is a directory. A file already at `path` is left as it is until
    /// `finish` replaces it.
    pub fn create(path: &Path, library: &str) -> Result<Self, LogError> {
        Self::create_with(path, library, Threading::Thread)
    }

    /// [`create`](Self::create), encoding and compressing where `threading` says.
    pub fn create_with(path: &Path, library: &str, threading: Threading) -> Result<Self, LogError> {
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
            // LZ4 (the MCAP format's other compression; Foxglove and the official
            // readers take both): on the 10,000-asteroid level the log is 13.2 MB
            // against zstd level 1's 9.0 MB, and the writer thread spends about half as
            // long a byte, which recording at half the simulation's rate needs (issue
            // #37, BENCHMARKS.md "LZ4 chunks"). Levels below 3 are LZ4's fast mode.
            .compression(Some(mcap::Compression::Lz4))
            .compression_level(1)
            .compression_threads(0);
        let mcap = options
            .create(BufWriter::new(file))
            .map_err(|source| LogError::Write {
                path: path.clone(),
                source,
            })?;
        let sink = Sink {
            mcap,
            buf: Vec::new(),
        };
        let engine = match threading {
            Threading::Inline => Engine::Inline(Box::new(sink)),
            Threading::Thread => {
                let (jobs, queue) = mpsc::sync_channel::<Job>(QUEUE);
                let queued = Arc::new(AtomicUsize::new(0));
                let ran = Arc::clone(&queued);
                let backlog = Arc::new(Backlog::new(QUEUE_BYTES));
                let written = Arc::clone(&backlog);
                let thread = std::thread::Builder::new()
                    .name("log-writer".into())
                    .spawn(move || {
                        let _close = CloseOnDrop(&written);
                        let mut sink = sink;
                        for job in queue {
                            let bytes = job.encoded_bytes();
                            sink.run(job)?;
                            written.take(bytes);
                            ran.fetch_sub(1, Ordering::Relaxed);
                        }
                        Ok(sink)
                    })
                    .map_err(|e| LogError::Write {
                        path: path.clone(),
                        source: mcap::McapError::Io(e),
                    })?;
                Engine::Thread {
                    jobs,
                    thread,
                    queued,
                    share_from: SHARE_ENCODING_FROM,
                    backlog,
                }
            }
        };
        Ok(Self {
            path,
            engine,
            temp,
            target,
            sequences: BTreeMap::new(),
        })
    }

    /// Adds a channel on `topic` whose messages are encoded as `message_encoding`
    /// (`protobuf` or `json`) and described by `schema`. Adding the same topic and schema
    /// again returns the same channel.
    pub fn add_channel(
        &mut self,
        topic: &str,
        schema: Schema,
        message_encoding: &'static str,
    ) -> Result<ChannelId, LogError> {
        let (reply, answer) = mpsc::channel();
        self.submit(Job::Channel {
            topic: topic.to_owned(),
            schema,
            message_encoding,
            reply,
        })?;
        match answer.recv() {
            Ok(Ok(id)) => Ok(ChannelId(id)),
            Ok(Err(source)) => Err(self.write_error(source)),
            // The writer thread stopped: its error says why.
            Err(_) => Err(self.fail()),
        }
    }

    /// Adds a channel on `topic` for protobuf messages of type `schema.name`, whose
    /// `schema.data` is a FileDescriptorSet that defines it (MCAP's protobuf profile).
    pub fn add_protobuf_channel(
        &mut self,
        topic: &str,
        schema: Schema,
    ) -> Result<ChannelId, LogError> {
        self.add_channel(topic, schema, "protobuf")
    }

    /// Adds a channel on `topic` for the official Foxglove message type `T`
    /// (`SceneUpdate`, `FrameTransforms`, `Log`, ... from [`fox`](crate::messages::fox)).
    pub fn add_foxglove_channel<T: foxglove::Encode>(
        &mut self,
        topic: &str,
    ) -> Result<ChannelId, LogError> {
        self.add_protobuf_channel(topic, Schema::foxglove::<T>())
    }

    /// Adds a channel on `topic` whose messages are JSON (message encoding
    /// `json`) described by the JSON Schema `schema_json` named
    /// `schema_name` (schema encoding `jsonschema`).
    pub fn add_json_channel(
        &mut self,
        topic: &str,
        schema_name: &str,
        schema_json: &str,
    ) -> Result<ChannelId, LogError> {
        let schema = Schema {
            name: schema_name.to_owned(),
            encoding: "jsonschema".to_owned(),
            data: schema_json.as_bytes().to_vec(),
        };
        self.add_channel(topic, schema, "json")
    }

    /// Writes the protobuf `message` on `channel` at simulation time `time_ns` (both the
    /// log and publish time). Its sequence number is the count of messages written on
    /// `channel` before it. The message is encoded on the writer thread, or here when that
    /// thread is behind (the same bytes either way).
    pub fn write<M: prost::Message + Send + 'static>(
        &mut self,
        channel: ChannelId,
        time_ns: u64,
        message: M,
    ) -> Result<(), LogError> {
        let payload = match &self.engine {
            Engine::Thread {
                queued, share_from, ..
            } if queued.load(Ordering::Relaxed) >= *share_from => {
                Payload::Bytes(message.encode_to_vec())
            }
            _ => Payload::Proto(Box::new(message)),
        };
        self.write_payload(channel, time_ns, payload)
    }

    /// Encodes a message on the caller's thread, in [`write`](Self::write), once `jobs`
    /// jobs are queued for the writer thread ([`SHARE_ENCODING_FROM`] by default; 0: every
    /// message, `usize::MAX`: none). A queue that long means the writer is behind, and the
    /// caller, which would soon wait for room, takes a share of its work instead: on the
    /// 10,000-asteroid level the writer thread is the recording's bound (issue #37). Where a
    /// message is encoded never changes the file's bytes, only which core spends the time.
    /// Nothing changes with [`Threading::Inline`].
    pub fn share_encoding_from(&mut self, jobs: usize) {
        if let Engine::Thread { share_from, .. } = &mut self.engine {
            *share_from = jobs;
        }
    }

    /// Writes `bytes`, one message already encoded as `channel`'s schema says (protobuf, or
    /// JSON on a JSON channel), like [`write`](Self::write): for a caller that encodes a
    /// message once for the log and for something else (`ricochet serve`'s live stream).
    pub fn write_encoded(
        &mut self,
        channel: ChannelId,
        time_ns: u64,
        bytes: Vec<u8>,
    ) -> Result<(), LogError> {
        self.write_payload(channel, time_ns, Payload::Bytes(bytes))
    }

    /// Attaches a file to the log (an MCAP attachment, times 0): `ricochet serve` attaches
    /// the scenario, so that `ricochet replay` needs nothing but the log.
    pub fn attach(&mut self, name: &str, media_type: &str, data: &[u8]) -> Result<(), LogError> {
        self.submit(Job::Attachment {
            name: name.to_owned(),
            media_type: media_type.to_owned(),
            data: data.to_vec(),
        })
    }

    /// Writes `message` as compact JSON on `channel` (a JSON channel), like
    /// [`write`](Self::write). Floating-point fields of `message` must be finite:
    /// `serde_json` writes NaN and the infinities as `null`.
    pub fn write_json<T: Serialize>(
        &mut self,
        channel: ChannelId,
        time_ns: u64,
        message: &T,
    ) -> Result<(), LogError> {
        let data = serde_json::to_vec(message)?;
        self.write_payload(channel, time_ns, Payload::Bytes(data))
    }

    fn write_payload(
        &mut self,
        channel: ChannelId,
        time_ns: u64,
        payload: Payload,
    ) -> Result<(), LogError> {
        let sequence = self.sequences.get(&channel).copied().unwrap_or(0);
        let header = MessageHeader {
            channel_id: channel.0,
            sequence,
            log_time: time_ns,
            publish_time: time_ns,
        };
        self.submit(Job::Message { header, payload })?;
        self.sequences.insert(channel, sequence.wrapping_add(1));
        Ok(())
    }

    /// Runs `job` inline, or queues it for the writer thread (waiting while the queue is
    /// full). A failure of the thread is reported by the next call.
    fn submit(&mut self, job: Job) -> Result<(), LogError> {
        match &mut self.engine {
            Engine::Inline(sink) => sink.run(job).map_err(|source| self.write_error(source)),
            Engine::Thread {
                jobs,
                queued,
                backlog,
                ..
            } => {
                backlog.add(job.encoded_bytes());
                queued.fetch_add(1, Ordering::Relaxed);
                match jobs.send(job) {
                    Ok(()) => Ok(()),
                    Err(_) => Err(self.fail()),
                }
            }
            Engine::Failed => Err(self.write_error(mcap::McapError::Io(std::io::Error::other(
                "the log writer failed before",
            )))),
        }
    }

    /// Stops the writer thread and returns its error.
    fn fail(&mut self) -> LogError {
        match self.take_sink() {
            Ok(_) => self.write_error(mcap::McapError::Io(std::io::Error::other(
                "the log writer thread stopped",
            ))),
            Err(e) => e,
        }
    }

    /// The sink, back from the writer thread once it has run every queued job.
    fn take_sink(&mut self) -> Result<Sink, LogError> {
        match std::mem::replace(&mut self.engine, Engine::Failed) {
            Engine::Inline(sink) => Ok(*sink),
            Engine::Thread { jobs, thread, .. } => {
                drop(jobs);
                match thread.join() {
                    Ok(Ok(sink)) => Ok(sink),
                    Ok(Err(source)) => Err(self.write_error(source)),
                    Err(panic) => std::panic::resume_unwind(panic),
                }
            }
            Engine::Failed => Err(self.write_error(mcap::McapError::Io(std::io::Error::other(
                "the log writer failed before",
            )))),
        }
    }

    /// Ends the last chunk, writes the summary (schemas, channels,
    /// statistics, chunk indexes), the footer and the closing magic, flushes
    /// and syncs the file, and renames it onto the path given to
    /// [`create`](Self::create), replacing any file there.
    pub fn finish(mut self) -> Result<(), LogError> {
        let mut sink = self.take_sink()?;
        sink.mcap
            .finish()
            .map_err(|source| self.write_error(source))?;
        let Self {
            path, temp, target, ..
        } = self;
        let io_error = |path: &Path, error: std::io::Error| LogError::Write {
            path: path.to_path_buf(),
            source: mcap::McapError::Io(error),
        };
        let mut file = sink
            .mcap
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
