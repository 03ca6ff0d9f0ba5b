//! The services `ricochet serve` offers (Foxglove's Call Service panel, or any client of
//! the protocol's `services` capability), JSON in and out:
//!
//! | service | request | what it does |
//! |---|---|---|
//! | `/pause` | `{}` | stops stepping (the clients still get the last state) |
//! | `/play` | `{}` | steps again, in real time from now |
//! | `/step` | `{"frames": N}` (default 1, at most 10,000) | pauses, then steps N frames as fast as it can |
//! | `/reset` | `{}` | the scenario again from frame 0; a recording goes on in a new file (at most 1,000 files) |
//! | `/load` | `{"scenario": "scenarios/level.toml"}` | another scenario file (a relative path, below the server's directory), from frame 0, likewise |
//! | `/seek` | `{"frame": N}` | to frame N: forward by stepping as fast as it can, back by stepping again from the latest snapshot before N with the inputs since (recording: from frame 0, writing the recording's file again, so that it holds the session as it now stands and replays on its own) |
//! | `/speed` | `{"speed": X}` | simulation seconds per wall second, from now (0.01 to 100) |
//! | `/query` | `{"kind": "ray", "origin": [0, 0], "direction": [1, 0], "max_distance": 50}`, or `point`, `aabb`, `shape` (`query.rs`) | a scene query of the state the clients were last sent: `{"frame": F, "count": N, "hits": [...], "truncated": T}` |
//!
//! Every response but `/query`'s is `{"frame": F, "paused": P}` (the next frame, and whether stepping is
//! paused), with `"recording": "FILE"` after a reset or load that started a new file, or a
//! seek back that writes one again.
//!
//! No `/step` or `/seek` (nor a timeline seek) goes past the session's last frame
//! (`--frames`, else 100,000,000), and a step or seek runs in slices: meanwhile every client
//! gets its progress (a status every 0.5 s), calls are answered "busy", and SIGTERM stops it
//! and finishes the recording. After an overflow the session is paused at its last good
//! frame: `/play`, `/step` and seeks forward are refused until a seek back, `/reset` or
//! `/load`.

use serde::Deserialize;

use crate::protocol::{Service, ServiceSchema};

/// A request the simulation loop carries out at the next frame boundary.
#[derive(Debug)]
pub enum Command {
    /// Stop stepping.
    Pause,
    /// Step again.
    Play,
    /// Pause, then step this many frames.
    Step(u64),
    /// The scenario again.
    Reset,
    /// Another scenario.
    Load(String),
    /// To this frame.
    Seek(u64),
    /// Simulation seconds per wall second.
    Speed(f64),
    /// A scene query, answered at once (`query.rs`).
    Query(crate::query::Request),
}

/// At most this many frames in one `/step`.
pub const MAX_STEP: u64 = 10_000;

const NAMES: [&str; 8] = [
    "/pause", "/play", "/step", "/reset", "/load", "/seek", "/speed", "/query",
];

/// `/query`'s request: one of four kinds, each with optional `layers` (`query.rs`).
const QUERY_REQUEST: &str = r#"{"type": "object", "properties": {"kind": {"type": "string", "enum": ["ray", "point", "aabb", "shape"]}, "origin": {"type": "array", "items": {"type": "number"}, "minItems": 2, "maxItems": 2}, "direction": {"type": "array", "items": {"type": "number"}, "minItems": 2, "maxItems": 2}, "max_distance": {"type": "number", "minimum": 0}, "all": {"type": "boolean"}, "point": {"type": "array", "items": {"type": "number"}, "minItems": 2, "maxItems": 2}, "min": {"type": "array", "items": {"type": "number"}, "minItems": 2, "maxItems": 2}, "max": {"type": "array", "items": {"type": "number"}, "minItems": 2, "maxItems": 2}, "shape": {"type": "object", "properties": {"kind": {"type": "string", "enum": ["circle", "aabb", "obb", "capsule", "polygon", "compound"]}}, "required": ["kind"]}, "position": {"type": "array", "items": {"type": "number"}, "minItems": 2, "maxItems": 2}, "angle": {"type": "number"}, "layers": {"type": "array", "items": {"type": "string"}}}, "required": ["kind"]}"#;

/// `/query`'s answer.
const QUERY_RESPONSE: &str = r#"{"type": "object", "properties": {"frame": {"type": "integer"}, "count": {"type": "integer"}, "truncated": {"type": "boolean"}, "hits": {"type": "array", "items": {"type": "object", "properties": {"body": {"type": "string"}, "name": {"type": "string"}, "layer": {"type": "string"}, "point": {"type": "array", "items": {"type": "number"}}, "normal": {"type": "array", "items": {"type": "number"}}, "distance": {"type": "number"}}}}}}"#;

/// The id of `/query` (the services' ids are their places in the list, from 1).
pub const QUERY: u32 = 8;

/// The services, ids 1 to 8.
pub fn list() -> Vec<Service> {
    let empty = r#"{"type": "object", "properties": {}}"#;
    let response = r#"{"type": "object", "properties": {"frame": {"type": "integer"}, "paused": {"type": "boolean"}, "recording": {"type": "string"}}}"#;
    let requests = [
        empty,
        empty,
        r#"{"type": "object", "properties": {"frames": {"type": "integer", "minimum": 1}}}"#,
        empty,
        r#"{"type": "object", "properties": {"scenario": {"type": "string"}}, "required": ["scenario"]}"#,
        r#"{"type": "object", "properties": {"frame": {"type": "integer", "minimum": 0}}, "required": ["frame"]}"#,
        r#"{"type": "object", "properties": {"speed": {"type": "number"}}, "required": ["speed"]}"#,
        QUERY_REQUEST,
    ];
    NAMES
        .iter()
        .zip(requests)
        .enumerate()
        .map(|(i, (name, request))| Service {
            id: i as u32 + 1,
            name: (*name).to_owned(),
            kind: format!("ricochet{name}"),
            request: ServiceSchema::json(&format!("ricochet{name}.Request"), request),
            response: if i as u32 + 1 == QUERY {
                ServiceSchema::json("ricochet/query.Response", QUERY_RESPONSE)
            } else {
                ServiceSchema::json("ricochet.ServiceResponse", response)
            },
        })
        .collect()
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct StepRequest {
    #[serde(default = "one")]
    frames: u64,
}

fn one() -> u64 {
    1
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LoadRequest {
    scenario: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Empty {}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SeekRequest {
    frame: u64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SpeedRequest {
    speed: f64,
}

/// The command a call to service `id` with `payload` asks for, or why it can't be.
pub fn parse(id: u32, payload: &[u8]) -> Result<Command, String> {
    let body = if payload.is_empty() {
        b"{}".as_slice()
    } else {
        payload
    };
    let bad = |e: serde_json::Error| format!("bad request: {e}");
    match id {
        1 | 2 | 4 => {
            serde_json::from_slice::<Empty>(body).map_err(bad)?;
            Ok(match id {
                1 => Command::Pause,
                2 => Command::Play,
                _ => Command::Reset,
            })
        }
        3 => {
            let r: StepRequest = serde_json::from_slice(body).map_err(bad)?;
            if !(1..=MAX_STEP).contains(&r.frames) {
                return Err(format!("frames must be 1 to {MAX_STEP}, got {}", r.frames));
            }
            Ok(Command::Step(r.frames))
        }
        5 => {
            let r: LoadRequest = serde_json::from_slice(body).map_err(bad)?;
            let path = std::path::Path::new(&r.scenario);
            let inside = path.is_relative()
                && path
                    .components()
                    .all(|c| matches!(c, std::path::Component::Normal(_)));
            if !inside {
                return Err(format!(
                    "{:?}: a scenario is loaded by a relative path below the server's directory",
                    r.scenario
                ));
            }
            Ok(Command::Load(r.scenario))
        }
        6 => {
            // The range (the session's last frame) is checked where every seek is.
            let r: SeekRequest = serde_json::from_slice(body).map_err(bad)?;
            Ok(Command::Seek(r.frame))
        }
        7 => {
            let r: SpeedRequest = serde_json::from_slice(body).map_err(bad)?;
            if !(r.speed.is_finite() && crate::common::SPEEDS.contains(&r.speed)) {
                return Err(format!(
                    "speed must be 0.01 to 100, got {}",
                    ricochet_geom::Number(r.speed)
                ));
            }
            Ok(Command::Speed(r.speed))
        }
        QUERY => crate::query::parse(body).map(Command::Query),
        other => Err(format!("no service {other}")),
    }
}
