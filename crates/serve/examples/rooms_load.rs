//! The load of BENCHMARKS.md's "Rooms": R rooms of about 100 bodies each (96 balls in a
//! walled arena, and a ball per player), 4 players a room each pushing its ball 10 times a
//! second, for S seconds, on loopback in this one process (the server's room workers on a
//! thread per core, the load client on one thread). Prints the server's frame lateness
//! (how late each room's frame started against its real-time schedule) and the memory per
//! room, and the CPU time of each side (room workers, WebSocket thread, load client).
//!
//! ```text
//! cargo run --release -p ricochet-serve --example rooms_load -- 200 10
//! ```

use std::collections::BTreeMap;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use futures_util::{SinkExt, StreamExt};
use ricochet_serve::{Listener, RoomMaker, RoomOptions};
use ricochet_sim::prelude::*;
use ricochet_sim::{Game, Player};
use tokio_tungstenite::tungstenite::Message;
use tokio_tungstenite::tungstenite::client::IntoClientRequest;
use tokio_tungstenite::tungstenite::protocol::WebSocketConfig;

/// A ball per player, pushed by `{"push": [vx, vy]}`; the state counts the pushes.
#[derive(Default)]
struct Balls {
    balls: BTreeMap<Player, Entity>,
    pushes: u64,
}

#[derive(serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
struct Push {
    push: [f64; 2],
}

impl Game for Balls {
    type Input = Push;
    type State = u64;

    fn name(&self) -> &str {
        "balls"
    }

    fn join(&mut self, sim: &mut Simulation, player: Player, _name: &str) -> Result<(), String> {
        let ball = sim.spawn(&BodyDef {
            position: Vec2::new(2.0 * f64::from(player.0), 18.0),
            ..BodyDef::default()
        });
        self.balls.insert(player, ball);
        Ok(())
    }

    fn leave(&mut self, sim: &mut Simulation, player: Player) {
        if let Some(ball) = self.balls.remove(&player) {
            let _ = sim.despawn(ball);
        }
    }

    fn input(&mut self, sim: &mut Simulation, player: Player, input: Push) -> Result<(), String> {
        let ball = *self.balls.get(&player).ok_or("no ball")?;
        sim.set_velocity(ball, Vec2::new(input.push[0], input.push[1]))
            .map_err(|e| e.to_string())?;
        self.pushes += 1;
        Ok(())
    }

    fn state(&self) -> Option<&u64> {
        Some(&self.pushes)
    }
}

struct Crowded;

impl RoomMaker for Crowded {
    type Game = Balls;

    fn make(&self, _room: &str) -> Result<(Simulation, Balls), String> {
        let mut sim = Simulation::from_def(WorldDef {
            gravity: Vec2::ZERO,
            ..WorldDef::default()
        })
        .map_err(|e| e.to_string())?;
        for (x, y, hx, hy) in [
            (0.0, -21.0, 21.0, 1.0),
            (0.0, 21.0, 21.0, 1.0),
            (-21.0, 0.0, 1.0, 21.0),
            (21.0, 0.0, 1.0, 21.0),
        ] {
            sim.spawn(&BodyDef {
                kind: BodyKind::Static,
                shape: Shape::aabb(Vec2::new(hx, hy)).map_err(|e| e.to_string())?,
                position: Vec2::new(x, y),
                ..BodyDef::default()
            });
        }
        for i in 0..96u32 {
            let (col, row) = (f64::from(i % 12), f64::from(i / 12));
            sim.spawn(&BodyDef {
                shape: Shape::circle(0.4).map_err(|e| e.to_string())?,
                position: Vec2::new(-16.5 + 3.0 * col, -12.0 + 3.0 * row),
                velocity: Vec2::new(f64::from(i % 7) - 3.0, f64::from(i % 5) - 2.0),
                ..BodyDef::default()
            });
        }
        Ok((sim, Balls::default()))
    }
}

/// CPU seconds (user + system) of this process's threads so far, by thread name, from
/// /proc (Linux; empty elsewhere): the room workers (`rooms-N`), the WebSocket thread
/// (`serve`) and the load client (the main thread, `rooms_load`).
fn cpu_by_thread() -> BTreeMap<String, f64> {
    let mut by = BTreeMap::new();
    let Ok(tasks) = std::fs::read_dir("/proc/self/task") else {
        return by;
    };
    // Clock ticks a second: 100 on Linux's common configurations.
    let hz = 100.0;
    for task in tasks.flatten() {
        let Ok(stat) = std::fs::read_to_string(task.path().join("stat")) else {
            continue;
        };
        // `pid (comm) state ...`: the fields after the name's closing parenthesis.
        let (Some(open), Some(close)) = (stat.find('('), stat.rfind(')')) else {
            continue;
        };
        let comm = stat[open + 1..close].to_owned();
        let fields: Vec<&str> = stat[close + 2..].split_whitespace().collect();
        let ticks = |i: usize| {
            fields
                .get(i)
                .and_then(|f| f.parse::<f64>().ok())
                .unwrap_or(0.0)
        };
        // utime and stime are fields 14 and 15, 12 and 13 after the state (field 3).
        let name = if comm.starts_with("rooms-") {
            "room workers".to_owned()
        } else {
            comm
        };
        *by.entry(name).or_insert(0.0) += (ticks(11) + ticks(12)) / hz;
    }
    by
}

/// The process's resident memory, bytes (Linux; 0 elsewhere).
fn rss() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find(|l| l.starts_with("VmRSS:"))
        .and_then(|l| l.split_whitespace().nth(1)?.parse::<u64>().ok())
        .map_or(0, |kib| kib * 1024)
}

type Ws =
    tokio_tungstenite::WebSocketStream<tokio_tungstenite::MaybeTlsStream<tokio::net::TcpStream>>;

/// The next text message as JSON.
async fn next_json(ws: &mut Ws) -> serde_json::Value {
    loop {
        let m = tokio::time::timeout(Duration::from_secs(10), ws.next())
            .await
            .expect("a message within 10 s")
            .expect("open")
            .expect("readable");
        if let Message::Text(t) = m {
            return serde_json::from_str(t.as_str()).expect("JSON");
        }
    }
}

/// Connects to a room, joins it as `name`, subscribes to `/game` and advertises `/input`
/// (channel 5).
async fn player(url: &str, name: &str) -> Ws {
    let mut request = url.into_client_request().expect("a URL");
    request.headers_mut().insert(
        "Sec-WebSocket-Protocol",
        "foxglove.websocket.v1".parse().expect("a header"),
    );
    // A small read buffer, as the server's: tungstenite's default (128 KiB) is zeroed
    // before every read, which would make this client, sharing the server's cores, the cost.
    let config = WebSocketConfig::default().read_buffer_size(4096);
    let (mut ws, _) = tokio_tungstenite::connect_async_with_config(request, Some(config), false)
        .await
        .expect("connected");
    let mut game = None;
    loop {
        let v = next_json(&mut ws).await;
        if v["op"] == "advertise" {
            game = v["channels"]
                .as_array()
                .and_then(|c| c.iter().find(|c| c["topic"] == "/game"))
                .map(|c| c["id"].clone());
        }
        if v["op"] == "advertiseServices" {
            break;
        }
    }
    let mut call = vec![2u8];
    call.extend_from_slice(&1u32.to_le_bytes()); // /join
    call.extend_from_slice(&1u32.to_le_bytes());
    call.extend_from_slice(&4u32.to_le_bytes());
    call.extend_from_slice(b"json");
    call.extend_from_slice(format!(r#"{{"name": "{name}"}}"#).as_bytes());
    ws.send(Message::binary(call)).await.expect("sent");
    let subscribe =
        serde_json::json!({"op": "subscribe", "subscriptions": [{"id": 1, "channelId": game}]});
    ws.send(Message::text(subscribe.to_string()))
        .await
        .expect("sent");
    let advertise = serde_json::json!({"op": "advertise", "channels": [
        {"id": 5, "topic": "/input", "encoding": "json", "schemaName": "push"}]});
    ws.send(Message::text(advertise.to_string()))
        .await
        .expect("sent");
    ws
}

/// The most rooms: 8,000 connections (both ends in this process, 2 descriptors each:
/// 16,000 of a 20,000 open-file limit).
const MAX_ROOMS: usize = 2000;

fn main() {
    let mut args = std::env::args().skip(1);
    let rooms: usize = args.next().map_or(50, |a| a.parse().expect("ROOMS"));
    let seconds: u64 = args.next().map_or(10, |a| a.parse().expect("SECONDS"));
    assert!(
        (1..=MAX_ROOMS).contains(&rooms) && (1..=120).contains(&seconds),
        "1 to {MAX_ROOMS} rooms, 1 to 120 s"
    );
    let listener = Listener::bind("127.0.0.1:0".parse().expect("an address")).expect("bound");
    let base = format!("ws://{}", listener.local_addr());
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    // The server's default cap, 1,000 clients, is 250 rooms of 4: raised to the rooms asked.
    let options = RoomOptions {
        max_clients: 4 * rooms,
        max_rooms: rooms,
        note: Arc::new(|_: &str| {}),
        ..RoomOptions::default()
    };
    let threads = options.threads;
    let before = rss();
    let server = std::thread::spawn(move || {
        ricochet_serve::serve_rooms(listener, Crowded, &options, &flag).expect("served")
    });
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .expect("a runtime");
    let (pushes, after, cpu) = runtime.block_on(async {
        let mut sinks = Vec::new();
        let mut readers = Vec::new();
        for r in 0..rooms {
            for p in 0..4 {
                let ws = player(&format!("{base}/rooms/r{r}"), &format!("p{p}")).await;
                let (sink, mut stream) = ws.split();
                // Every client reads all it is sent, as a game's client would.
                readers.push(tokio::spawn(async move {
                    while let Some(Ok(_)) = stream.next().await {}
                }));
                sinks.push(sink);
            }
        }
        let mut tick = tokio::time::interval(Duration::from_millis(100));
        let mut pushes = 0u64;
        for k in 0..seconds * 10 {
            tick.tick().await;
            for sink in &mut sinks {
                let mut data = vec![1u8];
                data.extend_from_slice(&5u32.to_le_bytes());
                data.extend_from_slice(format!(r#"{{"push": [{}, 1]}}"#, k % 5).as_bytes());
                sink.send(Message::binary(data)).await.expect("sent");
                pushes += 1;
            }
        }
        let after = rss();
        let cpu = cpu_by_thread();
        for r in readers {
            r.abort();
        }
        (pushes, after, cpu)
    });
    stop.store(true, Ordering::SeqCst);
    let served = server.join().expect("the server thread");
    let per_room = served.frames as f64 / rooms as f64;
    println!(
        "{rooms} rooms, {threads} worker threads, {seconds} s of inputs: {pushes} inputs sent; \
         {} frames ({per_room:.0} a room, from its making to the stop; {} rooms failed); frame \
         start late: p50 {:.3} ms, p99 {:.3} ms, max {:.3} ms (100 ms: 100 ms or more); RSS \
         {:.1} MiB before, {:.1} MiB with the rooms: {:.2} MiB a room (the server's room and \
         its 4 clients' both ends)",
        served.frames,
        served.failed,
        served.late_ms[0],
        served.late_ms[1],
        served.late_ms[2],
        before as f64 / 1_048_576.0,
        after as f64 / 1_048_576.0,
        after.saturating_sub(before) as f64 / 1_048_576.0 / rooms as f64,
    );
    let cpu: Vec<String> = cpu.iter().map(|(t, s)| format!("{t} {s:.2} s")).collect();
    println!(
        "CPU time by thread, connecting included: {}",
        cpu.join(", ")
    );
}
