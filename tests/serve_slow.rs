//! A client that reads slowly gets the latest `/scene`, not a backlog (issue #37, item 2):
//! `ricochet serve` of a 2,000-body level at real speed, one client that stops reading for
//! 2 s, and one that reads all along; and a client that reads as fast as it can is sent
//! whole states no faster than the server's pace for them (`STATE_RATE`).

use std::cell::Cell;
use std::time::{Duration, Instant};

use prost::Message as _;
use ricochet_log::messages::ricochet::Stats;
use tokio_tungstenite::MaybeTlsStream;
use tokio_tungstenite::tungstenite::client::IntoClientRequest;

use crate::serve_client::*;

/// One frame at 60 Hz, ns (what `/stats` and `/scene` are stamped with).
const FRAME_NS: u64 = 16_666_667;

/// The most the kernel may hold of a connection's sent bytes, by `tcp_wmem`'s maximum (the
/// server does not set its own): what a paused client reads first, older than anything the
/// server can replace.
fn kernel_send_buffer() -> usize {
    std::fs::read_to_string("/proc/sys/net/ipv4/tcp_wmem")
        .ok()
        .and_then(|s| s.split_whitespace().nth(2)?.parse().ok())
        .unwrap_or(4 << 20)
}

/// The receive buffer the slow client asks for, bytes (the kernel doubles it).
const RECEIVE_BUFFER: u32 = 16 << 10;

/// A client whose socket buffers little ([`RECEIVE_BUFFER`]), so what it reads after a
/// pause is what the server and its kernel held for it.
async fn connect_small(url: &str) -> Ws {
    let address = url.trim_start_matches("ws://");
    let socket = tokio::net::TcpSocket::new_v4().unwrap();
    socket.set_recv_buffer_size(RECEIVE_BUFFER).unwrap();
    let stream = socket.connect(address.parse().unwrap()).await.unwrap();
    let mut request = url.into_client_request().unwrap();
    request.headers_mut().insert(
        "Sec-WebSocket-Protocol",
        "foxglove.websocket.v1".parse().unwrap(),
    );
    let (ws, _) = tokio_tungstenite::client_async(request, MaybeTlsStream::Plain(stream))
        .await
        .unwrap();
    ws
}

#[test]
fn a_slow_client_gets_the_latest_scene_and_a_reading_one_every_frame() {
    let dir = tempfile::tempdir().unwrap();
    let level = level_2000(dir.path());
    let server = serve(&[level.to_str().unwrap(), "--speed", "1"]);
    runtime().block_on(async {
        let mut slow = connect_small(&server.url).await;
        let _ = next_json(&mut slow).await;
        let channels = next_json(&mut slow).await;
        subscribe_to(&mut slow, &channels, "/scene", 1).await;
        subscribe_to(&mut slow, &channels, "/stats", 2).await;
        let (mut good, _) = connect(&server.url, "foxglove.websocket.v1").await.unwrap();
        let _ = next_json(&mut good).await;
        let channels = next_json(&mut good).await;
        subscribe_to(&mut good, &channels, "/stats", 1).await;
        // The newest frame's time the reading client has seen.
        let newest = Cell::new(0u64);
        let done = Cell::new(false);
        let reading = async {
            let mut frames = Vec::new();
            while !done.get() {
                let (_, time, payload) = next_data(&mut good).await;
                newest.set(time);
                frames.push(Stats::decode(payload.as_slice()).unwrap().frame);
            }
            frames
        };
        let pausing = async {
            tokio::time::sleep(Duration::from_secs(2)).await;
            let paused_at = newest.get();
            // Read until a scene stamped at or after the pause's end: the scenes before it
            // are the backlog; the first scene read is what the client is shown first.
            let mut scenes = Vec::new();
            let until = Instant::now() + Duration::from_secs(8);
            while Instant::now() < until {
                let (sub, time, payload) = next_data(&mut slow).await;
                if sub == 1 {
                    scenes.push((time, payload.len()));
                    if time >= paused_at {
                        break;
                    }
                }
            }
            done.set(true);
            (paused_at, scenes)
        };
        let (frames, (paused_at, scenes)) = tokio::join!(reading, pausing);
        assert!(frames.len() > 30, "{} frames read", frames.len());
        assert!(
            frames.windows(2).all(|w| w[1] == w[0] + 1),
            "the reading client missed frames"
        );
        // Scenes older than the pause's end, read after it: only what the kernel held
        // (bounded by its buffers), and at most one the server queued; with a backlog in the
        // server's queue they would be its budget more (8 MiB, about 27 such scenes).
        let (last, _) = *scenes.last().expect("a scene after the pause");
        assert!(
            last + 5 * FRAME_NS >= paused_at,
            "no recent scene after the pause: {scenes:?}, the newest frame at {paused_at} ns"
        );
        let largest = scenes.iter().map(|&(_, len)| len).max().unwrap_or(0);
        let old: usize = scenes[..scenes.len() - 1].iter().map(|&(_, len)| len).sum();
        let kernel = kernel_send_buffer() + 2 * RECEIVE_BUFFER as usize;
        assert!(
            old <= kernel + 2 * largest,
            "{} bytes in {} older scenes read before the latest, beyond the kernel's {kernel} \
             and two scenes of {largest}: {scenes:?}",
            old,
            scenes.len() - 1
        );
    });
}

/// The 2,000-body level of `scripts/asteroids_level.py`, in `dir`.
fn level_2000(dir: &std::path::Path) -> std::path::PathBuf {
    let level = dir.join("level.toml");
    let out = std::process::Command::new("python3")
        .arg(crate::util::root().join("scripts/asteroids_level.py"))
        .arg("2000")
        .output()
        .unwrap();
    assert!(out.status.success());
    std::fs::write(&level, &out.stdout).unwrap();
    level
}

/// A viewer that reads every message at once is not sent every scene: after writing a
/// whole state of `n` bytes, the server waits `n / STATE_RATE` before that channel's next
/// (newer ones replace it meanwhile). Here the level runs at 4 times real speed, 240
/// scenes of about 0.3 MB a second (72 MB/s, far past the pace), and the bound
/// checked holds on any machine however loaded: each scene is written no sooner than the
/// bytes of those before it at the pace, counted from the subscription, so the bytes of
/// all the scenes read but the last are at most `STATE_RATE` times the time from the
/// subscription to the last one's arrival. Without the pace, a reading client was sent
/// every scene the loop made.
#[test]
fn a_reading_client_is_sent_whole_states_no_faster_than_their_pace() {
    let dir = tempfile::tempdir().unwrap();
    let level = level_2000(dir.path());
    let server = serve(&[level.to_str().unwrap(), "--speed", "4"]);
    runtime().block_on(async {
        let (mut ws, _) = connect(&server.url, "foxglove.websocket.v1").await.unwrap();
        let _ = next_json(&mut ws).await;
        let channels = next_json(&mut ws).await;
        let subscribed = Instant::now();
        subscribe_to(&mut ws, &channels, "/scene", 1).await;
        // (arrival, bytes as sent: the payload and the 13 bytes of the message's header)
        let mut scenes = Vec::new();
        let until = subscribed + Duration::from_secs(3);
        while Instant::now() < until {
            let (sub, _, payload) = next_data(&mut ws).await;
            if sub == 1 {
                scenes.push((Instant::now(), payload.len() + 13));
            }
        }
        assert!(scenes.len() >= 2, "{} scenes in 3 s", scenes.len());
        let (last, _) = *scenes.last().unwrap();
        let before_last: usize = scenes[..scenes.len() - 1].iter().map(|&(_, n)| n).sum();
        let allowed = ricochet_serve::STATE_RATE * (last - subscribed).as_secs_f64();
        assert!(
            before_last as f64 <= allowed,
            "{} scenes read in {:.3} s, {before_last} bytes before the last, more than the \
             {allowed:.0} of {} bytes a second",
            scenes.len(),
            (last - subscribed).as_secs_f64(),
            ricochet_serve::STATE_RATE
        );
    });
}
