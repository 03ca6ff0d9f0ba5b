//! `ricochet serve` under hostile connections (issue 20), on loopback, bounded in count and
//! time: half-open sockets under a file-descriptor limit, a client advertising past the
//! cap, a client that never reads on a scene of thousands of bodies (the server's RSS stays
//! under its stated bound).

use std::io::{Read, Write};
use std::net::TcpStream;
use std::process::Command;
use std::time::{Duration, Instant};

use futures_util::SinkExt;
use prost::Message as _;
use ricochet_log::messages::ricochet::Stats;
use serde_json::Value;
use tokio_tungstenite::tungstenite::Message;

use crate::serve_client::*;

/// The server's per-client byte budget and its room for answers (crates/serve/src/hub.rs).
pub(crate) const CLIENT_BUDGET: u64 = 8 << 20;
pub(crate) const ANSWER_ROOM: u64 = 1 << 20;

pub(crate) fn port(url: &str) -> u16 {
    url.rsplit(':').next().unwrap().parse().unwrap()
}

/// A field of /proc/PID/status, in kB.
pub(crate) fn status_kb(pid: u32, field: &str) -> u64 {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap();
    status
        .lines()
        .find_map(|l| l.strip_prefix(field))
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{field} in /proc/{pid}/status"))
}

/// User plus system CPU seconds of a process, from /proc/PID/stat.
fn cpu_seconds(pid: u32) -> f64 {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap();
    let fields: Vec<&str> = stat
        .rsplit(')')
        .next()
        .unwrap()
        .split_whitespace()
        .collect();
    let ticks: u64 = fields[11].parse::<u64>().unwrap() + fields[12].parse::<u64>().unwrap();
    // USER_HZ is 100 on every Linux ABI.
    ticks as f64 / 100.0
}

/// Whether the server closed `socket` (EOF or reset), waiting at most until `deadline`.
fn closed_by(socket: &mut TcpStream, deadline: Instant) -> bool {
    let mut buf = [0u8; 512];
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return false;
        }
        socket.set_read_timeout(Some(left)).unwrap();
        match socket.read(&mut buf) {
            Ok(0) => return true,
            Ok(_) => {}
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => return false,
            Err(e) if e.kind() == std::io::ErrorKind::TimedOut => return false,
            Err(_) => return true,
        }
    }
}

// Issue 20: 150 sockets that send half a request and stop exhausted the descriptors; the
// accept loop then spun (a CPU-second a second) and a real client's handshake timed out.
#[test]
fn half_open_sockets_neither_spin_the_server_nor_lock_out_a_real_client() {
    // 24 descriptors: the server uses about 10 of its own, so the sockets run it out of
    // descriptors before the pending handshakes reach their cap.
    let mut command = Command::new("sh");
    command.args([
        "-c",
        "ulimit -n 24 && exec \"$0\" serve --bind 127.0.0.1:0 --paused",
        env!("CARGO_BIN_EXE_ricochet"),
    ]);
    let server = serve_with(command);
    let pid = server.child.id();
    let addr = std::net::SocketAddr::from(([127, 0, 0, 1], port(&server.url)));
    let mut half_open: Vec<TcpStream> = (0..150)
        .map(|_| {
            // A server that stops accepting lets the backlog fill: fail in seconds, not
            // after the kernel's two minutes of retries.
            let mut s = TcpStream::connect_timeout(&addr, Duration::from_secs(3))
                .expect("the server takes connections");
            s.write_all(b"GET / HTTP/1.1\r\nHost: x\r\n").unwrap();
            s
        })
        .collect();
    let cpu = cpu_seconds(pid);
    std::thread::sleep(Duration::from_secs(2));
    let spent = cpu_seconds(pid) - cpu;
    assert!(spent < 0.5, "{spent} CPU seconds in 2 s, paused");
    runtime().block_on(async {
        let (mut ws, _) = tokio::time::timeout(
            Duration::from_secs(3),
            connect(&server.url, "foxglove.websocket.v1"),
        )
        .await
        .expect("a real client's handshake within 3 s")
        .unwrap();
        assert_eq!(next_json(&mut ws).await["op"], "serverInfo");
    });
    // Each is closed: evicted by newer ones, or after the 5 s handshake timeout.
    let deadline = Instant::now() + Duration::from_secs(8);
    let open = half_open
        .iter_mut()
        .map(|s| closed_by(s, deadline))
        .filter(|closed| !closed)
        .count();
    assert_eq!(open, 0, "half-open sockets still open 8 s on");
}

// Issue 20: `advertise` had no cap (13 M client channels took 200 MB more).
#[test]
fn advertising_past_the_cap_is_refused_and_the_client_told() {
    let server = serve(&["--paused"]);
    runtime().block_on(async {
        let (mut ws, _) = connect(&server.url, "foxglove.websocket.v1").await.unwrap();
        let _ = next_json(&mut ws).await;
        let _ = next_json(&mut ws).await;
        let channels: Vec<Value> = (0..300)
            .map(|i| serde_json::json!({"id": i, "topic": format!("/t{i}"), "encoding": "json", "schemaName": "x"}))
            .collect();
        let advertise = serde_json::json!({"op": "advertise", "channels": channels});
        ws.send(Message::text(advertise.to_string())).await.unwrap();
        let status = tokio::time::timeout(Duration::from_secs(3), next_json(&mut ws))
            .await
            .expect("a status within 3 s");
        assert_eq!(status["op"], "status", "{status}");
        let message = status["message"].as_str().unwrap();
        assert!(
            message.contains("channel 256 refused") && message.contains("at most 256"),
            "{message}"
        );
        // The 256 taken still work: an input on one of them is refused only for its topic.
        let mut data = vec![1u8];
        data.extend_from_slice(&5u32.to_le_bytes());
        data.extend_from_slice(b"{}");
        ws.send(Message::binary(data)).await.unwrap();
        let status = next_json(&mut ws).await;
        assert!(
            status["message"]
                .as_str()
                .unwrap()
                .contains("not an advertised /input channel"),
            "{status}"
        );
    });
}

/// A scene of `n` circles drifting on a layer that collides with nothing: every frame sends
/// the whole /scene (every body moved; per-layer batches above 1000 bodies).
pub(crate) fn drifting_scene(n: usize) -> String {
    let mut text = String::from("hz = 60\nframes = 100000\nlayers = [\"dust\"]\n");
    for i in 0..n {
        let (x, y) = ((i % 100) as f64 * 3.0, (i / 100) as f64 * 3.0);
        text.push_str(&format!(
            "[[bodies]]\nname = \"d{i}\"\nlayer = \"dust\"\nshape = {{ kind = \"circle\", radius = 1 }}\nposition = [{x}, {y}]\nvelocity = [0.5, 0.25]\n"
        ));
    }
    text
}

// Issue 20: the queue counted messages, not bytes: four clients that never read, on a
// 5,000-body scene, took 1.2 GB.
#[test]
fn a_client_that_never_reads_keeps_the_server_within_its_byte_budget() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("dust.toml");
    std::fs::write(&scene, drifting_scene(3000)).unwrap();
    let server = serve(&[scene.to_str().unwrap(), "--speed", "4"]);
    let pid = server.child.id();
    runtime().block_on(async {
        // A good client reads /stats all along; the server's resident size with it is the
        // base.
        let (mut good, _) = connect(&server.url, "foxglove.websocket.v1").await.unwrap();
        let _ = next_json(&mut good).await;
        let channels = next_json(&mut good).await;
        subscribe_to(&mut good, &channels, "/stats", 1).await;
        for _ in 0..30 {
            next_data(&mut good).await;
        }
        let base = status_kb(pid, "VmRSS:");
        // The slow client subscribes to everything, then never reads again.
        let (mut slow, _) = connect(&server.url, "foxglove.websocket.v1").await.unwrap();
        let _ = next_json(&mut slow).await;
        subscribe_all(&mut slow, &channels).await;
        // 600 frames: enough for the old message-counted queue (4,096 messages, 9 a frame)
        // to fill with hundreds of megabytes.
        let mut last = 0;
        let mut peak = base;
        while last < 600 {
            let (_, _, payload) = next_data(&mut good).await;
            let frame = Stats::decode(payload.as_slice()).unwrap().frame;
            assert!(frame == last + 1 || last == 0, "{last} then {frame}");
            last = frame;
            peak = peak.max(status_kb(pid, "VmRSS:"));
        }
        // Its queue (the budget, and room for answers), the message being written, and the
        // allocator's slack: 32 MiB in all over the base.
        let bound_kb = (CLIENT_BUDGET + ANSWER_ROOM) / 1024 + 23 * 1024;
        let grew = peak.saturating_sub(base);
        eprintln!("RSS base {base} kB, peak {peak} kB, grew {grew} kB (bound {bound_kb} kB)");
        assert!(grew < bound_kb, "RSS grew {grew} kB, over {bound_kb} kB");
        drop(slow);
    });
}

/// The close frame a client gets after sending `message`, waiting at most 5 s; `None` if
/// the connection ended without one.
async fn close_after(ws: &mut Ws, message: Message) -> Option<(u16, String)> {
    use futures_util::StreamExt;
    // The server may close before the whole message is written: a failed send is seen as
    // the missing close frame below.
    let _ = ws.send(message).await;
    let deadline = tokio::time::Instant::now() + Duration::from_secs(5);
    loop {
        match tokio::time::timeout_at(deadline, ws.next()).await {
            Err(_) => panic!("no close frame nor end within 5 s"),
            Ok(Some(Ok(Message::Close(frame)))) => {
                return frame.map(|f| (u16::from(f.code), f.reason.as_str().to_owned()));
            }
            Ok(Some(Ok(_))) => {}
            Ok(None | Some(Err(_))) => return None,
        }
    }
}

// Issue 34: a message over 64 KiB dropped the connection with neither a close frame nor a
// reason. It is now closed with 1009 (Message Too Big, RFC 6455 §7.4.1) and the limit said,
// for a binary message (an input) and a text one (a subscribe) alike; the server goes on.
#[test]
fn a_message_over_64_kib_is_closed_with_1009_and_the_limit() {
    let server = serve(&["--paused"]);
    runtime().block_on(async {
        let binary = {
            // An input on channel 5, 70 KiB in all.
            let mut data = vec![1u8];
            data.extend_from_slice(&5u32.to_le_bytes());
            data.resize(70 * 1024, b' ');
            Message::binary(data)
        };
        let text = {
            let mut subscribe = String::from(r#"{"op":"subscribe","subscriptions":[]}"#);
            subscribe.push_str(&" ".repeat(70 * 1024));
            Message::text(subscribe)
        };
        for message in [binary, text] {
            let (mut ws, _) = open(&server, "foxglove.websocket.v1").await;
            let (code, reason) = close_after(&mut ws, message)
                .await
                .expect("a close frame, not a dropped connection");
            assert_eq!(code, 1009, "{reason}");
            assert!(reason.contains("message over 64 KiB"), "{reason}");
        }
        // The server still serves.
        let (mut ws, _) = connect(&server.url, "foxglove.websocket.v1").await.unwrap();
        assert_eq!(next_json(&mut ws).await["op"], "serverInfo");
    });
}

// The 65th client was sent a status and dropped, with no close frame. It is now closed with
// 1013 (Try Again Later, RFC 6455 §7.4.1) and the cap said; one leaving makes room.
#[test]
fn the_65th_client_is_told_too_many_and_closed_with_1013() {
    use futures_util::StreamExt;
    let server = serve(&["--paused"]);
    runtime().block_on(async {
        let mut admitted = Vec::new();
        for _ in 0..64 {
            admitted.push(open(&server, "foxglove.websocket.v1").await.0);
        }
        let (mut refused, _) = connect(&server.url, "foxglove.websocket.v1").await.unwrap();
        let (level, text) = next_status(&mut refused).await;
        assert_eq!((level, text.as_str()), (2, "too many clients"));
        let close = tokio::time::timeout(Duration::from_secs(5), refused.next())
            .await
            .expect("a close frame within 5 s");
        let Some(Ok(Message::Close(Some(frame)))) = close else {
            panic!("a close frame, not {close:?}");
        };
        assert_eq!(u16::from(frame.code), 1013, "{frame:?}");
        assert!(frame.reason.contains("at most 64"), "{frame:?}");
        // One leaves: a new client gets in (once the server has seen it go).
        drop(admitted.pop());
        let deadline = Instant::now() + Duration::from_secs(5);
        loop {
            let (mut ws, _) = connect(&server.url, "foxglove.websocket.v1").await.unwrap();
            if any_json(&mut ws).await["op"] == "serverInfo" {
                break;
            }
            assert!(Instant::now() < deadline, "no room 5 s after a client left");
            tokio::time::sleep(Duration::from_millis(50)).await;
        }
    });
}
