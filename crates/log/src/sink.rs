//! Where a recorder's messages go ([`MessageSink`]): an MCAP file ([`LogWriter`]), a live
//! stream, or both; and the channels they go on.

use crate::messages::Schema;
use crate::{LogError, LogWriter};

/// A channel of a [`LogWriter`], returned when the channel is added.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct ChannelId(pub(crate) u16);

impl ChannelId {
    /// The channel numbered `index` (for a [`MessageSink`] of another kind than a file).
    pub fn from_index(index: u16) -> ChannelId {
        ChannelId(index)
    }

    /// Its number.
    pub fn index(self) -> u16 {
        self.0
    }
}

/// Where a recorder's messages go: an MCAP file ([`LogWriter`]), a live stream, or both.
/// Channels are added first; then each message is written on its channel at a simulation
/// time, in nondecreasing time order.
pub trait MessageSink {
    /// Adds a channel on `topic` for protobuf messages described by `schema`.
    fn add_protobuf_channel(&mut self, topic: &str, schema: Schema) -> Result<ChannelId, LogError>;

    /// Writes `message` on `channel` at `time_ns`.
    fn write<M: prost::Message + Clone + Send + 'static>(
        &mut self,
        channel: ChannelId,
        time_ns: u64,
        message: M,
    ) -> Result<(), LogError>;

    /// Adds a channel on `topic` for JSON messages described by the JSON Schema
    /// `schema_json` named `schema_name` (a game's own state, `/game`).
    fn add_json_channel(
        &mut self,
        topic: &str,
        schema_name: &str,
        schema_json: &str,
    ) -> Result<ChannelId, LogError>;

    /// Writes `bytes`, one message already encoded as `channel`'s schema says (protobuf,
    /// or a JSON value on a JSON channel), like [`write`](Self::write).
    fn write_encoded(
        &mut self,
        channel: ChannelId,
        time_ns: u64,
        bytes: Vec<u8>,
    ) -> Result<(), LogError>;

    /// Attaches a file to a recording (the scenario, the game's name); a live stream
    /// ignores it.
    fn attach(&mut self, name: &str, media_type: &str, data: &[u8]) -> Result<(), LogError> {
        let _ = (name, media_type, data);
        Ok(())
    }

    /// Writes `message` to live viewers only, never to a recording (the current state again
    /// for a viewer that just subscribed): encoded, through
    /// [`write_live_encoded`](Self::write_live_encoded), which a live sink implements. A file
    /// ignores it.
    fn write_live<M: prost::Message + Clone + Send + 'static>(
        &mut self,
        channel: ChannelId,
        time_ns: u64,
        message: M,
    ) -> Result<(), LogError> {
        self.write_live_encoded(channel, time_ns, message.encode_to_vec())
    }

    /// Writes `bytes`, one message already encoded as `channel`'s schema says, to live
    /// viewers only, like [`write_live`](Self::write_live). A file ignores it.
    fn write_live_encoded(
        &mut self,
        _channel: ChannelId,
        _time_ns: u64,
        _bytes: Vec<u8>,
    ) -> Result<(), LogError> {
        Ok(())
    }
}

impl MessageSink for LogWriter {
    fn add_protobuf_channel(&mut self, topic: &str, schema: Schema) -> Result<ChannelId, LogError> {
        LogWriter::add_protobuf_channel(self, topic, schema)
    }

    fn write<M: prost::Message + Clone + Send + 'static>(
        &mut self,
        channel: ChannelId,
        time_ns: u64,
        message: M,
    ) -> Result<(), LogError> {
        LogWriter::write(self, channel, time_ns, message)
    }

    fn add_json_channel(
        &mut self,
        topic: &str,
        schema_name: &str,
        schema_json: &str,
    ) -> Result<ChannelId, LogError> {
        LogWriter::add_json_channel(self, topic, schema_name, schema_json)
    }

    fn attach(&mut self, name: &str, media_type: &str, data: &[u8]) -> Result<(), LogError> {
        LogWriter::attach(self, name, media_type, data)
    }

    fn write_encoded(
        &mut self,
        channel: ChannelId,
        time_ns: u64,
        bytes: Vec<u8>,
    ) -> Result<(), LogError> {
        LogWriter::write_encoded(self, channel, time_ns, bytes)
    }
}
