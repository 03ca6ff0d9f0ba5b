//! One room: its game session (simulation, game, recorder), its clients' hub, and the
//! players its clients joined as. A room worker (`rooms.rs`) calls it between frames to
//! take its clients' calls and inputs, and steps it when a frame is due.
//!
//! Everything a room does with game code (join, leave, input, step) runs inside
//! `catch_unwind`: a panic closes this room only (its recording finished up to its last
//! good frame, its clients told why), never the worker or another room.

use std::collections::BTreeMap;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use ricochet_record::channels::Channels;
use ricochet_record::session::{GameSession, StepError};
use ricochet_sim::{Game, Player};
use serde::Deserialize;
use tokio_tungstenite::tungstenite::Message;

use crate::hub::{Hub, LATEST};
use crate::protocol::{self, Service, ServiceSchema};
use crate::sink::ServeSink;

/// A room's services, ids 1 to 3.
pub const JOIN: u32 = 1;
/// `/leave`.
pub const LEAVE: u32 = 2;
/// `/rooms`.
pub const ROOMS: u32 = 3;

/// What a room shows of itself to `/rooms`, updated as it steps (read without its lock).
#[derive(Default)]
pub struct Stats {
    /// The frame it steps next.
    pub frame: AtomicU64,
    /// Players in it now.
    pub players: AtomicU64,
}

/// Why a room closed (its clients are told; a failure is also noted).
pub enum Closing {
    /// It had no client for the grace period, or the server stopped: no failure.
    Done(String),
    /// Its game panicked, its simulation overflowed, or its recording failed.
    Failed(String),
}

/// A running room.
pub struct Room<G: Game> {
    pub name: String,
    pub hub: Hub,
    pub stats: Arc<Stats>,
    session: Option<GameSession<G, ServeSink>>,
    /// Client → the player it joined as.
    players: BTreeMap<u64, Player>,
    /// Frame `n` is due at `start + n * dt`.
    start: Instant,
    dt: Duration,
    /// When its last client left (or when it was made, with none).
    pub empty_since: Option<Instant>,
    /// The game's input schema, for `/join`'s answer.
    input_schema: Arc<str>,
    /// Where its recording goes, for messages.
    pub recording: Option<PathBuf>,
    /// When its worker last took its clients' calls.
    looked: Instant,
}

/// The room services' list (advertised to a room's clients).
pub fn services() -> Vec<Service> {
    let join_req = r#"{"type": "object", "properties": {"name": {"type": "string", "minLength": 1, "maxLength": 64}}, "required": ["name"]}"#;
    let join_resp = r#"{"type": "object", "properties": {"player": {"type": "integer"}, "input_schema": {"type": "object"}}}"#;
    let leave_resp = r#"{"type": "object", "properties": {"left": {"type": "integer"}}}"#;
    let rooms_req =
        r#"{"type": "object", "properties": {"create": {"type": "string", "maxLength": 64}}}"#;
    let rooms_resp = r#"{"type": "object", "properties": {"rooms": {"type": "array", "items": {"type": "object", "properties": {"name": {"type": "string"}, "frame": {"type": "integer"}, "players": {"type": "integer"}, "clients": {"type": "integer"}}}}}}"#;
    let empty = r#"{"type": "object", "properties": {}}"#;
    [
        (JOIN, "/join", join_req, join_resp),
        (LEAVE, "/leave", empty, leave_resp),
        (ROOMS, "/rooms", rooms_req, rooms_resp),
    ]
    .into_iter()
    .map(|(id, name, request, response)| Service {
        id,
        name: name.to_owned(),
        kind: format!("ricochet{name}"),
        request: ServiceSchema::json(&format!("ricochet{name}.Request"), request),
        response: ServiceSchema::json(&format!("ricochet{name}.Response"), response),
    })
    .collect()
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JoinRequest {
    name: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Empty {}

/// `/rooms`' request.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RoomsRequest {
    /// A room to create (if it has none of that name).
    #[serde(default)]
    pub create: Option<String>,
}

/// The request body of a call (`{}` when empty).
pub fn body(payload: &[u8]) -> &[u8] {
    if payload.is_empty() { b"{}" } else { payload }
}

/// A panic's message.
fn panic_text(payload: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_owned()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "a panic".to_owned()
    }
}

impl<G: Game> Room<G> {
    /// A room `name` running `session`, stepping every `dt` from now.
    pub fn new(
        name: String,
        hub: Hub,
        session: GameSession<G, ServeSink>,
        dt: Duration,
        input_schema: Arc<str>,
        recording: Option<PathBuf>,
    ) -> Room<G> {
        Room {
            name,
            hub,
            stats: Arc::new(Stats::default()),
            session: Some(session),
            players: BTreeMap::new(),
            start: Instant::now(),
            dt,
            empty_since: Some(Instant::now()),
            input_schema,
            recording,
            looked: Instant::now(),
        }
    }

    /// Whether its worker should look at it now: its frame is due, or `poll` has passed
    /// since it was last looked at (then it is marked looked at).
    pub fn worth_a_look(&mut self, now: Instant, poll: Duration) -> bool {
        let due = self.due() <= now;
        if due || now.saturating_duration_since(self.looked) >= poll {
            self.looked = now;
            return true;
        }
        false
    }

    /// When its next frame is due.
    pub fn due(&self) -> Instant {
        let next = self.session.as_ref().map_or(0, GameSession::next_frame);
        let n = u32::try_from(next).unwrap_or(u32::MAX);
        self.start
            .checked_add(self.dt.saturating_mul(n))
            .unwrap_or_else(|| self.start + Duration::from_secs(1 << 40))
    }

    /// Runs `f` on the session, a panic in it caught: `Err` names what panicked.
    fn guarded<T>(
        &mut self,
        what: &str,
        f: impl FnOnce(&mut GameSession<G, ServeSink>) -> T,
    ) -> Result<T, Closing> {
        let Some(session) = self.session.as_mut() else {
            return Err(Closing::Failed("closed".to_owned()));
        };
        let frame = session.next_frame();
        catch_unwind(AssertUnwindSafe(|| f(session))).map_err(|payload| {
            Closing::Failed(format!(
                "room {}: its game panicked in {what} at frame {frame}: {}",
                self.name,
                panic_text(payload.as_ref())
            ))
        })
    }

    /// Takes the clients' calls (but `/rooms`, answered by `rooms`), inputs and leaves, in
    /// that order; `Err` when the room must close.
    pub fn commands(
        &mut self,
        rooms: &dyn Fn(&[u8]) -> Result<String, String>,
    ) -> Result<(), Closing> {
        let (calls, inputs, left) = {
            let mut s = self.hub.lock();
            // A room has no timeline and answers no clicks: what came is told so, not kept.
            let mut refused: Vec<u64> = s.playback.drain(..).map(|(c, _)| c).collect();
            refused.extend(s.clicks.drain(..).map(|(c, _)| c));
            for client in refused {
                s.tell(
                    client,
                    1,
                    "a room has no timeline and answers no clicked points",
                );
            }
            (
                std::mem::take(&mut s.calls),
                std::mem::take(&mut s.inputs),
                std::mem::take(&mut s.left),
            )
        };
        for (client, call) in calls {
            let result = match call.service {
                JOIN => self.join(client, &call.payload)?,
                LEAVE => match serde_json::from_slice::<Empty>(body(&call.payload)) {
                    Err(e) => Err(format!("bad request: {e}")),
                    Ok(Empty {}) => match self.players.remove(&client) {
                        None => Err("this client has not joined".to_owned()),
                        Some(p) => self.leave(p)?.map(|()| format!(r#"{{"left": {}}}"#, p.0)),
                    },
                },
                ROOMS => rooms(&call.payload),
                other => Err(format!("no service {other}")),
            };
            self.hub
                .lock()
                .answer(client, call.service, call.call, result);
        }
        for (client, text) in inputs {
            let player = self.players.get(&client).copied().unwrap_or(Player::HOST);
            let verdict = self
                .guarded("input", |s| s.input_text(player, &text))?
                .map_err(|e| Closing::Failed(format!("room {}: recording: {e}", self.name)))?;
            if let Err(why) = verdict {
                self.hub
                    .lock()
                    .tell(client, 2, &format!("input refused: {why}"));
            }
        }
        for client in left {
            if let Some(p) = self.players.remove(&client) {
                let _ = self.leave(p)?;
            }
        }
        self.stats
            .players
            .store(self.players.len() as u64, Ordering::Relaxed);
        Ok(())
    }

    fn join(&mut self, client: u64, payload: &[u8]) -> Result<Result<String, String>, Closing> {
        let request: JoinRequest = match serde_json::from_slice(body(payload)) {
            Ok(r) => r,
            Err(e) => return Ok(Err(format!("bad request: {e}"))),
        };
        if let Some(p) = self.players.get(&client) {
            return Ok(Err(format!("this client already joined, as {p}")));
        }
        let has_players = self
            .session
            .as_ref()
            .is_some_and(|s| s.run().game().has_players());
        if !has_players {
            // Refused before the session sees it: a game without players records no joins.
            return Ok(Err(
                "this game has no players: send inputs without joining".to_owned()
            ));
        }
        let verdict = self
            .guarded("join", |s| s.join(&request.name))?
            .map_err(|e| Closing::Failed(format!("room {}: recording: {e}", self.name)))?;
        Ok(match verdict {
            Ok(player) => {
                self.players.insert(client, player);
                let schema: serde_json::Value = serde_json::from_str(&self.input_schema)
                    .unwrap_or_else(|_| serde_json::json!({"type": "object"}));
                Ok(serde_json::json!({"player": player.0, "input_schema": schema}).to_string())
            }
            Err((_, why)) => Err(why),
        })
    }

    fn leave(&mut self, player: Player) -> Result<Result<(), String>, Closing> {
        self.guarded("leave", |s| s.leave(player))?
            .map_err(|e| Closing::Failed(format!("room {}: recording: {e}", self.name)))
    }

    /// Steps one frame, telling the clients its time first.
    pub fn step(&mut self) -> Result<(), Closing> {
        let Some(session) = self.session.as_ref() else {
            return Err(Closing::Failed("closed".to_owned()));
        };
        let t = session.next_frame().saturating_mul(session.dt_ns());
        if session.next_frame() > ricochet_sim::MAX_FRAMES {
            return Err(Closing::Done(format!(
                "room {}: its last frame, {}, was stepped",
                self.name,
                ricochet_sim::MAX_FRAMES
            )));
        }
        let wanted = {
            let mut s = self.hub.lock();
            s.broadcast(&Message::binary(protocol::time(t)));
            // A room nobody records builds only the messages some client subscribes to:
            // building every channel's for nobody was most of a room's frame
            // (BENCHMARKS.md, "Rooms"). A recorded room builds them all, as before. And it
            // draws `/scene` only in the frames some client is due one, as `serve` does
            // (`Hub::scene_due`).
            self.recording.is_none().then(|| {
                let channels = Channels {
                    scene: LATEST.iter().any(|topic| s.watched(topic)),
                    bodies: s.watched("/bodies"),
                    contacts: s.watched("/contacts"),
                    stats: s.watched("/stats"),
                    events: s.watched("/events"),
                };
                let draw = s.scene_due(self.dt);
                (channels, draw)
            })
        };
        if let (Some((wanted, draw)), Some(session)) = (wanted, self.session.as_mut()) {
            session.recorder().build_only(wanted);
            session.recorder().draw_moving(draw);
        }
        match self.guarded("a frame", GameSession::step)? {
            Ok(_) => {}
            Err(StepError::Overflow { frame, what }) => {
                return Err(Closing::Failed(format!(
                    "room {}: frame {frame}: {what}; the simulation overflowed",
                    self.name
                )));
            }
            Err(e) => {
                return Err(Closing::Failed(format!(
                    "room {}: recording: {e}",
                    self.name
                )));
            }
        }
        let next = self.session.as_ref().map_or(0, GameSession::next_frame);
        self.stats.frame.store(next, Ordering::Relaxed);
        Ok(())
    }

    /// The frame it steps next.
    pub fn next_frame(&self) -> u64 {
        self.session.as_ref().map_or(0, GameSession::next_frame)
    }

    /// Ends the room: its clients are told `why` and disconnected, its recording finished
    /// (it holds every frame stepped: a frame whose step panicked wrote nothing). Returns
    /// why finishing the recording failed, if it did.
    pub fn close(&mut self, why: &str) -> Option<String> {
        self.hub.lock().close_all(why);
        let session = self.session.take()?;
        // A panic in game code may have left the game in any state, but the recorder and
        // its file are only written between game calls, so the file is whole.
        let sink = catch_unwind(AssertUnwindSafe(|| session.into_sink())).ok()?;
        let (file, _) = sink.file?;
        file.finish().err().map(|e| {
            format!(
                "room {}: finishing its recording {}: {e}",
                self.name,
                self.recording
                    .as_ref()
                    .map_or(String::new(), |p| p.display().to_string())
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use ricochet_sim::prelude::*;

    use super::*;
    use crate::hub::client_queue;
    use crate::queue::ClientQueueReceiver;
    use crate::sink::LiveSink;

    /// A game whose state (on `/game`) counts the frames stepped.
    struct Frames(u64);

    impl Game for Frames {
        type Input = u64;
        type State = u64;

        fn name(&self) -> &str {
            "frames"
        }

        fn input(&mut self, _: &mut Simulation, _: Player, _: u64) -> Result<(), String> {
            Ok(())
        }

        fn after_step(&mut self, _sim: &mut Simulation, _out: &FrameOutput) {
            self.0 += 1;
        }

        fn state(&self) -> Option<&u64> {
            Some(&self.0)
        }
    }

    /// An unrecorded room of a wall and three balls crossing it (so `/scene`, `/bodies`,
    /// `/stats` and `/contacts` change every frame), and a client of it.
    fn room() -> (Room<Frames>, u64, ClientQueueReceiver) {
        let mut sim = Simulation::from_def(WorldDef {
            gravity: Vec2::ZERO,
            ..WorldDef::default()
        })
        .unwrap();
        sim.spawn(&BodyDef {
            kind: BodyKind::Static,
            shape: Shape::aabb(Vec2::new(10.0, 1.0)).unwrap(),
            ..BodyDef::default()
        });
        for i in 0..3u32 {
            sim.spawn(&BodyDef {
                shape: Shape::circle(0.5).unwrap(),
                position: Vec2::new(f64::from(i) * 2.0, 3.0),
                velocity: Vec2::new(0.0, -10.0),
                ..BodyDef::default()
            });
        }
        let hub = Hub::default();
        let sink = ServeSink {
            live: LiveSink::new(hub.clone()),
            file: None,
            muted: false,
        };
        let session = GameSession::start(sim, Frames(0), sink, true).unwrap();
        let dt = Duration::from_millis(16);
        let room = Room::new("r".into(), hub.clone(), session, dt, "{}".into(), None);
        let (queue, rx) = client_queue();
        let (client, _kicked) = hub.lock().connect(queue);
        (room, client, rx)
    }

    fn subscribe(room: &Room<Frames>, client: u64, topic: &str, subscription: u32) {
        let mut s = room.hub.lock();
        let id = s.channels().iter().find(|c| c.topic == topic).unwrap().id;
        s.subscribe(client, subscription, id).unwrap();
    }

    /// The subscription ids of the messages `rx` holds, with their times (ns), in order.
    fn received(rx: &mut ClientQueueReceiver) -> Vec<(u32, u64)> {
        let mut got = Vec::new();
        while let Ok(m) = rx.try_recv() {
            let data = m.into_data();
            if data.first() == Some(&protocol::OP_MESSAGE_DATA) {
                let sub = u32::from_le_bytes(data[1..5].try_into().unwrap());
                let time = u64::from_le_bytes(data[5..13].try_into().unwrap());
                got.push((sub, time));
            }
        }
        got
    }

    #[test]
    fn an_unrecorded_room_builds_no_message_nobody_subscribed_to() {
        let (mut room, client, mut rx) = room();
        subscribe(&room, client, "/game", 7);
        for _ in 0..10 {
            room.step().map_err(|_| "a step failed").unwrap();
        }
        let built = room.session.as_mut().unwrap().recorder().built();
        assert_eq!(
            built, 0,
            "no client watches the scene, bodies, stats or contacts"
        );
        // Its `/game` still came, one a frame: frame n at n × 16 ms.
        let dt_ns = room.session.as_ref().unwrap().dt_ns();
        let game: Vec<(u32, u64)> = (0..10).map(|n| (7, n * dt_ns)).collect();
        assert_eq!(received(&mut rx), game);
    }

    /// Messages the room's recorder built in `n` frames; `read` drains the receiver after
    /// each frame, as a connection writing at once does.
    fn built_in(room: &mut Room<Frames>, n: u64, read: Option<&mut ClientQueueReceiver>) -> u64 {
        let before = room.session.as_mut().unwrap().recorder().built();
        let mut read = read;
        for _ in 0..n {
            room.step().map_err(|_| "a step failed").unwrap();
            if let Some(rx) = read.as_deref_mut() {
                while rx.ready().is_some() {}
            }
        }
        room.session.as_mut().unwrap().recorder().built() - before
    }

    /// Unrecorded, a room draws `/scene` only in the frames its client is due one: every
    /// frame for a client that reads each (the balls move every frame; a scene this small is
    /// due again well within a frame), and once in ten frames for one that never reads (its
    /// queue holds that one, which a newer one would only replace). The first frame after
    /// subscribing sends the scene's channels whole: `/scene`, `/scene/static` and `/tf`
    /// (the wall and the camera's frame do not change after it).
    #[test]
    fn an_unrecorded_room_draws_the_scene_only_when_a_client_is_due_one() {
        let (mut read, client, mut rx) = room();
        subscribe(&read, client, "/scene", 2);
        assert_eq!(
            built_in(&mut read, 10, Some(&mut rx)),
            3 + 9,
            "a client reading each"
        );
        let (mut stuck, client, _rx) = room();
        subscribe(&stuck, client, "/scene", 2);
        assert_eq!(
            built_in(&mut stuck, 10, None),
            3,
            "a client that never reads"
        );
    }

    #[test]
    fn a_worker_looks_at_a_room_when_its_frame_is_due_or_a_poll_after_it_last_did() {
        let (mut room, _, _) = room();
        let poll = Duration::from_millis(5);
        let start = room.start;
        room.looked = start;
        // Frame 0 is due at the start.
        assert!(room.worth_a_look(start, poll));
        room.step().map_err(|_| "a step failed").unwrap();
        // Frame 1 is due 16 ms after the start: 1 ms and 4 ms in, nothing to do.
        assert!(!room.worth_a_look(start + Duration::from_millis(1), poll));
        assert!(!room.worth_a_look(start + Duration::from_millis(4), poll));
        // 5 ms after it was last looked at: its calls are taken.
        assert!(room.worth_a_look(start + Duration::from_millis(5), poll));
        assert!(!room.worth_a_look(start + Duration::from_millis(9), poll));
        assert!(room.worth_a_look(start + Duration::from_millis(16), poll));
    }

    #[test]
    fn a_client_subscribing_later_gets_the_whole_scene_at_the_next_frame() {
        let (mut room, client, mut rx) = room();
        for _ in 0..5 {
            room.step().map_err(|_| "a step failed").unwrap();
        }
        for (topic, sub) in [
            ("/scene/static", 1),
            ("/scene", 2),
            ("/tf", 3),
            ("/stats", 4),
        ] {
            subscribe(&room, client, topic, sub);
        }
        room.step().map_err(|_| "a step failed").unwrap();
        let t5 = 5 * room.session.as_ref().unwrap().dt_ns();
        let mut got = received(&mut rx);
        got.sort_unstable();
        // The static wall never changes, yet its scene comes whole, with the camera's frame.
        assert_eq!(got, [(1, t5), (2, t5), (3, t5), (4, t5)]);
    }
}
