//! Rooms: one server hosting many game sessions at once, each its own simulation, game,
//! recording and clients, addressed by the URL path (`ws://HOST:PORT/rooms/NAME`).
//!
//! - A room is made ([`RoomMaker::make`]) when a client first connects to its URL, or by a
//!   `/rooms` call with `{"create": "NAME"}`; it starts at frame 0 and steps in real time
//!   at its simulation's dt. It closes when it has had no client for
//!   [`RoomOptions::grace`] (its recording finished, renamed into place), when the server
//!   stops, or when its game fails (a panic, an overflow: its clients are told why).
//! - Rooms step on [`RoomOptions::threads`] worker threads, not a thread each: a new room
//!   goes to the worker with the fewest, which steps each of its rooms when its frame is
//!   due (one frame per room per pass, so a late room catches up without starving the
//!   others). Game code runs inside `catch_unwind` (`room.rs`).
//! - Bounds: [`RoomOptions::max_rooms`] rooms, [`RoomOptions::max_clients_per_room`]
//!   clients in a room and [`RoomOptions::max_clients`] in all (past them a client is told
//!   why and closed with 1013); per client, the queue budget of the plain server
//!   ([`crate::CLIENT_BUDGET`] + 1 MiB of answers); per room, [`MAX_ROOM_INPUTS`] inputs
//!   waiting for the next frame (each at most 4 KiB) and 64 calls.

use std::collections::BTreeMap;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, mpsc};
use std::time::{Duration, Instant};

use ricochet_record::session::GameSession;
use ricochet_sim::Simulation;

use crate::common::{Lateness, MAX_CLIENTS, Note, ServeError, metadata};
use crate::door::{Door, Entered, check_room_name};
use crate::hub::{ClientQueue, Hub};
use crate::protocol::{self, ServerMessage};
use crate::room::{self, Closing, Room, RoomsRequest, Stats};
use crate::sink::LiveSink;
use crate::sink::ServeSink;

/// What a server hosts: each new room's simulation and game.
pub trait RoomMaker: Send + Sync + 'static {
    /// The game each room runs.
    type Game: ricochet_sim::Game + Send + 'static;

    /// Room `room`'s simulation at frame 0 and its game.
    ///
    /// # Errors
    /// Why the room can't be made (told to the client that asked for it).
    fn make(&self, room: &str) -> Result<(Simulation, Self::Game), String>;

    /// The JSON Schema of the game's input (what a client publishes on `/input`), sent in
    /// `/join`'s answer.
    fn input_schema(&self) -> String {
        r#"{"type": "object"}"#.to_owned()
    }

    /// Files attached to each room's recording: (name, media type, bytes).
    fn attachments(&self, room: &str) -> Vec<(String, String, Vec<u8>)> {
        let _ = room;
        Vec::new()
    }
}

/// Inputs waiting for a room's next frame, from all its clients, beyond which new ones are
/// refused: a room's 64 clients at 10 a frame (the plain server takes 10,000; a room's
/// share of memory stays 4 MiB at 4 KiB an input).
pub const MAX_ROOM_INPUTS: usize = 1024;

/// The most worker threads.
pub const MAX_THREADS: usize = 256;

/// How to host rooms.
#[derive(Clone)]
pub struct RoomOptions {
    /// A folder: each room records to `NAME.mcap` there (`NAME-1.mcap`, ... when a room of
    /// that name was recorded before: no file is ever replaced).
    pub record: Option<PathBuf>,
    /// How long a room with no client lives on.
    pub grace: Duration,
    /// Rooms at once.
    pub max_rooms: usize,
    /// Clients in one room.
    pub max_clients_per_room: usize,
    /// Clients in all rooms.
    pub max_clients: usize,
    /// Worker threads stepping the rooms (1 to [`MAX_THREADS`]).
    pub threads: usize,
    /// Where notes go (a room opened, closed, failed).
    pub note: Note,
}

impl Default for RoomOptions {
    /// No recording, 10 s of grace, 1,000 rooms, 64 clients a room, 1,000 in all, a
    /// thread per core.
    fn default() -> Self {
        RoomOptions {
            record: None,
            grace: Duration::from_secs(10),
            max_rooms: 1000,
            max_clients_per_room: MAX_CLIENTS,
            max_clients: 1000,
            threads: std::thread::available_parallelism().map_or(1, usize::from),
            note: Arc::new(|text: &str| eprintln!("{text}")),
        }
    }
}

/// What the rooms did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ServedRooms {
    /// Rooms made.
    pub opened: u64,
    /// Rooms closed by a failure (a panic, an overflow, a recording that failed).
    pub failed: u64,
    /// Frames stepped, all rooms.
    pub frames: u64,
    /// How late frames started against their room's schedule, ms: p50, p99, max.
    pub late_ms: [f64; 3],
}

/// A registered room, as connections and `/rooms` see it.
struct Entry {
    hub: Hub,
    stats: Arc<Stats>,
}

struct Inner {
    rooms: BTreeMap<String, Entry>,
    opened: u64,
}

/// The rooms a server hosts: made, found and closed under one lock.
struct Registry<M: RoomMaker> {
    maker: M,
    options: RoomOptions,
    input_schema: Arc<str>,
    inner: Mutex<Inner>,
    /// Clients in all rooms.
    clients: AtomicUsize,
    /// Each worker's new rooms, and how many it has.
    workers: Vec<Worker<M::Game>>,
}

/// A worker's inbox of new rooms, and how many rooms it has.
type Worker<G> = (Mutex<mpsc::Sender<Room<G>>>, AtomicUsize);

impl<M: RoomMaker> Registry<M> {
    fn lock(&self) -> MutexGuard<'_, Inner> {
        self.inner
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// Makes room `name` (the caller holds the lock and checked it has none such).
    fn open(&self, inner: &mut Inner, name: &str) -> Result<Hub, String> {
        if inner.rooms.len() >= self.options.max_rooms {
            return Err(format!(
                "too many rooms, at most {}",
                self.options.max_rooms
            ));
        }
        let made = catch_unwind(AssertUnwindSafe(|| self.maker.make(name)))
            .map_err(|_| format!("room {name}: making it panicked"))?;
        let (sim, game) = made.map_err(|why| format!("room {name}: {why}"))?;
        let dt = Duration::try_from_secs_f64(sim.dt())
            .ok()
            .filter(|d| !d.is_zero())
            .ok_or_else(|| format!("room {name}: dt {} is no frame length", sim.dt()))?;
        let hub = Hub::default();
        {
            let mut s = hub.lock();
            s.track_leaves = true;
            s.input_cap = Some(MAX_ROOM_INPUTS);
        }
        let (file, recording) = match &self.options.record {
            None => (None, None),
            Some(dir) => {
                let path = free_path(dir, name)?;
                let mut file = ricochet_record::log_writer(&path)
                    .map_err(|e| format!("room {name}: recording: {e}"))?;
                for (n, media, bytes) in self.maker.attachments(name) {
                    ricochet_log::MessageSink::attach(&mut file, &n, &media, &bytes)
                        .map_err(|e| format!("room {name}: recording: {e}"))?;
                }
                (Some((file, Vec::new())), Some(path))
            }
        };
        let sink = ServeSink {
            live: LiveSink::new(hub.clone()),
            file,
            muted: false,
        };
        let session = catch_unwind(AssertUnwindSafe(|| {
            GameSession::start(sim, game, sink, true)
        }))
        .map_err(|_| format!("room {name}: starting its game panicked"))?
        .map_err(|e| format!("room {name}: {e}"))?;
        let room = Room::new(
            name.to_owned(),
            hub.clone(),
            session,
            dt,
            Arc::clone(&self.input_schema),
            recording,
        );
        let stats = Arc::clone(&room.stats);
        let worker = self
            .workers
            .iter()
            .min_by_key(|(_, n)| n.load(Ordering::Relaxed))
            .ok_or("no worker")?;
        worker.1.fetch_add(1, Ordering::Relaxed);
        let sent = worker
            .0
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .send(room);
        if sent.is_err() {
            return Err("the server is stopping".to_owned());
        }
        inner.rooms.insert(
            name.to_owned(),
            Entry {
                hub: hub.clone(),
                stats,
            },
        );
        inner.opened += 1;
        (self.options.note)(&format!("serve: room {name} opened"));
        Ok(hub)
    }

    /// `/rooms`: the list, after making the room asked for if any.
    fn rooms_call(&self, payload: &[u8]) -> Result<String, String> {
        let request: RoomsRequest =
            serde_json::from_slice(room::body(payload)).map_err(|e| format!("bad request: {e}"))?;
        let mut inner = self.lock();
        if let Some(name) = &request.create {
            check_room_name(name)?;
            if !inner.rooms.contains_key(name) {
                self.open(&mut inner, name)?;
            }
        }
        let list: Vec<serde_json::Value> = inner
            .rooms
            .iter()
            .map(|(name, e)| {
                serde_json::json!({
                    "name": name,
                    "frame": e.stats.frame.load(Ordering::Relaxed),
                    "players": e.stats.players.load(Ordering::Relaxed),
                    "clients": e.hub.lock().client_count(),
                })
            })
            .collect();
        Ok(serde_json::json!({ "rooms": list }).to_string())
    }

    /// Closes `room` if it has had no client for the grace period, or `failed`: it is
    /// forgotten (a new client makes a new room of that name).
    fn close_if(&self, room: &mut Room<M::Game>, now: Instant, closing: Option<Closing>) -> bool {
        let why = {
            let inner = self.lock();
            let why = match closing {
                Some(Closing::Failed(why)) => Some((why, true)),
                Some(Closing::Done(why)) => Some((why, false)),
                None => {
                    let clients = room.hub.lock().client_count();
                    if clients > 0 {
                        room.empty_since = None;
                        None
                    } else {
                        let since = *room.empty_since.get_or_insert(now);
                        (now.saturating_duration_since(since) >= self.options.grace)
                            .then(|| (format!("room {}: closed, empty", room.name), false))
                    }
                }
            };
            if why.is_some() {
                // Under the registry's lock: no client enters it from now. It stays listed
                // (and its name taken) until its recording is finished below, so a new room
                // of that name never records to the same file.
                room.hub.lock().closed = true;
            }
            drop(inner);
            why
        };
        let Some((why, failed)) = why else {
            return false;
        };
        let frames = match room.next_frame().checked_sub(1) {
            Some(last) => format!("frames 0 to {last}"),
            None => "no frame".to_owned(),
        };
        let recording = room
            .recording
            .as_ref()
            .map_or(String::new(), |p| format!(", recorded to {}", p.display()));
        (self.options.note)(&format!(
            "serve: {why}{} ({frames}{recording})",
            if failed { "; room closed" } else { "" }
        ));
        let told = if failed {
            format!("{why}; room closed ({frames}{recording})")
        } else {
            why
        };
        if let Some(e) = room.close(&told) {
            (self.options.note)(&format!("error: {e}"));
        }
        self.lock().rooms.remove(&room.name);
        failed
    }
}

/// `dir/NAME.mcap`, or `dir/NAME-K.mcap` for the first K whose file is not there.
fn free_path(dir: &Path, name: &str) -> Result<PathBuf, String> {
    let first = dir.join(format!("{name}.mcap"));
    if !first.exists() {
        return Ok(first);
    }
    (1..10_000)
        .map(|k| dir.join(format!("{name}-{k}.mcap")))
        .find(|p| !p.exists())
        .ok_or_else(|| format!("room {name}: 10,000 recordings of it in {}", dir.display()))
}

impl<M: RoomMaker> Door for Registry<M> {
    fn enter(&self, name: &str, queue: ClientQueue) -> Result<Entered, String> {
        let max = self.options.max_clients;
        if self.clients.load(Ordering::Acquire) >= max {
            return Err(format!("too many clients on this server, at most {max}"));
        }
        let mut inner = self.lock();
        let hub = match inner.rooms.get(name) {
            Some(e) => e.hub.clone(),
            None => self.open(&mut inner, name)?,
        };
        let mut s = hub.lock();
        if s.closed {
            return Err(format!(
                "room {name} is closing (its recording being finished); try again in a moment"
            ));
        }
        let per_room = self.options.max_clients_per_room;
        if s.client_count() >= per_room {
            return Err(format!("room {name} is full, at most {per_room} clients"));
        }
        // Counted under the registry's lock, so two connections can't both take the last
        // place.
        if self.clients.fetch_add(1, Ordering::AcqRel) >= max {
            self.clients.fetch_sub(1, Ordering::AcqRel);
            return Err(format!("too many clients on this server, at most {max}"));
        }
        let info = ServerMessage::ServerInfo {
            name: "ricochet",
            capabilities: &["time", "clientPublish", "services"],
            supported_encodings: &["json"],
            metadata: metadata(),
            session_id: &format!("ricochet-room-{name}"),
            data_start_time: protocol::Time::from_ns(0),
            data_end_time: protocol::Time::from_ns(0),
        };
        let advertise = ServerMessage::Advertise {
            channels: s.channels(),
        };
        let services = ServerMessage::AdvertiseServices {
            services: &room::services(),
        };
        let hello = [info.json(), advertise.json(), services.json()];
        let (id, kicked) = s.connect(queue);
        drop(s);
        Ok(Entered {
            hub,
            id,
            kicked,
            hello,
        })
    }

    fn left(&self, _hub: &Hub, _client: u64) {
        self.clients.fetch_sub(1, Ordering::AcqRel);
    }

    fn rooms_call(&self, payload: &[u8]) -> Result<String, String> {
        Registry::rooms_call(self, payload)
    }
}

/// The longest a worker sleeps before it looks at its rooms' clients again.
const POLL: Duration = Duration::from_millis(5);

/// What a worker did.
#[derive(Default)]
struct WorkerDone {
    frames: u64,
    failed: u64,
    lateness: Lateness,
}

/// One worker: steps its rooms when due until `stop`, then closes them.
fn work<M: RoomMaker>(
    registry: &Registry<M>,
    index: usize,
    new_rooms: &mpsc::Receiver<Room<M::Game>>,
    stop: &AtomicBool,
) -> WorkerDone {
    let mut done = WorkerDone::default();
    let mut rooms: Vec<Room<M::Game>> = Vec::new();
    let rooms_call = |payload: &[u8]| registry.rooms_call(payload);
    loop {
        while let Ok(room) = new_rooms.try_recv() {
            rooms.push(room);
        }
        if stop.load(Ordering::SeqCst) {
            for mut room in rooms.drain(..) {
                let why = Closing::Done(format!("room {}: the server stopped", room.name));
                registry.close_if(&mut room, Instant::now(), Some(why));
            }
            // Rooms made since (their senders are still held by the registry).
            while let Ok(mut room) = new_rooms.try_recv() {
                let why = Closing::Done(format!("room {}: the server stopped", room.name));
                registry.close_if(&mut room, Instant::now(), Some(why));
            }
            return done;
        }
        let mut wake = Instant::now() + POLL;
        let before = rooms.len();
        rooms.retain_mut(|room| {
            // A room is looked at when its frame is due, or POLL after it was last looked
            // at (its calls answered): not on every pass, which each room's frame causes,
            // so a worker's passes cost O(rooms) a frame, not O(rooms²).
            if !room.worth_a_look(Instant::now(), POLL) {
                wake = wake.min(room.due());
                return true;
            }
            let mut closing = room.commands(&rooms_call).err();
            let now = Instant::now();
            let due = room.due();
            if closing.is_none() && due <= now {
                done.lateness.add(now.saturating_duration_since(due));
                match room.step() {
                    Ok(()) => done.frames += 1,
                    Err(c) => closing = Some(c),
                }
            }
            wake = wake.min(room.due());
            let failed = matches!(closing, Some(Closing::Failed(_)));
            let was_closing = closing.is_some();
            if registry.close_if(room, now, closing) || was_closing {
                done.failed += u64::from(failed);
                return false;
            }
            // `close_if` may have closed it for being empty.
            !room.hub.lock().closed
        });
        let closed = before - rooms.len();
        registry.workers[index]
            .1
            .fetch_sub(closed, Ordering::Relaxed);
        if let Some(wait) = wake.checked_duration_since(Instant::now()) {
            std::thread::sleep(wait);
        }
    }
}

/// Rooms being served: their registry (the connections' door) and workers.
pub(crate) struct Hosted {
    pub(crate) door: Arc<dyn Door>,
    stop: Arc<AtomicBool>,
    threads: Vec<std::thread::JoinHandle<WorkerDone>>,
    opened: Box<dyn Fn() -> u64 + Send>,
}

/// Starts the workers hosting `maker`'s rooms.
pub(crate) fn host<M: RoomMaker>(maker: M, o: &RoomOptions) -> Result<Hosted, ServeError> {
    if !(1..=MAX_THREADS).contains(&o.threads) {
        return Err(ServeError::Options(format!(
            "threads must be 1 to {MAX_THREADS}, got {}",
            o.threads
        )));
    }
    for (what, n) in [
        ("max_rooms", o.max_rooms),
        ("max_clients_per_room", o.max_clients_per_room),
        ("max_clients", o.max_clients),
    ] {
        if n == 0 {
            return Err(ServeError::Options(format!("{what} must be at least 1")));
        }
    }
    if let Some(dir) = &o.record
        && !dir.is_dir()
    {
        return Err(ServeError::Options(format!(
            "--record-rooms {}: not a folder (make it first)",
            dir.display()
        )));
    }
    let mut receivers = Vec::new();
    let mut workers = Vec::new();
    for _ in 0..o.threads {
        let (tx, rx) = mpsc::channel();
        workers.push((Mutex::new(tx), AtomicUsize::new(0)));
        receivers.push(rx);
    }
    let registry = Arc::new(Registry {
        input_schema: maker.input_schema().into(),
        maker,
        options: o.clone(),
        inner: Mutex::new(Inner {
            rooms: BTreeMap::new(),
            opened: 0,
        }),
        clients: AtomicUsize::new(0),
        workers,
    });
    let stop = Arc::new(AtomicBool::new(false));
    let mut threads = Vec::new();
    for (index, rx) in receivers.into_iter().enumerate() {
        let (registry, flag) = (Arc::clone(&registry), Arc::clone(&stop));
        let spawned = std::thread::Builder::new()
            .name(format!("rooms-{index}"))
            .spawn(move || work(&registry, index, &rx, &flag));
        match spawned {
            Ok(t) => threads.push(t),
            Err(e) => {
                stop.store(true, Ordering::SeqCst);
                return Err(ServeError::Runtime(e));
            }
        }
    }
    let counter = Arc::clone(&registry);
    Ok(Hosted {
        door: registry,
        stop,
        threads,
        opened: Box::new(move || counter.lock().opened),
    })
}

impl Hosted {
    /// Stops every room (each recording finished) and says what they did.
    pub(crate) fn stop(self) -> ServedRooms {
        self.stop.store(true, Ordering::SeqCst);
        let mut served = ServedRooms::default();
        let mut lateness = Lateness::default();
        for t in self.threads {
            if let Ok(done) = t.join() {
                served.frames += done.frames;
                served.failed += done.failed;
                lateness.merge(&done.lateness);
            }
        }
        served.opened = (self.opened)();
        served.late_ms = [
            lateness.quantile(0.5),
            lateness.quantile(0.99),
            lateness.max_ms(),
        ];
        served
    }
}
