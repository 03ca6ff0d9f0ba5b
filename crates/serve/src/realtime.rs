//! The real-time loop: a simulation stepped on a fixed-timestep schedule and streamed live
//! over the Foxglove WebSocket protocol, the same messages and schemas as `ricochet run`
//! writes (a viewer that subscribes gets the last `/scene`, `/scene/static` and `/tf` at
//! once: each is whole), optionally recorded to a file at the same time.
//!
//! The simulation runs on the calling thread (frame `n` starts at `n * dt / speed` after the
//! start: a late frame is not skipped, the next ones catch up); the wall clock only paces,
//! it never reaches a message. The WebSocket side runs on a tokio runtime of its own thread
//! (`server.rs`); the two share the [`Hub`].

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use ricochet_sim::Scenario;

use crate::common::{Lateness, Listener, Note, SPEEDS, ServeError};
use crate::hub::Hub;
use crate::rooms::{RoomMaker, RoomOptions, ServedRooms, host};
use crate::serving::{Asker, PlainOptions, Serving};
use crate::sink::{finish, start};
use crate::{server, services};

/// The longest the loop sleeps before it looks at the stop flag and its clients' calls
/// again (paused, or before a frame is due): what SIGTERM or a call may wait, besides a
/// seek's or step's slice.
const POLL: Duration = Duration::from_millis(5);

/// How to serve.
pub struct Options {
    /// Simulation seconds per wall second ([`SPEEDS`]: 0.01 to 100).
    pub speed: f64,
    /// Stop after this many frames after frame 0 (`None`: until stopped, at most
    /// [`ricochet_sim::MAX_FRAMES`]); no `/step` or seek goes past it either.
    pub frames: Option<u64>,
    /// Also record the session here, as `ricochet run` writes a log (`/reset` and `/load`
    /// start `NAME-1.mcap`, ...).
    pub record: Option<PathBuf>,
    /// Start paused: frame 0 is shown; `/play` or `/step` goes on.
    pub paused: bool,
    /// Where notes go.
    pub note: Note,
    /// Also host rooms of the scenario's game on `/rooms/NAME` (each a fresh simulation of
    /// the scenario), besides the single session on the plain URL.
    pub rooms: Option<RoomOptions>,
}

impl Default for Options {
    /// Real time, until stopped, no recording, notes to stderr.
    fn default() -> Self {
        Options {
            speed: 1.0,
            frames: None,
            record: None,
            paused: false,
            note: Arc::new(|text: &str| eprintln!("{text}")),
            rooms: None,
        }
    }
}

/// What a served session did.
#[derive(Clone, Debug, PartialEq)]
pub struct Served {
    /// The frame the session would step next: it holds frames 0 to `next_frame - 1`.
    pub next_frame: u64,
    /// Steps in all (seeks' and `/step`'s included).
    pub stepped: u64,
    /// Frames stepped on the real-time schedule.
    pub real_time: u64,
    /// Messages slow clients lost.
    pub dropped: u64,
    /// What the rooms did, if it hosted rooms.
    pub rooms: Option<ServedRooms>,
}

/// Serves `scenario` (a file's, or one a game builds in code; `text` is its file, attached
/// to the recording for `ricochet replay`, or empty) on `listener` until `stop` is set or
/// the last frame is stepped. Clients' inputs (`/input`, JSON actions addressed by body
/// name) apply at the next frame boundary; their service calls (`/reset`, `/load`, `/step`,
/// `/query`, ...) and Foxglove's timeline (play, pause, seek, speed) between frames.
pub fn serve(
    listener: Listener,
    scenario: Scenario,
    text: String,
    o: &Options,
    stop: &AtomicBool,
) -> Result<Served, ServeError> {
    if !(o.speed.is_finite() && SPEEDS.contains(&o.speed)) {
        return Err(ServeError::Options(format!(
            "speed must be {} to {}, got {}",
            SPEEDS.start(),
            SPEEDS.end(),
            ricochet_geom::Number(o.speed)
        )));
    }
    // Every frame's log time must be a whole number of nanoseconds that fits in a u64.
    let last = o.frames.unwrap_or(ricochet_sim::MAX_FRAMES);
    if let Err(e) = scenario.world.last_time_ns(last) {
        return Err(ServeError::Options(format!("frames {last}: {e}")));
    }
    let hub = Hub::default();
    hub.lock().data_end_ns = scenario
        .frames
        .saturating_mul((scenario.world.dt * 1e9).round() as u64);
    let session = start(&scenario, &text, &hub, o.record.as_deref(), 0)?;
    let hosted = match &o.rooms {
        Some(ro) => Some(host(
            crate::scenario_rooms::ScenarioRooms::new(scenario.clone(), text.clone()),
            ro,
        )?),
        None => None,
    };
    let rooms = hosted.as_ref().map(|h| Arc::clone(&h.door));
    let session_id = format!("ricochet-{}", scenario.name);
    let server_hub = hub.clone();
    let Listener {
        runtime, listener, ..
    } = listener;
    let note = o.note.clone();
    std::thread::Builder::new()
        .name("serve".into())
        .spawn(move || {
            let routes = server::Routes {
                plain: Some((server_hub, session_id)),
                rooms,
            };
            runtime.block_on(server::accept(listener, routes, note))
        })
        .map_err(ServeError::Runtime)?;
    let plain = PlainOptions {
        speed: o.speed,
        paused: o.paused,
        frames: o.frames,
        record: o.record.clone(),
        note: o.note.clone(),
    };
    let mut serving = Serving::new(session, scenario, text, plain);
    let real_time = run_loop(&mut serving, &hub, stop, &o.note);
    let rooms = hosted.map(crate::rooms::Hosted::stop);
    let real_time = real_time?;
    let next_frame = serving.session.next_frame();
    let stepped = serving.stepped;
    finish(serving.session)?;
    let dropped = hub.lock().dropped;
    Ok(Served {
        next_frame,
        stepped,
        real_time,
        dropped,
        rooms,
    })
}

/// CPU time this process used (user + system), from `/proc/self/stat` (Linux); `None`
/// elsewhere.
pub fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (in parentheses, which may hold spaces).
    let rest = stat.rsplit_once(')')?.1;
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let utime: f64 = fields.get(11)?.parse().ok()?;
    let stime: f64 = fields.get(12)?.parse().ok()?;
    // Clock ticks: 100 a second on Linux.
    Some((utime + stime) / 100.0)
}

/// Steps on the real-time schedule until stopped, taking the clients' inputs at each frame
/// boundary and their service calls between frames, running a seek or a step in slices;
/// returns the real-time frames stepped.
fn run_loop(
    serving: &mut Serving,
    hub: &Hub,
    interrupted: &AtomicBool,
    note: &Note,
) -> Result<u64, ServeError> {
    // The schedule: frame `anchor.1 + n` starts at `anchor.0 + n * step`; moved when stepping
    // pauses, resumes, or starts over.
    let mut anchor = (Instant::now(), 0u64);
    let mut frames = 0u64;
    let mut lateness = Lateness::default();
    if serving.paused {
        // Frame 0 for the clients to see while paused.
        serving.frame(hub)?;
        frames += 1;
    }
    while !interrupted.load(Ordering::SeqCst) && serving.session.next_frame() <= serving.last {
        let calls = std::mem::take(&mut hub.lock().calls);
        for (client, call) in calls {
            let result = match (serving.busy(), services::parse(call.service, &call.payload)) {
                (Some(busy), _) => Some(Err(busy)),
                (None, Ok(command)) => {
                    let asker = Asker::Call {
                        client,
                        service: call.service,
                        call: call.call,
                    };
                    serving.command(command, hub, asker)?
                }
                (None, Err(why)) => Some(Err(why)),
            };
            if let Some(result) = result {
                hub.lock().answer(client, call.service, call.call, result);
            }
            anchor = (Instant::now(), frames);
        }
        serving.clicks(hub)?;
        let requests = std::mem::take(&mut hub.lock().playback);
        for (client, request) in requests {
            if let Some(busy) = serving.busy() {
                hub.lock().tell(client, 1, &busy);
                serving.playback_state(hub, false, &request.request_id);
                continue;
            }
            // Foxglove's timeline: speed, seek (to the frame at or before the time), play or
            // pause; every client is told the state that results.
            let speed = f64::from(request.speed);
            if speed.is_finite() && SPEEDS.contains(&speed) {
                serving.speed = speed;
            }
            anchor = (Instant::now(), frames);
            if let Some(ns) = request.seek {
                let dt_ns = serving.session.dt_ns().max(1);
                // Shown: the frame at or before the time (so the next one is after it).
                let target = (ns / dt_ns).saturating_add(1);
                let asker = Asker::Playback {
                    play: request.play,
                    request_id: request.request_id.clone(),
                };
                match serving.seek(target, hub, asker)? {
                    Ok(()) => continue,
                    Err(why) => hub.lock().tell(client, 2, &why),
                }
            }
            if !request.play || serving.session.overflowed().is_none() {
                serving.paused = !request.play;
            }
            serving.playback_state(hub, request.seek.is_some(), &request.request_id);
        }
        if serving.running.is_some() {
            serving.slice(hub)?;
            anchor = (Instant::now(), frames);
            continue;
        }
        if serving.paused {
            serving.show_last()?;
            std::thread::sleep(POLL);
            anchor = (Instant::now(), frames);
            continue;
        }
        let n = u32::try_from(frames - anchor.1).unwrap_or(u32::MAX);
        // A wait past what a `Duration` or an `Instant` holds (`--frames 0` lets any dt
        // through): never due.
        let step = Duration::try_from_secs_f64(serving.scenario.world.dt / serving.speed)
            .unwrap_or(Duration::MAX);
        let due = anchor.0.checked_add(step.saturating_mul(n));
        if let Some(wait) = due.map_or(Some(POLL), |d| d.checked_duration_since(Instant::now())) {
            // A frame's wait is dt / speed: 1.7 s at 60 Hz and speed 0.01, 100 s at 1 Hz. It
            // is slept a poll at a time, so that SIGTERM and the clients' calls are seen
            // within one, not when the frame is due.
            std::thread::sleep(wait.min(POLL));
            if due.is_none_or(|d| Instant::now() < d) {
                continue;
            }
        }
        let due = due.unwrap_or_else(Instant::now);
        lateness.add(Instant::now().saturating_duration_since(due));
        serving.frame(hub)?;
        frames += 1;
    }
    note(&format!(
        "frame starts late against the real-time schedule: p50 {:.3} ms, p99 {:.3} ms, max {:.3} ms",
        lateness.quantile(0.5),
        lateness.quantile(0.99),
        lateness.max_ms()
    ));
    Ok(frames)
}

/// Serves rooms of `maker`'s game on `listener` (`ws://HOST:PORT/rooms/NAME`; any other
/// path is refused with HTTP 400) until `stop` is set; then closes every room, each
/// recording finished.
pub fn serve_rooms<M: RoomMaker>(
    listener: Listener,
    maker: M,
    options: &RoomOptions,
    stop: &AtomicBool,
) -> Result<ServedRooms, ServeError> {
    let hosted = host(maker, options)?;
    let routes = server::Routes {
        plain: None,
        rooms: Some(Arc::clone(&hosted.door)),
    };
    let note = options.note.clone();
    let Listener {
        runtime, listener, ..
    } = listener;
    let spawned = std::thread::Builder::new()
        .name("serve".into())
        .spawn(move || runtime.block_on(server::accept(listener, routes, note)));
    if let Err(e) = spawned {
        hosted.stop();
        return Err(ServeError::Runtime(e));
    }
    while !stop.load(Ordering::SeqCst) {
        std::thread::sleep(POLL);
    }
    Ok(hosted.stop())
}
