//! The messages of a [`LogFile`](crate::LogFile) as a stream: a thread reads ahead a few
//! messages, and [`Messages`] checks and decodes them one at a time, so memory does not grow
//! with the log's length.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufReader;
use std::sync::mpsc::{Receiver, SyncSender};
use std::thread::JoinHandle;

use mcap::McapError;

use crate::LogError;
use crate::decode::Decoder;
use crate::log_file::RawMessage;
use crate::reader::{LogMessage, at, classify, corrupt, decode};

/// How many messages a log's reading thread may have read that [`Messages`] has not yet
/// taken: memory stays flat (at most this many messages, and the chunk being read).
pub(crate) const AHEAD: usize = 4;

/// What a log's reading thread hands over, in file order.
pub(crate) enum Ahead {
    Message(mcap::Message<'static>),
    /// The reader's error: nothing follows it.
    Failed(McapError),
    /// The last record was read.
    End,
}

/// The body of a log's reading thread: every message in turn, until the end, an error, or
/// [`Messages`] is dropped (the send then fails).
pub(crate) fn read_ahead(
    reader: mcap::io::MessageReader<BufReader<File>>,
    sender: &SyncSender<Ahead>,
) {
    for message in reader {
        let (item, last) = match message {
            Ok(m) => (Ahead::Message(m), false),
            Err(e) => (Ahead::Failed(e), true),
        };
        if sender.send(item).is_err() || last {
            return;
        }
    }
    // Nobody may be left to receive it: that is fine.
    let _ = sender.send(Ahead::End);
}

/// The messages of a [`LogFile`](crate::LogFile), read and decoded one at a time. Chunk CRCs
/// are checked before a chunk's messages are yielded; the data section's CRC,
/// the summary's and the message counts against the statistics at the end.
/// After an error it yields nothing more.
pub struct Messages {
    /// The messages the reading thread has read, `None` once dropped.
    pub(crate) incoming: Option<Receiver<Ahead>>,
    /// The reading thread, joined when this is dropped.
    pub(crate) reading: Option<JoinHandle<()>>,
    pub(crate) topic: Option<String>,
    pub(crate) path: std::path::PathBuf,
    pub(crate) expected: BTreeMap<u16, u64>,
    pub(crate) counts: BTreeMap<u16, u64>,
    pub(crate) done: bool,
    pub(crate) decoder: Decoder,
}

impl Messages {
    fn fail<T>(&mut self, error: LogError) -> Option<Result<T, LogError>> {
        self.done = true;
        Some(Err(at(&self.path)(error)))
    }

    /// The message [`next`](Iterator::next) would yield, with the same checks, but not
    /// decoded: to compare payloads byte for byte before decoding them.
    pub fn next_raw(&mut self) -> Option<Result<RawMessage, LogError>> {
        while !self.done {
            let received = self.incoming.as_ref().map(Receiver::recv);
            let message = match received {
                Some(Ok(Ahead::Message(m))) => Some(Ok(m)),
                Some(Ok(Ahead::Failed(e))) => Some(Err(e)),
                Some(Ok(Ahead::End)) => None,
                // The thread ended without saying why (it panicked): not a log's fault.
                _ => {
                    return self.fail(LogError::Read {
                        path: self.path.clone(),
                        source: std::io::Error::other("the thread reading it stopped"),
                    });
                }
            };
            let Some(message) = message else {
                self.done = true;
                if self.counts != self.expected {
                    return self.fail(corrupt(&format!(
                        "the data section holds {:?} messages (per channel id) but the \
                         summary counts {:?}",
                        self.counts, self.expected
                    )));
                }
                return None;
            };
            let message = match message {
                Ok(m) => m,
                Err(error) => return self.fail(classify(error, "data section")),
            };
            *self.counts.entry(message.channel.id).or_insert(0) += 1;
            if self
                .topic
                .as_ref()
                .is_none_or(|t| *t == message.channel.topic)
            {
                return Some(Ok(RawMessage { inner: message }));
            }
        }
        None
    }

    /// Checks that the top level of a message [`next_raw`](Self::next_raw) yielded decodes
    /// with its channel's schema (a corrupt log's error if not), without decoding the
    /// messages nested in it: cheap enough for every message, where decoding a big message
    /// whole costs more than reading it.
    pub fn check(&mut self, raw: &RawMessage) -> Result<(), LogError> {
        self.decoder.check(&raw.inner).map_err(|error| {
            self.done = true;
            at(&self.path)(corrupt(&format!(
                "message {} on {}: {error}",
                raw.inner.sequence, raw.inner.channel.topic
            )))
        })
    }

    /// Decodes a message [`next_raw`](Self::next_raw) yielded.
    pub fn decode(&mut self, raw: RawMessage) -> Result<LogMessage, LogError> {
        decode(&mut self.decoder, raw.inner).map_err(|e| {
            self.done = true;
            at(&self.path)(e)
        })
    }
}

impl Drop for Messages {
    fn drop(&mut self) {
        // Dropping the receiver first wakes the thread if it waits to send, and it ends.
        self.incoming = None;
        if let Some(reading) = self.reading.take() {
            let _ = reading.join();
        }
    }
}

impl Iterator for Messages {
    type Item = Result<LogMessage, LogError>;

    fn next(&mut self) -> Option<Self::Item> {
        Some(match self.next_raw()? {
            Ok(raw) => self.decode(raw),
            Err(e) => Err(e),
        })
    }
}
