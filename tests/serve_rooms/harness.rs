//! The rooms' loopback harness (`serve_rooms.rs`): a server of the test game's rooms on a
//! free port, a client's steps (enter a room, wait for a state, within 10 s), and a room's
//! recording read back and replayed.

use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use ricochet_serve::{Listener, RoomOptions, ServedRooms};
use serde_json::Value;

use super::game::{Maker, new_game};
use crate::serve_client::*;

/// A rooms server on a free loopback port, stopped (and its result kept) when asked.
pub(super) struct Rooms {
    pub(super) base: String,
    stop: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<ServedRooms>>,
}

impl Rooms {
    pub(super) fn start(options: RoomOptions) -> Rooms {
        let listener = Listener::bind("127.0.0.1:0".parse().unwrap()).unwrap();
        let base = format!("ws://{}", listener.local_addr());
        let stop = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&stop);
        let thread = std::thread::spawn(move || {
            ricochet_serve::serve_rooms(listener, Maker, &options, &flag).unwrap()
        });
        Rooms {
            base,
            stop,
            thread: Some(thread),
        }
    }

    pub(super) fn url(&self, room: &str) -> String {
        format!("{}/rooms/{room}", self.base)
    }

    pub(super) fn stop(mut self) -> ServedRooms {
        self.stop.store(true, Ordering::SeqCst);
        self.thread.take().unwrap().join().unwrap()
    }
}

impl Drop for Rooms {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::SeqCst);
    }
}

pub(super) fn quiet() -> RoomOptions {
    RoomOptions {
        note: Arc::new(|_: &str| {}),
        threads: 2,
        ..RoomOptions::default()
    }
}

/// Connects to a room: the socket, its channels and its services.
pub(super) async fn enter(url: &str) -> (Ws, Value, Value) {
    let (mut ws, _) = connect(url, "foxglove.websocket.v1").await.unwrap();
    let (mut channels, mut services) = (Value::Null, Value::Null);
    while channels.is_null() || services.is_null() {
        let v = any_json(&mut ws).await;
        match v["op"].as_str() {
            Some("advertise") => channels = v,
            Some("advertiseServices") => services = v,
            _ => {}
        }
    }
    (ws, channels, services)
}

/// The next `/game` state on subscription `sub` (JSON).
pub(super) async fn next_game(ws: &mut Ws, sub: u32) -> Value {
    loop {
        let (s, _, payload) = next_data(ws).await;
        if s == sub {
            return serde_json::from_slice(&payload).unwrap();
        }
    }
}

/// Waits (at most 10 s) until `/game` shows `pushes` (on subscription 1).
pub(super) async fn until_pushes(ws: &mut Ws, pushes: u64) -> Value {
    within(async {
        loop {
            let game = next_game(ws, 1).await;
            if game["pushes"] == pushes {
                return game;
            }
        }
    })
    .await
}

/// `f`'s answer, which must come within 10 s (data keeps coming, so a wait for one kind
/// of message is bounded as a whole).
pub(super) async fn within<T>(f: impl std::future::Future<Output = T>) -> T {
    tokio::time::timeout(Duration::from_secs(10), f)
        .await
        .expect("within 10 s")
}

/// The next status message (level, text), within 10 s.
pub(super) async fn status_within(ws: &mut Ws) -> (u64, String) {
    within(next_status(ws)).await
}

/// A log's `/input` messages, as JSON.
pub(super) fn commands(log: &Path) -> Vec<Value> {
    let bytes = std::fs::read(log).unwrap();
    mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(Result::unwrap)
        .filter(|m| m.channel.topic == "/input")
        .map(|m| serde_json::from_slice(&m.data).unwrap())
        .collect()
}

/// Replays `log` with a new game for `room` and says whether the replay is the same
/// bytes; also the frames it holds.
pub(super) fn replays_byte_for_byte(log: &Path, room: &str, dir: &Path) -> (bool, u64) {
    let recorded = ricochet_log::LogFile::open(log).unwrap();
    let again = dir.join(format!("{room}.again.mcap"));
    let out = ricochet_record::log_writer(&again).unwrap();
    let (sim, game) = new_game(room);
    let replayed = ricochet_record::replay::replay(&recorded, sim, game, out).unwrap();
    replayed.sink.finish().unwrap();
    let same = std::fs::read(log).unwrap() == std::fs::read(&again).unwrap();
    (same, replayed.frames)
}
