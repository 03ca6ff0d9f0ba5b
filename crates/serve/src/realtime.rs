//! `ricochet serve`: a scenario stepped in real time and streamed live over the Foxglove
//! WebSocket protocol, the same messages and schemas as `ricochet run` writes (a viewer that
//! subscribes gets the last `/scene`, `/scene/static` and `/tf` at once: each is whole),
//! optionally recorded to a file at the same time.
//!
//! The simulation runs on this thread, paced by a fixed-timestep schedule (frame `n` starts
//! at `n * dt / speed` after the start: a late frame is not skipped, the next ones catch up);
//! the wall clock only paces, it never reaches a message. The WebSocket side runs on a tokio
//! runtime of its own thread (`server.rs`); the two share the [`hub::Hub`].

mod click;
mod hub;
mod load_path;
mod protocol;
mod query;
mod server;
mod services;
mod serving;

use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use anyhow::Context;
use ricochet_log::{ChannelId, LogError, LogWriter, MessageSink, Schema};

use crate::out;
use crate::session::{SCENARIO_ATTACHMENT, Session};
use hub::{Hub, LiveSink};
use serving::{Asker, Serving};

/// Where `serve` listens unless told: what Foxglove's "Open connection" suggests.
pub const DEFAULT_BIND: &str = "127.0.0.1:8765";

/// Where a served session's messages go: the live stream, and the recording if any.
struct ServeSink {
    live: LiveSink,
    /// The recording, with its channel for each live channel id.
    file: Option<(LogWriter, Vec<ChannelId>)>,
    /// While a seek re-simulates: the recording gets every frame, the clients none.
    muted: bool,
}

impl MessageSink for ServeSink {
    fn add_protobuf_channel(&mut self, topic: &str, schema: Schema) -> Result<ChannelId, LogError> {
        if let Some((file, ids)) = &mut self.file {
            let id = file.add_protobuf_channel(topic, schema.clone())?;
            ids.push(id);
        }
        self.live.add_protobuf_channel(topic, schema)
    }

    fn write<M: prost::Message + Clone + Send + 'static>(
        &mut self,
        channel: ChannelId,
        time_ns: u64,
        message: M,
    ) -> Result<(), LogError> {
        if let Some((file, ids)) = &mut self.file {
            let id = ids[usize::from(channel.index()) - 1];
            file.write(id, time_ns, message.clone())?;
        }
        if self.muted {
            return Ok(());
        }
        self.live.write(channel, time_ns, message)
    }

    fn write_live<M: prost::Message + Clone + Send + 'static>(
        &mut self,
        channel: ChannelId,
        time_ns: u64,
        message: M,
    ) -> Result<(), LogError> {
        if self.muted {
            return Ok(());
        }
        self.live.write(channel, time_ns, message)
    }
}

/// The recording of segment `k` of a session recorded to `path`: `path` itself, then
/// `NAME-1.mcap`, `NAME-2.mcap`, ... (a reset or a load starts a new file).
fn segment(path: &Path, k: u32) -> PathBuf {
    if k == 0 {
        return path.to_path_buf();
    }
    let stem = path
        .file_stem()
        .map_or_else(|| "session".into(), |s| s.to_string_lossy());
    let ext = path
        .extension()
        .map_or_else(|| "mcap".into(), |s| s.to_string_lossy());
    path.with_file_name(format!("{stem}-{k}.{ext}"))
}

/// A new session of `scenario` (whose file's text is `text`) for `hub`, recording to
/// segment `k` of `record` if asked.
fn start(
    scenario: &ricochet_sim::Scenario,
    text: &str,
    hub: &Hub,
    record: Option<&Path>,
    k: u32,
) -> anyhow::Result<Session<ServeSink>> {
    let file = match record {
        None => None,
        Some(path) => {
            let path = segment(path, k);
            let mut file = LogWriter::create(&path, crate::record::LIBRARY)
                .with_context(|| format!("creating {}", path.display()))?;
            file.attach(SCENARIO_ATTACHMENT, "application/toml", text.as_bytes())?;
            Some((file, Vec::new()))
        }
    };
    let sink = ServeSink {
        live: LiveSink::new(hub.clone()),
        file,
        muted: false,
    };
    Ok(Session::new(scenario, sink)?)
}

/// Finishes a session's recording, if it has one.
fn finish(session: Session<ServeSink>) -> anyhow::Result<()> {
    if let Some((file, _)) = session.into_sink().file {
        file.finish()?;
    }
    Ok(())
}

/// The options of `ricochet serve`.
pub struct Options<'a> {
    /// The scenario (none: the built-in demo).
    pub scenario: Option<&'a Path>,
    /// Address to listen on.
    pub bind: &'a str,
    /// Simulation seconds per wall second.
    pub speed: f64,
    /// Stop after this many frames (default: run until interrupted).
    pub frames: Option<u64>,
    /// Also write the log here.
    pub record: Option<&'a Path>,
    /// Start paused (the clients see frame 0; `/play` or `/step` goes on).
    pub paused: bool,
}

/// Runs `ricochet serve`. Exit code 0 when stopped (Ctrl-C, SIGTERM, `--frames`), 2 for bad
/// input (scenario, address, speed).
pub fn run(o: &Options) -> anyhow::Result<ExitCode> {
    if !(o.speed.is_finite() && o.speed > 0.0) {
        out::error(&format!(
            "error: --speed must be a positive number, got {}",
            ricochet_geom::Number(o.speed)
        ));
        return Ok(ExitCode::from(2));
    }
    let (scenario, text) = match crate::load::load_text(o.scenario) {
        Ok(s) => s,
        Err(code) => return Ok(code),
    };
    // Every frame's log time must be a whole number of nanoseconds that fits in a u64.
    let last = o.frames.unwrap_or(ricochet_sim::MAX_FRAMES);
    if let Err(e) = scenario.world.last_time_ns(last) {
        out::error(&format!("error: --frames {last}: {e}"));
        return Ok(ExitCode::from(2));
    }
    let addr: SocketAddr = match o.bind.parse() {
        Ok(a) => a,
        Err(e) => {
            out::error(&format!(
                "error: --bind {}: {e} (expected IP:PORT, e.g. {DEFAULT_BIND})",
                o.bind
            ));
            return Ok(ExitCode::from(2));
        }
    };
    let interrupted = Arc::new(AtomicBool::new(false));
    {
        let flag = Arc::clone(&interrupted);
        let _ = ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst));
    }
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .context("starting the WebSocket runtime")?;
    let listener = match runtime.block_on(tokio::net::TcpListener::bind(addr)) {
        Ok(l) => l,
        Err(e) => {
            out::error(&format!("error: cannot listen on {addr}: {e}"));
            return Ok(ExitCode::from(2));
        }
    };
    let local = listener.local_addr().context("reading the bound address")?;
    if !local.ip().is_loopback() {
        out::note(&format!(
            "warning: listening on {local}, beyond this machine: the Foxglove WebSocket \
             protocol has no authentication, anyone who can reach it can watch"
        ))?;
    }
    let hub = Hub::default();
    hub.lock().data_end_ns = scenario
        .frames
        .saturating_mul((scenario.world.dt * 1e9).round() as u64);
    let session = start(&scenario, &text, &hub, o.record, 0)?;
    let session_id = format!("ricochet-{}", scenario.name);
    let server_hub = hub.clone();
    std::thread::Builder::new()
        .name("serve".into())
        .spawn(move || runtime.block_on(server::accept(listener, server_hub, session_id)))
        .context("starting the WebSocket thread")?;
    out::note(&format!(
        "serving {} on ws://{local} (Foxglove: Open connection; layout foxglove/ricochet-layout.json); Ctrl-C stops",
        scenario.name
    ))?;
    let mut serving = Serving::new(session, scenario, text, o);
    let frames = run_loop(&mut serving, &hub, &interrupted)?;
    let next = serving.session.next_frame();
    let stepped = serving.stepped;
    finish(serving.session)?;
    let dropped = hub.lock().dropped;
    let session = match next.checked_sub(1) {
        Some(last) => format!("frames 0 to {last}"),
        None => "no frame".to_owned(),
    };
    out::note(&format!(
        "served {session} ({stepped} steps in all, {frames} in real time, the rest by /step \
         and seeks); {dropped} messages dropped for slow clients; {} s of CPU",
        cpu_seconds().map_or("?".to_owned(), |s| format!("{s:.2}"))
    ))?;
    Ok(ExitCode::SUCCESS)
}

/// Steps on the real-time schedule until stopped, taking the clients' inputs at each frame
/// boundary and their service calls between frames, running a seek or a step in slices;
/// returns the real-time frames stepped.
fn run_loop(serving: &mut Serving, hub: &Hub, interrupted: &AtomicBool) -> anyhow::Result<u64> {
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
            if speed.is_finite() && (0.01..=100.0).contains(&speed) {
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
            std::thread::sleep(Duration::from_millis(5));
            anchor = (Instant::now(), frames);
            continue;
        }
        let n = u32::try_from(frames - anchor.1).unwrap_or(u32::MAX);
        let step = Duration::from_secs_f64(serving.scenario.world.dt / serving.speed);
        let due = anchor.0 + step.saturating_mul(n);
        if let Some(wait) = due.checked_duration_since(Instant::now()) {
            std::thread::sleep(wait);
        }
        lateness.add(Instant::now().saturating_duration_since(due));
        serving.frame(hub)?;
        frames += 1;
    }
    out::note(&format!(
        "frame starts late against the real-time schedule: p50 {:.3} ms, p99 {:.3} ms, max {:.3} ms",
        lateness.quantile(0.5),
        lateness.quantile(0.99),
        lateness.max_ms
    ))?;
    Ok(frames)
}

/// CPU time this process used (user + system), from `/proc/self/stat` (Linux); `None`
/// elsewhere.
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (in parentheses, which may hold spaces).
    let rest = stat.rsplit_once(')')?.1;
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let utime: f64 = fields.get(11)?.parse().ok()?;
    let stime: f64 = fields.get(12)?.parse().ok()?;
    // Clock ticks: 100 a second on Linux.
    Some((utime + stime) / 100.0)
}

/// How late frames start, in a fixed histogram (bounded memory however long the server
/// runs): 0.05 ms buckets up to 100 ms, then one for all later.
struct Lateness {
    buckets: [u64; 2001],
    count: u64,
    max_ms: f64,
}

impl Default for Lateness {
    fn default() -> Self {
        Lateness {
            buckets: [0; 2001],
            count: 0,
            max_ms: 0.0,
        }
    }
}

impl Lateness {
    fn add(&mut self, late: Duration) {
        let ms = late.as_secs_f64() * 1e3;
        let bucket = ((ms / 0.05) as usize).min(self.buckets.len() - 1);
        self.buckets[bucket] += 1;
        self.count += 1;
        self.max_ms = self.max_ms.max(ms);
    }

    /// The `q` quantile, ms (the upper edge of its bucket).
    fn quantile(&self, q: f64) -> f64 {
        let want = (q * self.count as f64).ceil() as u64;
        let mut seen = 0;
        for (i, n) in self.buckets.iter().enumerate() {
            seen += n;
            if seen >= want.max(1) {
                return ((i + 1) as f64 * 0.05).min(self.max_ms);
            }
        }
        self.max_ms
    }
}
