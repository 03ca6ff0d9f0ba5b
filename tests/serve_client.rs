//! A client of `ricochet serve` for the tests (`serve_ws.rs`, `serve_session.rs`): starts
//! a server on a free loopback port, connects with a subprotocol, and reads what the
//! Foxglove WebSocket protocol sends (JSON messages, message data, service answers,
//! playback states).

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use futures_util::{SinkExt, StreamExt};
use prost::Message as _;
use ricochet_log::messages::ricochet::Stats;
use serde_json::Value;
use tokio_tungstenite::tungstenite::Message;
use tokio_tungstenite::tungstenite::client::IntoClientRequest;

/// A server on a free loopback port; killed when dropped.
pub(crate) struct Server {
    /// The server's process.
    pub(crate) child: Child,
    /// `ws://127.0.0.1:PORT`.
    pub(crate) url: String,
    /// Its stderr lines after the first.
    pub(crate) lines: std::sync::Arc<std::sync::Mutex<Vec<String>>>,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

pub(crate) fn serve(args: &[&str]) -> Server {
    let mut command = Command::new(env!("CARGO_BIN_EXE_ricochet"));
    command.args(["serve", "--bind", "127.0.0.1:0"]).args(args);
    serve_with(command)
}

/// A server started by `command` (a `ricochet serve` on 127.0.0.1:0, maybe through a shell
/// that limits it, or in another directory).
pub(crate) fn serve_with(mut command: Command) -> Server {
    let mut child = command
        .stderr(Stdio::piped())
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(child.stderr.take().unwrap()).lines();
    let url = loop {
        let line = lines
            .next()
            .expect("the server says where it listens")
            .unwrap();
        if let Some(rest) = line.split(" on ws://").nth(1) {
            break format!("ws://{}", rest.split_whitespace().next().unwrap());
        }
    };
    // Keep draining stderr so the server never blocks on it.
    let kept = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
    let sink = kept.clone();
    std::thread::spawn(move || {
        for line in lines.map_while(Result::ok) {
            sink.lock().unwrap().push(line);
        }
    });
    Server {
        child,
        url,
        lines: kept,
    }
}

pub(crate) type Ws =
    tokio_tungstenite::WebSocketStream<tokio_tungstenite::MaybeTlsStream<tokio::net::TcpStream>>;

pub(crate) async fn connect(url: &str, subprotocol: &str) -> Result<(Ws, String), String> {
    let mut request = url.into_client_request().unwrap();
    request
        .headers_mut()
        .insert("Sec-WebSocket-Protocol", subprotocol.parse().unwrap());
    let (ws, response) = tokio_tungstenite::connect_async(request)
        .await
        .map_err(|e| e.to_string())?;
    let chosen = response.headers()["Sec-WebSocket-Protocol"]
        .to_str()
        .unwrap()
        .to_owned();
    Ok((ws, chosen))
}

/// Subscribes `ws` to `topic`, as listed in the `advertise` message `channels`, with the
/// client's subscription id `id`.
pub(crate) async fn subscribe_to(ws: &mut Ws, channels: &Value, topic: &str, id: u32) {
    let channel = channels["channels"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["topic"] == topic)
        .unwrap_or_else(|| panic!("a channel {topic}"))["id"]
        .clone();
    let subscribe =
        serde_json::json!({"op": "subscribe", "subscriptions": [{"id": id, "channelId": channel}]});
    ws.send(Message::text(subscribe.to_string())).await.unwrap();
}

/// Subscribes `ws` to every channel of the `advertise` message `channels` (subscription `i`
/// for the `i`-th).
pub(crate) async fn subscribe_all(ws: &mut Ws, channels: &Value) {
    let all: Vec<Value> = channels["channels"]
        .as_array()
        .unwrap()
        .iter()
        .enumerate()
        .map(|(i, c)| serde_json::json!({"id": i, "channelId": c["id"]}))
        .collect();
    let subscribe = serde_json::json!({"op": "subscribe", "subscriptions": all});
    ws.send(Message::text(subscribe.to_string())).await.unwrap();
}

/// The next JSON message, but for the services' advertisement (see [`services`]).
pub(crate) async fn next_json(ws: &mut Ws) -> Value {
    loop {
        let v = any_json(ws).await;
        if v["op"] != "advertiseServices" {
            return v;
        }
    }
}

pub(crate) async fn any_json(ws: &mut Ws) -> Value {
    loop {
        let m = next_message(ws).await;
        if let Message::Text(t) = m {
            return serde_json::from_str(t.as_str()).unwrap();
        }
    }
}

/// The next message on a subscription: (subscription, time, payload).
pub(crate) async fn next_data(ws: &mut Ws) -> (u32, u64, Vec<u8>) {
    loop {
        let m = next_message(ws).await;
        if let Message::Binary(b) = m
            && b[0] == 1
        {
            let sub = u32::from_le_bytes(b[1..5].try_into().unwrap());
            let time = u64::from_le_bytes(b[5..13].try_into().unwrap());
            return (sub, time, b[13..].to_vec());
        }
    }
}

/// The next message on `ws`, waiting at most 10 s.
pub(crate) async fn next_message(ws: &mut Ws) -> Message {
    tokio::time::timeout(Duration::from_secs(10), ws.next())
        .await
        .expect("a message within 10 s")
        .unwrap()
        .unwrap()
}

pub(crate) fn runtime() -> tokio::runtime::Runtime {
    tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .unwrap()
}

/// Calls service `name` with `request`; its JSON response, or the failure's message.
pub(crate) async fn call(
    ws: &mut Ws,
    services: &Value,
    name: &str,
    call: u32,
    request: &str,
) -> Result<Value, String> {
    call_with_statuses(ws, services, name, call, request)
        .await
        .0
}

/// The next playback state: (status, time, whether it sought, request id).
pub(crate) async fn playback_state(ws: &mut Ws) -> (u8, u64, u8, String) {
    loop {
        let m = tokio::time::timeout(Duration::from_secs(10), ws.next())
            .await
            .unwrap()
            .unwrap()
            .unwrap();
        if let Message::Binary(b) = m
            && b[0] == 5
        {
            let time = u64::from_le_bytes(b[2..10].try_into().unwrap());
            let len = u32::from_le_bytes(b[15..19].try_into().unwrap()) as usize;
            let id = String::from_utf8(b[19..19 + len].to_vec()).unwrap();
            return (b[1], time, b[14], id);
        }
    }
}

/// The `/stats` message of the next frame stepped (`/step` of 1), decoded (it may come
/// before the call's answer).
pub(crate) async fn step_stats(ws: &mut Ws, services: &Value, call_id: u32) -> Stats {
    send_call(ws, services, "/step", call_id, r#"{"frames": 1}"#).await;
    let (mut stepped, mut frame) = (Vec::new(), None);
    loop {
        let m = next_message(ws).await;
        if let Message::Binary(b) = m {
            match b[0] {
                1 => stepped.push(Stats::decode(&b[13..]).unwrap()),
                3 => {
                    let answer: Value = serde_json::from_slice(&b[17..]).unwrap();
                    frame = Some(answer["frame"].as_u64().unwrap() - 1);
                }
                _ => {}
            }
        }
        if let Some(f) = frame
            && let Some(stats) = stepped.iter().find(|s| s.frame == f)
        {
            return stats.clone();
        }
    }
}

/// Advertises `/input` (JSON) as the client's channel 5.
pub(crate) async fn advertise_input(ws: &mut Ws) {
    let advertise = serde_json::json!({"op": "advertise", "channels": [
        {"id": 5, "topic": "/input", "encoding": "json", "schemaName": "ricochet.Input"}]});
    ws.send(Message::text(advertise.to_string())).await.unwrap();
}

/// Publishes `text` on the client's channel 5.
pub(crate) async fn publish(ws: &mut Ws, text: &str) {
    let mut data = vec![1u8];
    data.extend_from_slice(&5u32.to_le_bytes());
    data.extend_from_slice(text.as_bytes());
    ws.send(Message::binary(data)).await.unwrap();
}

/// The next status message's (level, text).
pub(crate) async fn next_status(ws: &mut Ws) -> (u64, String) {
    loop {
        let v = next_json(ws).await;
        if v["op"] == "status" {
            return (
                v["level"].as_u64().unwrap(),
                v["message"].as_str().unwrap().to_owned(),
            );
        }
    }
}

/// Sends a call to service `name` without waiting for its answer.
pub(crate) async fn send_call(ws: &mut Ws, services: &Value, name: &str, call: u32, request: &str) {
    let service = services["services"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["name"] == name)
        .unwrap_or_else(|| panic!("a service {name}"))["id"]
        .as_u64()
        .unwrap() as u32;
    let mut data = vec![2u8];
    data.extend_from_slice(&service.to_le_bytes());
    data.extend_from_slice(&call.to_le_bytes());
    data.extend_from_slice(&4u32.to_le_bytes());
    data.extend_from_slice(b"json");
    data.extend_from_slice(request.as_bytes());
    ws.send(Message::binary(data)).await.unwrap();
}

/// Calls service `name`; its answer (the response, or the failure's message) and the
/// status messages that came before it.
pub(crate) async fn call_with_statuses(
    ws: &mut Ws,
    services: &Value,
    name: &str,
    call: u32,
    request: &str,
) -> (Result<Value, String>, Vec<(u64, String)>) {
    send_call(ws, services, name, call, request).await;
    let mut statuses = Vec::new();
    loop {
        let m = next_message(ws).await;
        match m {
            Message::Binary(b) if b[0] == 3 => {
                assert_eq!(u32::from_le_bytes(b[5..9].try_into().unwrap()), call);
                assert_eq!(&b[13..17], b"json");
                return (Ok(serde_json::from_slice(&b[17..]).unwrap()), statuses);
            }
            Message::Text(t) => {
                let v: Value = serde_json::from_str(t.as_str()).unwrap();
                if v["op"] == "serviceCallFailure" {
                    return (Err(v["message"].as_str().unwrap().to_owned()), statuses);
                }
                if v["op"] == "status" {
                    let text = v["message"].as_str().unwrap().to_owned();
                    statuses.push((v["level"].as_u64().unwrap(), text));
                }
            }
            _ => {}
        }
    }
}

/// Connects, returning the socket and the services' advertisement.
pub(crate) async fn open(server: &Server, subprotocol: &str) -> (Ws, Value) {
    let (mut ws, _) = connect(&server.url, subprotocol).await.unwrap();
    loop {
        let v = any_json(&mut ws).await;
        if v["op"] == "advertiseServices" {
            return (ws, v);
        }
    }
}

/// SIGTERM, then the exit status, waiting at most `limit`.
pub(crate) fn terminate(server: &mut Server, limit: Duration) -> std::process::ExitStatus {
    let pid = server.child.id().to_string();
    assert!(
        Command::new("kill")
            .args(["-TERM", &pid])
            .status()
            .unwrap()
            .success()
    );
    let asked = Instant::now();
    loop {
        if let Some(status) = server.child.try_wait().unwrap() {
            return status;
        }
        assert!(
            asked.elapsed() < limit,
            "the server still runs {limit:?} after SIGTERM"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// `ricochet replay` of `log` gives the same bytes; the frames it holds (`/stats`).
pub(crate) fn replays_byte_for_byte(log: &Path) -> usize {
    let replayed = log.with_extension("replay.mcap");
    let o = Command::new(env!("CARGO_BIN_EXE_ricochet"))
        .args([
            "replay",
            log.to_str().unwrap(),
            "-o",
            replayed.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        std::fs::read(log).unwrap() == std::fs::read(&replayed).unwrap(),
        "byte-identical"
    );
    ricochet_log::read_log_file(log)
        .unwrap()
        .iter()
        .filter(|m| m.topic == "/stats")
        .count()
}
