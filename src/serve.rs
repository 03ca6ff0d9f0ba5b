//! `ricochet serve`: the live server is `ricochet_serve`'s; this file reads the options and
//! the scenario, installs the Ctrl-C/SIGTERM handler, and prints what happened.

use std::net::SocketAddr;
use std::path::Path;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use ricochet_serve::{Listener, ServeError};

use crate::out;

pub use ricochet_serve::DEFAULT_BIND;

/// The options of `ricochet serve`.
pub struct Options<'a> {
    /// The scenario (none: the built-in demo).
    pub scenario: Option<&'a Path>,
    /// Address to listen on.
    pub bind: &'a str,
    /// Simulation seconds per wall second (0.01 to 100).
    pub speed: f64,
    /// Stop after this many frames (default: run until interrupted).
    pub frames: Option<u64>,
    /// Also write the log here.
    pub record: Option<&'a Path>,
    /// Record each room to DIR/NAME.mcap.
    pub record_rooms: Option<&'a Path>,
    /// Start paused (the clients see frame 0; `/play` or `/step` goes on).
    pub paused: bool,
}

/// Runs `ricochet serve`. Exit code 0 when stopped (Ctrl-C, SIGTERM, `--frames`), 2 for bad
/// input (scenario, address, speed).
pub fn run(o: &Options) -> anyhow::Result<ExitCode> {
    if !(o.speed.is_finite() && ricochet_serve::SPEEDS.contains(&o.speed)) {
        out::error(&format!(
            "error: --speed must be {} to {}, got {}",
            ricochet_serve::SPEEDS.start(),
            ricochet_serve::SPEEDS.end(),
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
    if let Some(dir) = o.record_rooms
        && !dir.is_dir()
    {
        out::error(&format!(
            "error: --record-rooms {}: not a folder (make it first)",
            dir.display()
        ));
        return Ok(ExitCode::from(2));
    }
    let interrupted = Arc::new(AtomicBool::new(false));
    {
        let flag = Arc::clone(&interrupted);
        let _ = ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst));
    }
    let listener = match Listener::bind(addr) {
        Ok(l) => l,
        Err(e @ ServeError::Bind { .. }) => {
            out::error(&format!("error: {e}"));
            return Ok(ExitCode::from(2));
        }
        Err(e) => return Err(e.into()),
    };
    let local = listener.local_addr();
    if !local.ip().is_loopback() {
        out::note(&format!(
            "warning: listening on {local}, beyond this machine: the Foxglove WebSocket \
             protocol has no authentication, anyone who can reach it can watch"
        ))?;
    }
    out::note(&format!(
        "serving {} on ws://{local} (Foxglove: Open connection; layout foxglove/ricochet-layout.json), \
         and rooms of it on ws://{local}/rooms/NAME; Ctrl-C stops",
        scenario.name
    ))?;
    let note: ricochet_serve::Note = Arc::new(|text: &str| {
        // A lost line on stderr is no failure.
        let _ = out::note(text);
    });
    let options = ricochet_serve::Options {
        speed: o.speed,
        frames: o.frames,
        record: o.record.map(Path::to_path_buf),
        paused: o.paused,
        note: note.clone(),
        rooms: Some(ricochet_serve::RoomOptions {
            record: o.record_rooms.map(Path::to_path_buf),
            note,
            ..Default::default()
        }),
    };
    let served = ricochet_serve::serve(listener, scenario, text, &options, &interrupted)?;
    let session = match served.next_frame.checked_sub(1) {
        Some(last) => format!("frames 0 to {last}"),
        None => "no frame".to_owned(),
    };
    out::note(&format!(
        "served {session} ({} steps in all, {} in real time, the rest by /step \
         and seeks); {} messages dropped for slow clients; {} s of CPU",
        served.stepped,
        served.real_time,
        served.dropped,
        ricochet_serve::cpu_seconds().map_or("?".to_owned(), |s| format!("{s:.2}"))
    ))?;
    if let Some(r) = &served.rooms {
        out::note(&format!(
            "rooms: {} opened, {} failed, {} frames; frame starts late: p50 {:.3} ms, p99 {:.3} ms, max {:.3} ms",
            r.opened, r.failed, r.frames, r.late_ms[0], r.late_ms[1], r.late_ms[2]
        ))?;
    }
    Ok(ExitCode::SUCCESS)
}
