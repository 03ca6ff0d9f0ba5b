//! The Foxglove WebSocket protocol, v1 (`foxglove.websocket.v1`, the published spec, which
//! Lichtblick and `@foxglove/ws-protocol` speak; `foxglove.sdk.v1`, what the Foxglove SDK
//! and current Foxglove releases name the same messages): the subset a simulation server
//! uses. JSON text messages with an `op`; binary messages with a one-byte opcode.

use std::collections::BTreeMap;

use base64::Engine;
use serde::{Deserialize, Serialize};

/// The subprotocols accepted, in order of preference.
pub const SUBPROTOCOLS: [&str; 2] = ["foxglove.websocket.v1", "foxglove.sdk.v1"];

/// Binary opcode of a message on a subscription (server to client).
pub const OP_MESSAGE_DATA: u8 = 0x01;
/// Binary opcode of the server's time (the `time` capability).
pub const OP_TIME: u8 = 0x02;

/// A channel as `advertise` lists it: its schema inline, base64 for protobuf.
#[derive(Serialize, Debug, Clone)]
#[serde(rename_all = "camelCase")]
pub struct Channel {
    /// The server's id for it.
    pub id: u32,
    /// Topic.
    pub topic: String,
    /// Message encoding: `protobuf`.
    pub encoding: String,
    /// Schema name, e.g. `foxglove.SceneUpdate`.
    pub schema_name: String,
    /// The schema: a FileDescriptorSet, base64.
    pub schema: String,
    /// `protobuf`.
    pub schema_encoding: String,
}

impl Channel {
    /// The channel `id` on `topic`, protobuf with the FileDescriptorSet `descriptor`.
    pub fn protobuf(id: u32, topic: &str, schema_name: &str, descriptor: &[u8]) -> Channel {
        Channel {
            id,
            topic: topic.to_owned(),
            encoding: "protobuf".to_owned(),
            schema_name: schema_name.to_owned(),
            schema: base64::engine::general_purpose::STANDARD.encode(descriptor),
            schema_encoding: "protobuf".to_owned(),
        }
    }

    /// The channel `id` on `topic`, JSON described by the JSON Schema `schema`.
    pub fn json(id: u32, topic: &str, schema_name: &str, schema: &str) -> Channel {
        Channel {
            id,
            topic: topic.to_owned(),
            encoding: "json".to_owned(),
            schema_name: schema_name.to_owned(),
            schema: schema.to_owned(),
            schema_encoding: "jsonschema".to_owned(),
        }
    }
}

/// A service as `advertiseServices` lists it: JSON requests and responses, each with a
/// JSON Schema.
#[derive(Serialize, Debug, Clone)]
pub struct Service {
    /// The server's id for it.
    pub id: u32,
    /// Name, e.g. `/step`.
    pub name: String,
    /// Type name.
    #[serde(rename = "type")]
    pub kind: String,
    /// What a request is.
    pub request: ServiceSchema,
    /// What a response is.
    pub response: ServiceSchema,
}

/// The encoding and schema of a service's requests or responses.
#[derive(Serialize, Debug, Clone)]
#[serde(rename_all = "camelCase")]
pub struct ServiceSchema {
    /// `json`.
    pub encoding: String,
    /// Schema name.
    pub schema_name: String,
    /// `jsonschema`.
    pub schema_encoding: String,
    /// The JSON Schema.
    pub schema: String,
}

impl ServiceSchema {
    /// JSON described by the JSON Schema `schema`, named `name`.
    pub fn json(name: &str, schema: &str) -> ServiceSchema {
        ServiceSchema {
            encoding: "json".to_owned(),
            schema_name: name.to_owned(),
            schema_encoding: "jsonschema".to_owned(),
            schema: schema.to_owned(),
        }
    }
}

/// Binary opcode of a client's service call.
pub const OP_SERVICE_CALL: u8 = 0x02;
/// Binary opcode of the server's answer to a service call.
pub const OP_SERVICE_RESPONSE: u8 = 0x03;

/// A service call: service id, call id, encoding, payload.
pub struct ServiceCall {
    /// The service.
    pub service: u32,
    /// The client's id for the call.
    pub call: u32,
    /// The request.
    pub payload: Vec<u8>,
}

/// Parses a binary service call (opcode, service id, call id, encoding length, encoding,
/// payload); the encoding must be `json`.
pub fn service_call(data: &[u8]) -> Result<ServiceCall, String> {
    let u32_at = |i: usize| {
        data.get(i..i + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .ok_or("a service call cut short")
    };
    let (service, call, len) = (u32_at(1)?, u32_at(5)?, u32_at(9)? as usize);
    let encoding = data.get(13..13 + len).ok_or("a service call cut short")?;
    if encoding != b"json" {
        return Err(format!(
            "service calls are json, not {:?}",
            String::from_utf8_lossy(encoding)
        ));
    }
    Ok(ServiceCall {
        service,
        call,
        payload: data[13 + len..].to_vec(),
    })
}

/// The answer to a service call, in JSON.
pub fn service_response(service: u32, call: u32, payload: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(17 + payload.len());
    out.push(OP_SERVICE_RESPONSE);
    out.extend_from_slice(&service.to_le_bytes());
    out.extend_from_slice(&call.to_le_bytes());
    out.extend_from_slice(&4u32.to_le_bytes());
    out.extend_from_slice(b"json");
    out.extend_from_slice(payload);
    out
}

/// Binary opcode of a client's playback-control request (`playbackControl`, as the Foxglove
/// SDK's protocol defines it).
pub const OP_PLAYBACK_CONTROL: u8 = 0x03;
/// Binary opcode of the server's playback state.
pub const OP_PLAYBACK_STATE: u8 = 0x05;

/// A playback-control request: play or pause, at a speed, maybe seeking first.
#[derive(Debug, Clone, PartialEq)]
pub struct PlaybackControl {
    /// Play (else pause).
    pub play: bool,
    /// Playback speed, wall seconds of data per second.
    pub speed: f32,
    /// Seek to this time first (ns).
    pub seek: Option<u64>,
    /// The client's id for the request, sent back with the state.
    pub request_id: String,
}

/// Parses a playback-control request: opcode, command (0 play, 1 pause), speed (f32),
/// whether it seeks (u8) and to when (u64 ns), the request id (u32 length, UTF-8).
pub fn playback_control(data: &[u8]) -> Result<PlaybackControl, String> {
    let short = || "a playback-control request cut short".to_owned();
    if data.len() < 1 + 1 + 4 + 1 + 8 + 4 {
        return Err(short());
    }
    let play = match data[1] {
        0 => true,
        1 => false,
        other => return Err(format!("playback command {other}: 0 is play, 1 pause")),
    };
    let speed = f32::from_le_bytes([data[2], data[3], data[4], data[5]]);
    let seeks = data[6] != 0;
    let mut time = [0; 8];
    time.copy_from_slice(&data[7..15]);
    let len = u32::from_le_bytes([data[15], data[16], data[17], data[18]]) as usize;
    let id = data.get(19..19 + len).ok_or_else(short)?;
    Ok(PlaybackControl {
        play,
        speed,
        seek: seeks.then_some(u64::from_le_bytes(time)),
        request_id: String::from_utf8(id.to_vec()).map_err(|_| "a request id that is not UTF-8")?,
    })
}

/// The playback state: opcode, status (0 playing, 1 paused), current time (ns), speed, whether
/// it just sought, the request id it answers (u32 length, UTF-8; empty for none).
pub fn playback_state(
    playing: bool,
    time_ns: u64,
    speed: f32,
    sought: bool,
    request_id: &str,
) -> Vec<u8> {
    let mut out = Vec::with_capacity(19 + request_id.len());
    out.push(OP_PLAYBACK_STATE);
    out.push(if playing { 0 } else { 1 });
    out.extend_from_slice(&time_ns.to_le_bytes());
    out.extend_from_slice(&speed.to_le_bytes());
    out.push(u8::from(sought));
    out.extend_from_slice(&(request_id.len() as u32).to_le_bytes());
    out.extend_from_slice(request_id.as_bytes());
    out
}

/// A time in `serverInfo`: seconds and nanoseconds.
#[derive(Serialize, Debug, Clone, Copy)]
pub struct Time {
    /// Seconds.
    pub sec: u32,
    /// Nanoseconds past `sec`.
    pub nsec: u32,
}

impl Time {
    /// `ns` nanoseconds.
    pub fn from_ns(ns: u64) -> Time {
        Time {
            sec: u32::try_from(ns / 1_000_000_000).unwrap_or(u32::MAX),
            nsec: (ns % 1_000_000_000) as u32,
        }
    }
}

/// A JSON message from the server.
#[derive(Serialize, Debug)]
#[serde(tag = "op", rename_all = "camelCase")]
pub enum ServerMessage<'a> {
    /// First message on every connection.
    #[serde(rename_all = "camelCase")]
    ServerInfo {
        /// The server's name.
        name: &'a str,
        /// What it supports beyond subscribing (`time`).
        capabilities: &'a [&'a str],
        /// Message encodings clients may publish in (`json`).
        supported_encodings: &'a [&'a str],
        /// Free-form.
        metadata: BTreeMap<String, String>,
        /// Changes when the server restarts.
        session_id: &'a str,
        /// Where Foxglove's timeline starts (`playbackControl`).
        data_start_time: Time,
        /// Where it ends: the scenario's last frame.
        data_end_time: Time,
    },
    /// The channels a client may subscribe to.
    Advertise {
        /// Every channel.
        channels: &'a [Channel],
    },
    /// The services clients may call.
    AdvertiseServices {
        /// Every service.
        services: &'a [Service],
    },
    /// A service call that failed.
    #[serde(rename_all = "camelCase")]
    ServiceCallFailure {
        /// The service.
        service_id: u32,
        /// The call.
        call_id: u32,
        /// Why.
        message: &'a str,
    },
    /// A message for people: 0 info, 1 warning, 2 error.
    Status {
        /// Level.
        level: u8,
        /// Text.
        message: &'a str,
    },
}

impl ServerMessage<'_> {
    /// As JSON text.
    pub fn json(&self) -> String {
        serde_json::to_string(self).unwrap_or_default()
    }
}

/// One subscription of a `subscribe` request.
#[derive(Deserialize, Debug, Clone, Copy)]
#[serde(rename_all = "camelCase")]
pub struct Subscription {
    /// The client's id for it (sent back with every message).
    pub id: u32,
    /// The channel.
    pub channel_id: u32,
}

/// A channel a client publishes on (`advertise` from a client).
#[derive(Deserialize, Debug, Clone)]
#[serde(rename_all = "camelCase")]
pub struct ClientChannel {
    /// The client's id for it.
    pub id: u32,
    /// Topic: only `/input` and `/clicked_point` are taken.
    pub topic: String,
    /// Message encoding: only `json` is taken.
    pub encoding: String,
}

/// Binary opcode of a message a client publishes on its channel.
pub const OP_CLIENT_MESSAGE: u8 = 0x01;

/// A JSON message from a client (unknown ops are refused with a status).
#[derive(Deserialize, Debug)]
#[serde(tag = "op", rename_all = "camelCase")]
pub enum ClientMessage {
    /// Start receiving channels.
    Subscribe {
        /// The new subscriptions.
        subscriptions: Vec<Subscription>,
    },
    /// Stop receiving.
    #[serde(rename_all = "camelCase")]
    Unsubscribe {
        /// The client's ids of the subscriptions to end.
        subscription_ids: Vec<u32>,
    },
    /// Channels the client will publish on (`clientPublish`).
    Advertise {
        /// The channels.
        channels: Vec<ClientChannel>,
    },
    /// Channels the client stops publishing on.
    #[serde(rename_all = "camelCase")]
    Unadvertise {
        /// The client's channel ids.
        channel_ids: Vec<u32>,
    },
}

/// A message on a subscription: opcode, subscription id, time (ns), payload.
pub fn message_data(subscription: u32, time_ns: u64, payload: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(13 + payload.len());
    out.push(OP_MESSAGE_DATA);
    out.extend_from_slice(&subscription.to_le_bytes());
    out.extend_from_slice(&time_ns.to_le_bytes());
    out.extend_from_slice(payload);
    out
}

/// The server's time (ns).
pub fn time(time_ns: u64) -> Vec<u8> {
    let mut out = Vec::with_capacity(9);
    out.push(OP_TIME);
    out.extend_from_slice(&time_ns.to_le_bytes());
    out
}

/// The subprotocol to answer a client offering `offered` (a `Sec-WebSocket-Protocol` header:
/// comma-separated), or `None` if it offers neither.
pub fn choose(offered: &str) -> Option<&'static str> {
    let offered: Vec<&str> = offered.split(',').map(str::trim).collect();
    SUBPROTOCOLS.into_iter().find(|p| offered.contains(p))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_subprotocols_are_accepted_and_the_published_one_preferred() {
        assert_eq!(
            choose("foxglove.websocket.v1"),
            Some("foxglove.websocket.v1")
        );
        assert_eq!(choose("foxglove.sdk.v1"), Some("foxglove.sdk.v1"));
        assert_eq!(
            choose("foxglove.sdk.v1, foxglove.websocket.v1"),
            Some("foxglove.websocket.v1")
        );
        assert_eq!(choose("chat, superchat"), None);
    }

    #[test]
    fn message_data_is_opcode_subscription_time_payload_little_endian() {
        let m = message_data(7, 0x0102_0304_0506_0708, b"ab");
        assert_eq!(m, [1, 7, 0, 0, 0, 8, 7, 6, 5, 4, 3, 2, 1, b'a', b'b']);
        let sub: ClientMessage =
            serde_json::from_str(r#"{"op":"subscribe","subscriptions":[{"id":3,"channelId":9}]}"#)
                .unwrap();
        assert!(
            matches!(sub, ClientMessage::Subscribe { subscriptions } if subscriptions[0].channel_id == 9)
        );
    }
}
