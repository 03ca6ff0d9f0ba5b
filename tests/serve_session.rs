//! `ricochet serve` as a session: inputs from a client applied, recorded and replayed byte
//! for byte; services (pause, step, seek, reset) and recording segments; `--paused`; the
//! playback-control capability; seeks back, through frame 0 or a snapshot, giving exactly
//! the states of a straight run.

use std::process::Command;
use std::time::Duration;

use futures_util::SinkExt;
use prost::Message as _;
use ricochet_log::messages::fox::FrameTransforms;
use serde_json::Value;
use tokio_tungstenite::tungstenite::Message;

use crate::serve_client::*;
use crate::util::ricochet;

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
        // Subscribing to /tf (latched: this viewer gets the camera's last frame at once)
        // writes nothing: the recording (and so the replay) never sees it.
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
    replays_byte_for_byte(&out);
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
        // Seek back: the session again from frame 0 to frame 5, written again to the same
        // file (a seek adds no file); forward: steps.
        call(&mut ws, &services, "/pause", 7, "{}").await.unwrap();
        let back = call(&mut ws, &services, "/seek", 8, r#"{"frame": 5}"#)
            .await
            .unwrap();
        assert_eq!(back["frame"], 5);
        assert!(
            back["recording"]
                .as_str()
                .unwrap()
                .ends_with("session-1.mcap"),
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
    let mut files: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    files.sort();
    assert_eq!(
        files,
        ["session-1.mcap", "session.mcap"],
        "no file per seek"
    );
    for file in ["session.mcap", "session-1.mcap"] {
        replays_byte_for_byte(&dir.path().join(file));
    }
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

/// The raw payloads of `topic` in a log, by log time.
fn payloads(log: &std::path::Path, topic: &str) -> Vec<(u64, Vec<u8>)> {
    let bytes = std::fs::read(log).unwrap();
    let messages = mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(Result::unwrap);
    let ours = messages.filter(|m| m.channel.topic == topic);
    ours.map(|m| (m.log_time, m.data.into_owned())).collect()
}

/// Subscribes to the three latched topics: the last message of each comes at once, and
/// nothing else while paused. Their (time, payload), in that order.
async fn latched(ws: &mut Ws, channels: &Value) -> Vec<(u64, Vec<u8>)> {
    for (id, topic) in [(1, "/scene"), (2, "/scene/static"), (3, "/tf")] {
        subscribe_to(ws, channels, topic, id).await;
    }
    let mut got = std::collections::BTreeMap::new();
    while got.len() < 3 {
        let (sub, time, payload) = next_data(ws).await;
        assert!(
            got.insert(sub, (time, payload)).is_none(),
            "subscription {sub} twice"
        );
    }
    let more = tokio::time::timeout(Duration::from_millis(300), next_data(ws)).await;
    assert!(more.is_err(), "more data while paused");
    got.into_values().collect()
}

#[test]
fn a_client_that_subscribes_while_paused_gets_the_whole_scene_at_once() {
    // The scene as `ricochet run` records it: frame 0, then frame 3.
    let dir = tempfile::tempdir().unwrap();
    let scenario = crate::util::root().join("scenarios/platformer.toml");
    let straight = dir.path().join("straight.mcap");
    let args = ["run", scenario.to_str().unwrap(), "--frames", "3", "-o"];
    let o = crate::util::ricochet(&[&args[..], &[straight.to_str().unwrap()]].concat(), b"");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let recorded: Vec<Vec<(u64, Vec<u8>)>> = ["/scene", "/scene/static", "/tf"]
        .iter()
        .map(|topic| payloads(&straight, topic))
        .collect();
    // Platformer's static tiles are sent once (frame 0), as is the camera's frame (the
    // centre of the world's bounds); its moving bodies every frame.
    assert_eq!(recorded[1].len(), 1, "/scene/static once");
    assert_eq!(recorded[2].len(), 1, "/tf once");
    assert_eq!(recorded[0].len(), 4, "/scene every frame");
    let server = serve(&[scenario.to_str().unwrap(), "--paused"]);
    runtime().block_on(async {
        let (mut ws, _) = connect(&server.url, "foxglove.websocket.v1").await.unwrap();
        let _ = any_json(&mut ws).await;
        let channels = any_json(&mut ws).await;
        let services = any_json(&mut ws).await;
        tokio::time::sleep(Duration::from_millis(300)).await;
        let first = latched(&mut ws, &channels).await;
        let want = [&recorded[0][0], &recorded[1][0], &recorded[2][0]];
        for (topic, (got, want)) in ["/scene", "/scene/static", "/tf"]
            .iter()
            .zip(first.iter().zip(want))
        {
            assert!(got == want, "{topic}: frame 0's, as recorded");
        }
        // Three frames on, a new viewer gets frame 3's moving bodies, the static ones as
        // they have been since frame 0, and the camera's frame as it has been since frame 0
        // stamped again at frame 3: each drawing carries it to live viewers (Lichtblick's
        // live 3D panel does not apply a transform stamped long before the frames it shows;
        // a file records it once).
        let stepped = call(&mut ws, &services, "/step", 4, r#"{"frames": 3}"#)
            .await
            .unwrap();
        assert_eq!(stepped["frame"], 4, "frames 1 to 3 stepped: 4 is next");
        let (mut late, _) = connect(&server.url, "foxglove.websocket.v1").await.unwrap();
        let _ = any_json(&mut late).await;
        let channels = any_json(&mut late).await;
        let now = latched(&mut late, &channels).await;
        let want = [&recorded[0][3], &recorded[1][0]];
        for (topic, (got, want)) in ["/scene", "/scene/static"].iter().zip(now.iter().zip(want)) {
            assert!(got == want, "{topic}: the last sent, as recorded");
        }
        let frame_3 = recorded[0][3].0;
        assert_eq!(now[2].0, frame_3, "/tf: sent with frame 3's drawing");
        let got = FrameTransforms::decode(now[2].1.as_slice()).unwrap();
        let mut want = FrameTransforms::decode(recorded[2][0].1.as_slice()).unwrap();
        for t in &mut want.transforms {
            t.timestamp = Some(ricochet_log::messages::timestamp(frame_3));
        }
        assert_eq!(got, want, "/tf: frame 0's camera, stamped at frame 3");
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

/// A game with players, for `ricochet replay`'s refusal: it names itself in its log.
struct Tag;

impl ricochet_sim::Game for Tag {
    type Input = ();
    type State = ();
    fn name(&self) -> &str {
        "tag"
    }
    fn join(
        &mut self,
        _: &mut ricochet_sim::Simulation,
        _: ricochet_sim::Player,
        _: &str,
    ) -> Result<(), String> {
        Ok(())
    }
    fn input(
        &mut self,
        _: &mut ricochet_sim::Simulation,
        _: ricochet_sim::Player,
        (): (),
    ) -> Result<(), String> {
        Ok(())
    }
}

#[test]
fn replay_of_a_game_it_does_not_have_is_refused_naming_the_game() {
    let dir = tempfile::tempdir().unwrap();
    let log_path = dir.path().join("room.mcap");
    let mut log = ricochet_record::log_writer(&log_path).unwrap();
    // A room of a game records the scenario it was built from too, as a served room does.
    log.attach(
        "scenario.toml",
        "application/toml",
        b"name = \"x\"\n[world]\ndt = 0.0166\n",
    )
    .unwrap();
    let sim = ricochet_sim::Simulation::from_def(ricochet_sim::WorldDef::default()).unwrap();
    let mut session = ricochet_record::session::GameSession::start(sim, Tag, log, true).unwrap();
    session.join("ada").unwrap().unwrap();
    for _ in 0..3 {
        session.step().unwrap();
    }
    session.into_sink().finish().unwrap();
    let out = ricochet(&["replay", log_path.to_str().unwrap()], b"");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("recorded by the game \"tag\""), "{stderr}");
    // Nothing was written beside it.
    assert!(!dir.path().join("room.replay.mcap").exists());
}
