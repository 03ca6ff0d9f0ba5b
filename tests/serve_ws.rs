//! `ricochet serve` over a real WebSocket client (tokio-tungstenite), speaking the published
//! Foxglove WebSocket protocol: both subprotocols accepted, any other refused; the server
//! info and the channels advertised with their protobuf schemas; subscriptions answered
//! with messages that decode as the log's; malformed messages and an abrupt disconnect
//! answered without harm; SIGTERM finishes the recording as a complete log.

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::time::Duration;

use futures_util::{SinkExt, StreamExt};
use prost::Message as _;
use ricochet_log::messages::ricochet::Stats;
use serde_json::Value;
use tokio_tungstenite::tungstenite::Message;
use tokio_tungstenite::tungstenite::client::IntoClientRequest;

/// A server on a free loopback port; killed when dropped.
struct Server {
    child: Child,
    url: String,
    /// Its stderr lines after the first.
    lines: std::sync::Arc<std::sync::Mutex<Vec<String>>>,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn serve(args: &[&str]) -> Server {
    let mut child = Command::new(env!("CARGO_BIN_EXE_ricochet"))
        .args(["serve", "--bind", "127.0.0.1:0"])
        .args(args)
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

type Ws =
    tokio_tungstenite::WebSocketStream<tokio_tungstenite::MaybeTlsStream<tokio::net::TcpStream>>;

async fn connect(url: &str, subprotocol: &str) -> Result<(Ws, String), String> {
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
async fn subscribe_to(ws: &mut Ws, channels: &Value, topic: &str, id: u32) {
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

/// The next JSON message, but for the services' advertisement (see [`services`]).
async fn next_json(ws: &mut Ws) -> Value {
    loop {
        let v = any_json(ws).await;
        if v["op"] != "advertiseServices" {
            return v;
        }
    }
}

async fn any_json(ws: &mut Ws) -> Value {
    loop {
        let m = tokio::time::timeout(Duration::from_secs(10), ws.next())
            .await
            .expect("a message within 10 s")
            .unwrap()
            .unwrap();
        if let Message::Text(t) = m {
            return serde_json::from_str(t.as_str()).unwrap();
        }
    }
}

/// The next message on a subscription: (subscription, time, payload).
async fn next_data(ws: &mut Ws) -> (u32, u64, Vec<u8>) {
    loop {
        let m = tokio::time::timeout(Duration::from_secs(10), ws.next())
            .await
            .expect("a message within 10 s")
            .unwrap()
            .unwrap();
        if let Message::Binary(b) = m
            && b[0] == 1
        {
            let sub = u32::from_le_bytes(b[1..5].try_into().unwrap());
            let time = u64::from_le_bytes(b[5..13].try_into().unwrap());
            return (sub, time, b[13..].to_vec());
        }
    }
}

fn runtime() -> tokio::runtime::Runtime {
    tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .unwrap()
}

#[test]
fn a_client_of_either_subprotocol_gets_the_channels_and_decodable_messages() {
    let server = serve(&["--speed", "4"]);
    runtime().block_on(async {
        for subprotocol in ["foxglove.websocket.v1", "foxglove.sdk.v1"] {
            let (mut ws, chosen) = connect(&server.url, subprotocol).await.unwrap();
            assert_eq!(chosen, subprotocol);
            let info = next_json(&mut ws).await;
            assert_eq!(info["op"], "serverInfo");
            assert_eq!(
                info["capabilities"],
                serde_json::json!(["time", "clientPublish", "services", "playbackControl"])
            );
            let advertise = next_json(&mut ws).await;
            assert_eq!(advertise["op"], "advertise");
            let channels = advertise["channels"].as_array().unwrap();
            let topics: Vec<&str> = channels
                .iter()
                .map(|c| c["topic"].as_str().unwrap())
                .collect();
            assert_eq!(
                topics,
                [
                    "/scene",
                    "/scene/static",
                    "/tf",
                    "/scene/contacts",
                    "/bodies",
                    "/contacts",
                    "/stats",
                    "/events",
                    "/input"
                ]
            );
            for c in channels {
                assert_eq!(
                    (c["encoding"].as_str(), c["schemaEncoding"].as_str()),
                    (Some("protobuf"), Some("protobuf"))
                );
                assert!(c["schema"].as_str().unwrap().len() > 100, "{}", c["topic"]);
            }
            let id =
                |topic: &str| channels.iter().find(|c| c["topic"] == topic).unwrap()["id"].clone();
            let subscribe = serde_json::json!({"op": "subscribe", "subscriptions": [
                {"id": 7, "channelId": id("/stats")}, {"id": 8, "channelId": id("/scene")}]});
            ws.send(Message::text(subscribe.to_string())).await.unwrap();
            // /scene is latched: its last message comes at once; /stats every frame, frame
            // numbers rising, at frame * dt.
            let mut frames = Vec::new();
            let mut scenes = 0;
            while frames.len() < 5 {
                let (sub, time, payload) = next_data(&mut ws).await;
                match sub {
                    7 => {
                        let stats = Stats::decode(payload.as_slice()).unwrap();
                        assert_eq!(time, stats.frame * 16_666_667);
                        frames.push(stats.frame);
                    }
                    8 => scenes += 1,
                    other => panic!("subscription {other}"),
                }
            }
            assert!(scenes >= 1, "the latched scene");
            assert!(frames.windows(2).all(|w| w[1] == w[0] + 1), "{frames:?}");
            ws.close(None).await.unwrap();
        }
    });
}

#[test]
fn other_subprotocols_are_refused_and_bad_clients_harm_nobody() {
    let server = serve(&["--speed", "4"]);
    runtime().block_on(async {
        let refused = connect(&server.url, "chat").await.unwrap_err();
        assert!(refused.contains("400"), "{refused}");
        // A client that sends garbage, then vanishes without a close.
        let (mut bad, _) = connect(&server.url, "foxglove.websocket.v1").await.unwrap();
        let _ = next_json(&mut bad).await;
        let _ = next_json(&mut bad).await;
        bad.send(Message::text("{not json")).await.unwrap();
        let status = next_json(&mut bad).await;
        assert_eq!(
            (status["op"].as_str(), status["level"].as_u64()),
            (Some("status"), Some(2))
        );
        bad.send(Message::text(
            r#"{"op":"subscribe","subscriptions":[{"id":1,"channelId":999}]}"#,
        ))
        .await
        .unwrap();
        let status = next_json(&mut bad).await;
        assert!(
            status["message"].as_str().unwrap().contains("999"),
            "{status}"
        );
        // Malformed binary frames: an unknown opcode, a service call and a playback request
        // cut short, a message on a channel never advertised.
        for (frame, says) in [
            (vec![9u8, 1, 2], "neither"),
            (vec![2u8, 1, 0], "cut short"),
            (vec![3u8, 0], "cut short"),
            (vec![1u8, 7, 0, 0, 0, b'{', b'}'], "not an advertised"),
        ] {
            bad.send(Message::binary(frame)).await.unwrap();
            let status = next_json(&mut bad).await;
            let message = status["message"].as_str().unwrap_or_default();
            assert!(message.contains(says), "{says}: {status}");
        }
        drop(bad);
        // Another client is served as before.
        let (mut good, _) = connect(&server.url, "foxglove.websocket.v1").await.unwrap();
        let _ = next_json(&mut good).await;
        let advertise = next_json(&mut good).await;
        subscribe_to(&mut good, &advertise, "/stats", 1).await;
        let (sub, _, payload) = next_data(&mut good).await;
        assert_eq!(sub, 1);
        Stats::decode(payload.as_slice()).unwrap();
    });
}

#[test]
fn sigterm_finishes_the_recording_as_a_complete_log() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("session.mcap");
    let mut server = serve(&["--speed", "8", "--record", out.to_str().unwrap()]);
    std::thread::sleep(Duration::from_millis(700));
    let pid = server.child.id().to_string();
    let killed = Command::new("kill").args(["-TERM", &pid]).status().unwrap();
    assert!(killed.success());
    let status = server.child.wait().unwrap();
    assert!(status.success(), "{status}");
    let log = ricochet_log::read_log_file(&out).expect("a complete, indexed log");
    let frames: Vec<u64> = log
        .iter()
        .filter(|m| m.topic == "/stats")
        .map(|m| m.data["frame"].as_u64().unwrap())
        .collect();
    assert!(frames.len() > 5, "{} frames recorded", frames.len());
    assert!(
        frames.iter().enumerate().all(|(i, f)| *f == i as u64),
        "every frame, in order"
    );
}

#[test]
fn inputs_from_a_client_are_applied_recorded_and_replayed_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("session.mcap");
    let mut server = serve(&["--speed", "4", "--record", out.to_str().unwrap()]);
    runtime().block_on(async {
        let (mut ws, _) = connect(&server.url, "foxglove.websocket.v1").await.unwrap();
        let info = next_json(&mut ws).await;
        assert!(
            info["capabilities"]
                .as_array()
                .unwrap()
                .contains(&"clientPublish".into())
        );
        // Subscribing to /tf makes the server send every pose again, to this viewer only:
        // the recording (and so the replay) never sees it.
        let channels = next_json(&mut ws).await;
        subscribe_to(&mut ws, &channels, "/tf", 1).await;
        let advertise = serde_json::json!({"op": "advertise", "channels": [
            {"id": 5, "topic": "/input", "encoding": "json", "schemaName": "ricochet.Input"}]});
        ws.send(Message::text(advertise.to_string())).await.unwrap();
        let send = |text: &str| {
            let mut data = vec![1u8];
            data.extend_from_slice(&5u32.to_le_bytes());
            data.extend_from_slice(text.as_bytes());
            Message::binary(data)
        };
        for text in [
            r#"{"action": "thrust", "body": "ship", "on": true}"#,
            r#"{"action": "turn", "body": "ship", "input": 0.5}"#,
            r#"{"action": "fire", "body": "ship"}"#,
            r#"{"action": "spawn", "template": "asteroid_small", "name": "visitor", "position": [5.0, 5.0], "velocity": [1.0, 0.0]}"#,
            r#"{"action": "fire", "body": "nobody"}"#,
            r#"{"action": "warp", "body": "ship"}"#,
        ] {
            ws.send(send(text)).await.unwrap();
            tokio::time::sleep(Duration::from_millis(50)).await;
        }
        // The two bad inputs are refused, and the client told.
        let mut refused = Vec::new();
        while refused.len() < 2 {
            let status = next_json(&mut ws).await;
            if status["op"] == "status" {
                refused.push(status["message"].as_str().unwrap().to_owned());
            }
        }
        assert!(refused[0].contains("nobody"), "{refused:?}");
        assert!(refused[1].contains("warp"), "{refused:?}");
        tokio::time::sleep(Duration::from_millis(200)).await;
    });
    let pid = server.child.id().to_string();
    assert!(
        Command::new("kill")
            .args(["-TERM", &pid])
            .status()
            .unwrap()
            .success()
    );
    assert!(server.child.wait().unwrap().success());
    let log = ricochet_log::read_log_file(&out).unwrap();
    let inputs: Vec<&Value> = log
        .iter()
        .filter(|m| m.topic == "/input")
        .map(|m| &m.data)
        .collect();
    assert_eq!(inputs.len(), 6, "every input recorded, refused ones too");
    // The spawned body is in /bodies from the next frame on.
    let full = crate::util::full_bodies(&log);
    assert!(
        full.iter().any(|f| f["bodies"]
            .as_array()
            .unwrap()
            .iter()
            .any(|b| b["name"] == "visitor")),
        "the spawned body"
    );
    assert!(log.iter().any(|m| {
        m.topic == "/events"
            && m.data["message"]
                .as_str()
                .unwrap()
                .starts_with("input refused: no body named \"nobody\"")
    }));
    assert!(
        log.iter()
            .any(|m| m.topic == "/events"
                && m.data["message"].as_str().unwrap().contains("thrust on")),
        "the thrust was applied"
    );
    let replayed = dir.path().join("replayed.mcap");
    let o = Command::new(env!("CARGO_BIN_EXE_ricochet"))
        .args([
            "replay",
            out.to_str().unwrap(),
            "-o",
            replayed.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        std::fs::read(&out).unwrap() == std::fs::read(&replayed).unwrap(),
        "byte-identical"
    );
}

#[test]
fn a_client_that_never_reads_loses_messages_and_nobody_else_does() {
    let shapes = crate::util::root().join("scenarios/shapes.toml");
    let mut server = serve(&[shapes.to_str().unwrap(), "--speed", "40"]);
    runtime().block_on(async {
        // The slow client subscribes to everything, then never reads again.
        let (mut slow, _) = connect(&server.url, "foxglove.websocket.v1").await.unwrap();
        let _ = next_json(&mut slow).await;
        let channels = next_json(&mut slow).await;
        let all: Vec<Value> = channels["channels"]
            .as_array()
            .unwrap()
            .iter()
            .enumerate()
            .map(|(i, c)| serde_json::json!({"id": i, "channelId": c["id"]}))
            .collect();
        let subscribe = serde_json::json!({"op": "subscribe", "subscriptions": all});
        slow.send(Message::text(subscribe.to_string()))
            .await
            .unwrap();
        // A good client reads /stats all along: every frame, none missing.
        let (mut good, _) = connect(&server.url, "foxglove.websocket.v1").await.unwrap();
        let _ = next_json(&mut good).await;
        let channels = next_json(&mut good).await;
        subscribe_to(&mut good, &channels, "/stats", 1).await;
        let mut frames = Vec::new();
        let until = std::time::Instant::now() + Duration::from_secs(6);
        while std::time::Instant::now() < until {
            let (_, _, payload) = next_data(&mut good).await;
            frames.push(Stats::decode(payload.as_slice()).unwrap().frame);
        }
        assert!(frames.len() > 1000, "{} frames", frames.len());
        assert!(
            frames.windows(2).all(|w| w[1] == w[0] + 1),
            "the good client missed frames"
        );
        drop(slow);
    });
    let pid = server.child.id().to_string();
    assert!(
        Command::new("kill")
            .args(["-TERM", &pid])
            .status()
            .unwrap()
            .success()
    );
    assert!(server.child.wait().unwrap().success());
    std::thread::sleep(Duration::from_millis(200));
    let lines = server.lines.lock().unwrap().clone();
    let last = lines
        .iter()
        .find(|l| l.starts_with("served "))
        .expect("a summary line");
    let dropped: u64 = last
        .split("; ")
        .nth(1)
        .and_then(|s| s.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap();
    assert!(dropped > 0, "the slow client lost messages: {last}");
}

/// Calls service `name` with `request`; its JSON response, or the failure's message.
async fn call(
    ws: &mut Ws,
    services: &Value,
    name: &str,
    call: u32,
    request: &str,
) -> Result<Value, String> {
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
    loop {
        let m = tokio::time::timeout(Duration::from_secs(10), ws.next())
            .await
            .expect("an answer within 10 s")
            .unwrap()
            .unwrap();
        match m {
            Message::Binary(b) if b[0] == 3 => {
                assert_eq!(u32::from_le_bytes(b[5..9].try_into().unwrap()), call);
                assert_eq!(&b[13..17], b"json");
                return Ok(serde_json::from_slice(&b[17..]).unwrap());
            }
            Message::Text(t) => {
                let v: Value = serde_json::from_str(t.as_str()).unwrap();
                if v["op"] == "serviceCallFailure" {
                    return Err(v["message"].as_str().unwrap().to_owned());
                }
            }
            _ => {}
        }
    }
}

#[test]
fn services_pause_step_seek_and_reset_and_each_recording_segment_replays() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("session.mcap");
    let mut server = serve(&["--speed", "4", "--record", out.to_str().unwrap()]);
    runtime().block_on(async {
        let (mut ws, _) = connect(&server.url, "foxglove.websocket.v1").await.unwrap();
        let info = any_json(&mut ws).await;
        assert!(
            info["capabilities"]
                .as_array()
                .unwrap()
                .contains(&"services".into())
        );
        let _ = any_json(&mut ws).await;
        let services = any_json(&mut ws).await;
        assert_eq!(services["op"], "advertiseServices");
        let paused = call(&mut ws, &services, "/pause", 1, "{}").await.unwrap();
        assert_eq!(paused["paused"], true);
        let at = paused["frame"].as_u64().unwrap();
        tokio::time::sleep(Duration::from_millis(300)).await;
        // Paused: no frame went by; a step of 3 makes exactly 3.
        let stepped = call(&mut ws, &services, "/step", 2, r#"{"frames": 3}"#)
            .await
            .unwrap();
        assert_eq!(stepped["frame"].as_u64().unwrap(), at + 3);
        let bad = call(&mut ws, &services, "/step", 3, r#"{"frames": 0}"#)
            .await
            .unwrap_err();
        assert!(bad.contains("frames"), "{bad}");
        let outside = call(
            &mut ws,
            &services,
            "/load",
            4,
            r#"{"scenario": "/etc/passwd"}"#,
        )
        .await
        .unwrap_err();
        assert!(outside.contains("relative path"), "{outside}");
        let reset = call(&mut ws, &services, "/reset", 5, "{}").await.unwrap();
        assert_eq!(reset["frame"], 0);
        assert!(
            reset["recording"]
                .as_str()
                .unwrap()
                .ends_with("session-1.mcap"),
            "{reset}"
        );
        call(&mut ws, &services, "/play", 6, "{}").await.unwrap();
        tokio::time::sleep(Duration::from_millis(300)).await;
        // Seek back: the session again from frame 0 to frame 5, in a new file; forward: steps.
        call(&mut ws, &services, "/pause", 7, "{}").await.unwrap();
        let back = call(&mut ws, &services, "/seek", 8, r#"{"frame": 5}"#)
            .await
            .unwrap();
        assert_eq!(back["frame"], 5);
        assert!(
            back["recording"]
                .as_str()
                .unwrap()
                .ends_with("session-2.mcap"),
            "{back}"
        );
        let forward = call(&mut ws, &services, "/seek", 9, r#"{"frame": 40}"#)
            .await
            .unwrap();
        assert_eq!(forward["frame"], 40);
        assert!(forward.get("recording").is_none(), "{forward}");
        let fast = call(&mut ws, &services, "/speed", 10, r#"{"speed": 2.5}"#)
            .await
            .unwrap();
        assert_eq!(fast["frame"], 40);
        let bad = call(&mut ws, &services, "/speed", 11, r#"{"speed": 0}"#)
            .await
            .unwrap_err();
        assert!(bad.contains("speed"), "{bad}");
        call(&mut ws, &services, "/play", 12, "{}").await.unwrap();
        tokio::time::sleep(Duration::from_millis(200)).await;
    });
    let pid = server.child.id().to_string();
    assert!(
        Command::new("kill")
            .args(["-TERM", &pid])
            .status()
            .unwrap()
            .success()
    );
    assert!(server.child.wait().unwrap().success());
    for file in ["session.mcap", "session-1.mcap", "session-2.mcap"] {
        let recorded = dir.path().join(file);
        let replayed = dir.path().join(format!("{file}.replay"));
        let o = Command::new(env!("CARGO_BIN_EXE_ricochet"))
            .args([
                "replay",
                recorded.to_str().unwrap(),
                "-o",
                replayed.to_str().unwrap(),
            ])
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{file}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
}

#[test]
fn a_flood_of_inputs_is_rate_limited_and_the_server_keeps_time() {
    let server = serve(&["--speed", "2"]);
    runtime().block_on(async {
        let (mut flood, _) = connect(&server.url, "foxglove.websocket.v1").await.unwrap();
        let _ = next_json(&mut flood).await;
        let _ = next_json(&mut flood).await;
        let advertise = serde_json::json!({"op": "advertise", "channels": [
            {"id": 9, "topic": "/input", "encoding": "json", "schemaName": "ricochet.Input"}]});
        flood
            .send(Message::text(advertise.to_string()))
            .await
            .unwrap();
        let input = br#"{"action": "turn", "body": "ship", "input": 0.25}"#;
        for _ in 0..6000 {
            let mut data = vec![1u8];
            data.extend_from_slice(&9u32.to_le_bytes());
            data.extend_from_slice(input);
            flood.feed(Message::binary(data)).await.unwrap();
        }
        flood.flush().await.unwrap();
        // Past 2,000 a second, inputs are refused and the client told.
        let status = next_json(&mut flood).await;
        assert!(
            status["message"]
                .as_str()
                .unwrap()
                .contains("inputs a second"),
            "{status}"
        );
        // Meanwhile another client gets every frame, on time.
        let (mut good, _) = connect(&server.url, "foxglove.websocket.v1").await.unwrap();
        let _ = next_json(&mut good).await;
        let channels = next_json(&mut good).await;
        subscribe_to(&mut good, &channels, "/stats", 1).await;
        let started = std::time::Instant::now();
        let mut frames = Vec::new();
        while frames.len() < 60 {
            let (_, _, payload) = next_data(&mut good).await;
            frames.push(Stats::decode(payload.as_slice()).unwrap().frame);
        }
        assert!(frames.windows(2).all(|w| w[1] == w[0] + 1), "{frames:?}");
        // 60 frames at twice real time take half a second; a stalled server would take longer.
        assert!(
            started.elapsed() < Duration::from_secs(5),
            "{:?}",
            started.elapsed()
        );
    });
}

#[test]
fn paused_serves_frame_0_and_steps_only_when_asked() {
    let server = serve(&["--paused"]);
    runtime().block_on(async {
        let (mut ws, _) = connect(&server.url, "foxglove.websocket.v1").await.unwrap();
        let _ = any_json(&mut ws).await;
        let _ = any_json(&mut ws).await;
        let services = any_json(&mut ws).await;
        tokio::time::sleep(Duration::from_millis(300)).await;
        // Paused after frame 0: the next frame is 1, however long we waited.
        let stepped = call(&mut ws, &services, "/step", 1, r#"{"frames": 2}"#)
            .await
            .unwrap();
        assert_eq!(
            (stepped["frame"].as_u64(), stepped["paused"].as_bool()),
            (Some(3), Some(true))
        );
    });
}

#[test]
fn playback_control_pauses_seeks_and_plays_and_every_client_is_told_the_state() {
    let server = serve(&["--speed", "2"]);
    runtime().block_on(async {
        let (mut ws, _) = connect(&server.url, "foxglove.sdk.v1").await.unwrap();
        let info = any_json(&mut ws).await;
        assert!(
            info["capabilities"]
                .as_array()
                .unwrap()
                .contains(&"playbackControl".into())
        );
        // The timeline: frame 0 to the scenario's last (600 frames at 60 Hz).
        assert_eq!(
            info["dataStartTime"],
            serde_json::json!({"sec": 0, "nsec": 0})
        );
        assert_eq!(
            info["dataEndTime"],
            serde_json::json!({"sec": 10, "nsec": 200})
        );
        // Pause, seeking to 1 s (frame 60), as the SDK encodes a PlaybackControlRequest.
        let request = |play: bool, seek: Option<u64>, id: &str| {
            let mut data = vec![3u8, u8::from(!play)];
            data.extend_from_slice(&1.0f32.to_le_bytes());
            data.push(u8::from(seek.is_some()));
            data.extend_from_slice(&seek.unwrap_or(0).to_le_bytes());
            data.extend_from_slice(&(id.len() as u32).to_le_bytes());
            data.extend_from_slice(id.as_bytes());
            Message::binary(data)
        };
        ws.send(request(false, Some(1_000_000_000), "a"))
            .await
            .unwrap();
        let (status, time, sought, id) = playback_state(&mut ws).await;
        assert_eq!((status, sought, id.as_str()), (1, 1, "a"), "paused, sought");
        assert_eq!(time, 59 * 16_666_667, "the frame at or before 1 s");
        ws.send(request(true, None, "b")).await.unwrap();
        let (status, _, sought, id) = playback_state(&mut ws).await;
        assert_eq!((status, sought, id.as_str()), (0, 0, "b"), "playing");
    });
}

/// The next playback state: (status, time, whether it sought, request id).
async fn playback_state(ws: &mut Ws) -> (u8, u64, u8, String) {
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
async fn step_stats(ws: &mut Ws, services: &Value, call_id: u32) -> Stats {
    let service = services["services"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["name"] == "/step")
        .unwrap()["id"]
        .as_u64()
        .unwrap() as u32;
    let mut data = vec![2u8];
    data.extend_from_slice(&service.to_le_bytes());
    data.extend_from_slice(&call_id.to_le_bytes());
    data.extend_from_slice(&4u32.to_le_bytes());
    data.extend_from_slice(b"json{\"frames\": 1}");
    ws.send(Message::binary(data)).await.unwrap();
    let (mut stepped, mut frame) = (Vec::new(), None);
    loop {
        let m = tokio::time::timeout(Duration::from_secs(10), ws.next())
            .await
            .expect("a message within 10 s")
            .unwrap()
            .unwrap();
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

#[test]
fn seeking_back_from_a_snapshot_gives_the_state_a_straight_run_has() {
    // The same scenario run straight through, with `ricochet run`: the expected states.
    let dir = tempfile::tempdir().unwrap();
    let straight = dir.path().join("straight.mcap");
    let scenario = crate::util::root().join("scenarios/asteroids.toml");
    let args = ["run", scenario.to_str().unwrap(), "--frames", "1400", "-o"];
    let o = crate::util::ricochet(&[&args[..], &[straight.to_str().unwrap()]].concat(), b"");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let expected: Vec<Value> = ricochet_log::read_log_file(&straight)
        .unwrap()
        .into_iter()
        .filter(|m| m.topic == "/stats")
        .map(|m| m.data)
        .collect();
    let server = serve(&["--paused"]);
    runtime().block_on(async {
        let (mut ws, _) = connect(&server.url, "foxglove.websocket.v1").await.unwrap();
        let _ = any_json(&mut ws).await;
        let channels = any_json(&mut ws).await;
        let services = any_json(&mut ws).await;
        subscribe_to(&mut ws, &channels, "/stats", 1).await;
        // Forward past two snapshots (every 600 frames; not recording); back to 599 and 590
        // (before the first snapshot: from frame 0), forward to 1250, back to 601 (from the
        // snapshot of frame 600); each checked by the next frame's stats against the
        // straight run's.
        let mut id = 10;
        for target in [1300u64, 599, 590, 1250, 601] {
            let request = format!(r#"{{"frame": {target}}}"#);
            let sought = call(&mut ws, &services, "/seek", id, &request).await;
            assert_eq!(sought.unwrap()["frame"], target);
            let got = step_stats(&mut ws, &services, id + 1).await;
            id += 2;
            let want = &expected[target as usize];
            assert_eq!(got.frame, target);
            assert_eq!(
                got.bodies,
                want["bodies"].as_u64().unwrap(),
                "frame {target}"
            );
            assert_eq!(
                got.kinetic_energy,
                want["kinetic_energy"].as_f64().unwrap(),
                "frame {target}"
            );
            assert_eq!(
                got.contacts,
                want["contacts"].as_u64().unwrap(),
                "frame {target}"
            );
        }
    });
}
