//! `ricochet serve` over a real WebSocket client (tokio-tungstenite), speaking the published
//! Foxglove WebSocket protocol: both subprotocols accepted, any other refused; the server
//! info and the channels advertised with their protobuf schemas; subscriptions answered
//! with messages that decode as the log's; malformed messages and an abrupt disconnect
//! answered without harm; a slow client and a flood; SIGTERM finishes the recording as a
//! complete log.

use std::process::Command;
use std::time::Duration;

use futures_util::SinkExt;
use prost::Message as _;
use ricochet_log::messages::ricochet::Stats;
use tokio_tungstenite::tungstenite::Message;

use crate::serve_client::*;

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
                    "/input/recorded"
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
fn a_client_that_never_reads_loses_messages_and_nobody_else_does() {
    let shapes = crate::util::root().join("scenarios/shapes.toml");
    let mut server = serve(&[shapes.to_str().unwrap(), "--speed", "40"]);
    runtime().block_on(async {
        // The slow client subscribes to everything, then never reads again.
        let (mut slow, _) = connect(&server.url, "foxglove.websocket.v1").await.unwrap();
        let _ = next_json(&mut slow).await;
        let channels = next_json(&mut slow).await;
        subscribe_all(&mut slow, &channels).await;
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
