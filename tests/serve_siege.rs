//! Issue 20's acceptance: one `serve --record` session under every hostile client at once
//! (overflowing impulses, seeks to 2^63 by service and by the timeline, 150 half-open
//! sockets and a client that never reads), while a well-behaved client keeps getting every
//! frame, the server's resident memory stays under its stated bound, and the recording
//! replays byte for byte. Loopback only; every wait is bounded.

use std::io::Write;
use std::net::TcpStream;
use std::time::Duration;

use futures_util::SinkExt;
use prost::Message as _;
use ricochet_log::messages::ricochet::Stats;
use tokio_tungstenite::tungstenite::Message;

use crate::serve_client::*;
use crate::serve_hostile::{ANSWER_ROOM, CLIENT_BUDGET, drifting_scene, port, status_kb};

/// The good client's next `/stats` frame (its subscription 1), checking it follows `last`.
async fn next_frame(good: &mut Ws, last: &mut u64) {
    let (sub, _, payload) = next_data(good).await;
    assert_eq!(sub, 1);
    let frame = Stats::decode(payload.as_slice()).unwrap().frame;
    assert!(
        *last == 0 || frame == *last + 1,
        "the good client got frame {frame} after {last}"
    );
    *last = frame;
}

/// A timeline request (the SDK's PlaybackControlRequest, opcode 3): play, seeking to `ns`.
fn timeline_seek(ns: u64) -> Message {
    let mut data = vec![3u8, 0];
    data.extend_from_slice(&1.0f32.to_le_bytes());
    data.push(1);
    data.extend_from_slice(&ns.to_le_bytes());
    data.extend_from_slice(&5u32.to_le_bytes());
    data.extend_from_slice(b"siege");
    Message::binary(data)
}

#[test]
fn a_recorded_session_under_every_hostile_client_serves_a_good_one_within_its_memory_bound() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("dust.toml");
    std::fs::write(&scene, drifting_scene(2000)).unwrap();
    let out = dir.path().join("s.mcap");
    let mut server = serve(&[
        scene.to_str().unwrap(),
        "--speed",
        "4",
        "--record",
        out.to_str().unwrap(),
    ]);
    let pid = server.child.id();
    let mut peak = 0;
    let (base, last) = runtime().block_on(async {
        let (mut good, _) = connect(&server.url, "foxglove.websocket.v1").await.unwrap();
        let _ = next_json(&mut good).await;
        let channels = next_json(&mut good).await;
        subscribe_to(&mut good, &channels, "/stats", 1).await;
        let mut last = 0;
        for _ in 0..30 {
            next_frame(&mut good, &mut last).await;
        }
        let base = status_kb(pid, "VmRSS:");

        // A client that subscribes to every channel and never reads again.
        let (mut slow, _) = connect(&server.url, "foxglove.websocket.v1").await.unwrap();
        let _ = next_json(&mut slow).await;
        subscribe_all(&mut slow, &channels).await;

        // 150 sockets that send half a handshake and stop.
        let port = port(&server.url);
        let half_open: Vec<TcpStream> = (0..150)
            .map(|_| {
                let mut s = TcpStream::connect(("127.0.0.1", port)).unwrap();
                s.write_all(b"GET / HTTP/1.1\r\nHost: x\r\n").unwrap();
                s
            })
            .collect();

        // Inputs that would overflow the state, and seeks to 2^63 (frames and ns).
        let (mut hostile, services) = open(&server, "foxglove.sdk.v1").await;
        advertise_input(&mut hostile).await;
        for text in [
            r#"{"action":"apply_impulse","body":"d0","impulse":[1.7e308,0]}"#,
            r#"{"action":"apply_impulse","body":"d0","impulse":[1.7e308,0]}"#,
            r#"{"action":"set_velocity","body":"d1","velocity":[1e300,1e300]}"#,
            r#"{"action":"set_force","body":"d2","force":[0,-1e308]}"#,
        ] {
            publish(&mut hostile, text).await;
        }
        let seek = call(
            &mut hostile,
            &services,
            "/seek",
            1,
            r#"{"frame": 9223372036854775808}"#,
        )
        .await;
        assert!(seek.unwrap_err().contains("past"), "a seek to 2^63 frames");
        hostile.send(timeline_seek(1 << 63)).await.unwrap();
        let (_, _, _, id) = playback_state(&mut hostile).await;
        assert_eq!(id, "siege", "the timeline's seek is answered");
        // The hostile client is done; it goes on existing without reading.

        // The good client gets every frame through all of it, in order.
        for _ in 0..400 {
            next_frame(&mut good, &mut last).await;
            peak = peak.max(status_kb(pid, "VmRSS:"));
        }
        drop(half_open);
        drop((slow, hostile));
        (base, last)
    });
    // The slow client's queue (its budget and the room for answers), 32 pending handshakes
    // of at most 64 KiB, and the allocator's slack and the message being written (as in
    // serve_hostile's bound for one slow client).
    let bound_kb = (CLIENT_BUDGET + ANSWER_ROOM + 32 * (64 << 10)) / 1024 + 23 * 1024;
    let grew = peak.saturating_sub(base);
    eprintln!("RSS base {base} kB, peak {peak} kB, grew {grew} kB (bound {bound_kb} kB)");
    assert!(grew < bound_kb, "RSS grew {grew} kB, over {bound_kb} kB");
    assert!(terminate(&mut server, Duration::from_secs(5)).success());
    let frames = replays_byte_for_byte(&out);
    // Frames 0 to at least the last one the good client got (it subscribed after frame 0).
    assert!(
        frames as u64 > last,
        "the recording holds {frames} frames, the good client got frame {last}"
    );
}
