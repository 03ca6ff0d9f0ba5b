//! Where a served session's messages go: the live stream ([`LiveSink`], publishing into the
//! room's hub) and its recording, if any; and a session's start and finish on them.

use std::path::{Path, PathBuf};

use ricochet_log::{ChannelId, LogError, LogWriter, MessageSink, Schema};
use ricochet_record::session::{SCENARIO_ATTACHMENT, Session};
use ricochet_sim::Scenario;

use crate::common::ServeError;
use crate::hub::Hub;
use crate::protocol::Channel;

/// The recorder's [`MessageSink`] for a live stream: each message encoded once and
/// published to the clients subscribed to its channel.
pub struct LiveSink {
    hub: Hub,
}

/// The topic a session (a room's, or the plain server's) advertises its recorded commands
/// on: `/input` is what its clients publish (the game's input, JSON), so the server's
/// record of them is told apart (the recording keeps `/input`, which replays read).
pub const RECORDED_INPUT: &str = "/input/recorded";

impl LiveSink {
    /// A sink publishing through `hub`; the session's recorded `/input` is advertised as
    /// [`RECORDED_INPUT`].
    pub fn new(hub: Hub) -> LiveSink {
        LiveSink { hub }
    }

    /// Publishes `payload` (an encoded message) on `channel` to its subscribers.
    fn publish(&self, channel: ChannelId, time_ns: u64, payload: Vec<u8>) {
        self.hub
            .lock()
            .publish(u32::from(channel.index()), time_ns, payload);
    }

    fn topic<'a>(&self, topic: &'a str) -> &'a str {
        if topic == "/input" {
            RECORDED_INPUT
        } else {
            topic
        }
    }
}

impl MessageSink for LiveSink {
    fn add_protobuf_channel(&mut self, topic: &str, schema: Schema) -> Result<ChannelId, LogError> {
        let topic = self.topic(topic);
        let id = self.hub.lock().channel(topic, |id| {
            Channel::protobuf(id, topic, &schema.name, &schema.data)
        });
        Ok(ChannelId::from_index(id as u16))
    }

    fn write<M: prost::Message + Clone + Send + 'static>(
        &mut self,
        channel: ChannelId,
        time_ns: u64,
        message: M,
    ) -> Result<(), LogError> {
        self.publish(channel, time_ns, message.encode_to_vec());
        Ok(())
    }

    fn add_json_channel(
        &mut self,
        topic: &str,
        schema_name: &str,
        schema_json: &str,
    ) -> Result<ChannelId, LogError> {
        let topic = self.topic(topic);
        let id = self.hub.lock().channel(topic, |id| {
            Channel::json(id, topic, schema_name, schema_json)
        });
        Ok(ChannelId::from_index(id as u16))
    }

    fn write_encoded(
        &mut self,
        channel: ChannelId,
        time_ns: u64,
        bytes: Vec<u8>,
    ) -> Result<(), LogError> {
        self.publish(channel, time_ns, bytes);
        Ok(())
    }

    fn write_live_encoded(
        &mut self,
        channel: ChannelId,
        time_ns: u64,
        bytes: Vec<u8>,
    ) -> Result<(), LogError> {
        // Everything a live sink writes is live.
        self.write_encoded(channel, time_ns, bytes)
    }
}

/// Where a served session's messages go: the live stream, and the recording if any.
pub(crate) struct ServeSink {
    pub(crate) live: LiveSink,
    /// The recording, with its channel for each live channel id.
    pub(crate) file: Option<(LogWriter, Vec<ChannelId>)>,
    /// While a seek re-simulates: the recording gets every frame, the clients none.
    pub(crate) muted: bool,
}

impl MessageSink for ServeSink {
    fn add_protobuf_channel(&mut self, topic: &str, schema: Schema) -> Result<ChannelId, LogError> {
        if let Some((file, ids)) = &mut self.file {
            let id = file.add_protobuf_channel(topic, schema.clone())?;
            ids.push(id);
        }
        self.live.add_protobuf_channel(topic, schema)
    }

    fn write<M: prost::Message + Clone + Send + 'static>(
        &mut self,
        channel: ChannelId,
        time_ns: u64,
        message: M,
    ) -> Result<(), LogError> {
        match (&mut self.file, self.muted) {
            (Some((file, ids)), true) => {
                file.write(ids[usize::from(channel.index()) - 1], time_ns, message)
            }
            (None, true) => Ok(()),
            (None, false) => self.live.write(channel, time_ns, message),
            (Some((file, ids)), false) => {
                // Encoded once, here, for both: the live stream needs the bytes now anyway
                // (a copy of the message for the file's writer thread cost more).
                let bytes = message.encode_to_vec();
                let id = ids[usize::from(channel.index()) - 1];
                file.write_encoded(id, time_ns, bytes.clone())?;
                self.live.publish(channel, time_ns, bytes);
                Ok(())
            }
        }
    }

    fn add_json_channel(
        &mut self,
        topic: &str,
        schema_name: &str,
        schema_json: &str,
    ) -> Result<ChannelId, LogError> {
        if let Some((file, ids)) = &mut self.file {
            let id = file.add_json_channel(topic, schema_name, schema_json)?;
            ids.push(id);
        }
        self.live.add_json_channel(topic, schema_name, schema_json)
    }

    fn attach(&mut self, name: &str, media_type: &str, data: &[u8]) -> Result<(), LogError> {
        match &mut self.file {
            Some((file, _)) => file.attach(name, media_type, data),
            None => Ok(()),
        }
    }

    fn write_encoded(
        &mut self,
        channel: ChannelId,
        time_ns: u64,
        bytes: Vec<u8>,
    ) -> Result<(), LogError> {
        if let Some((file, ids)) = &mut self.file {
            let id = ids[usize::from(channel.index()) - 1];
            file.write_encoded(id, time_ns, bytes.clone())?;
        }
        if self.muted {
            return Ok(());
        }
        self.live.write_encoded(channel, time_ns, bytes)
    }

    fn write_live_encoded(
        &mut self,
        channel: ChannelId,
        time_ns: u64,
        bytes: Vec<u8>,
    ) -> Result<(), LogError> {
        if self.muted {
            return Ok(());
        }
        self.live.write_live_encoded(channel, time_ns, bytes)
    }
}

/// The recording of segment `k` of a session recorded to `path`: `path` itself, then
/// `NAME-1.mcap`, `NAME-2.mcap`, ... (a reset or a load starts a new file).
pub(crate) fn segment(path: &Path, k: u32) -> PathBuf {
    if k == 0 {
        return path.to_path_buf();
    }
    let stem = path
        .file_stem()
        .map_or_else(|| "session".into(), |s| s.to_string_lossy());
    let ext = path
        .extension()
        .map_or_else(|| "mcap".into(), |s| s.to_string_lossy());
    path.with_file_name(format!("{stem}-{k}.{ext}"))
}

/// A new session of `scenario` (whose file's text is `text`, attached to the recording
/// when not empty, for `ricochet replay`) for `hub`, recording to segment `k` of `record` if
/// asked.
pub(crate) fn start(
    scenario: &Scenario,
    text: &str,
    hub: &Hub,
    record: Option<&Path>,
    k: u32,
) -> Result<Session<ServeSink>, ServeError> {
    let file = match record {
        None => None,
        Some(path) => {
            let path = segment(path, k);
            let mut file = LogWriter::create(&path, ricochet_record::LIBRARY)?;
            if !text.is_empty() {
                file.attach(SCENARIO_ATTACHMENT, "application/toml", text.as_bytes())?;
            }
            Some((file, Vec::new()))
        }
    };
    let sink = ServeSink {
        live: LiveSink::new(hub.clone()),
        file,
        muted: false,
    };
    Ok(Session::new(scenario, sink)?)
}

/// Finishes a session's recording, if it has one.
pub(crate) fn finish(session: Session<ServeSink>) -> Result<(), ServeError> {
    if let Some((file, _)) = session.into_sink().file {
        file.finish()?;
    }
    Ok(())
}
