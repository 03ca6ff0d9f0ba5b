//! `ricochet run`: a scenario stepped to the end (or to Ctrl-C, SIGTERM or SIGHUP) and recorded.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use anyhow::Context;
use ricochet_sim::{GameLoop, Overflowed, ScenarioGame, Simulation};

use crate::channels::Channels;
use crate::load::{DEFAULT_NAME, load};
use crate::out;
use crate::record::Recorder;

/// Runs of at least this many frames get a progress bar (on a terminal only).
const PROGRESS_FROM: u64 = 2_000;

/// `ricochet run`.
pub fn run(
    path: Option<&Path>,
    output: Option<PathBuf>,
    frames: Option<u64>,
    validate: bool,
    channels: Option<&str>,
    threads: Option<usize>,
    draw_every_frame: bool,
) -> anyhow::Result<ExitCode> {
    let channels = match channels.map(Channels::parse).transpose() {
        Ok(c) => c.unwrap_or_default(),
        Err(e) => {
            out::error(&format!("error: {e}"));
            return Ok(ExitCode::from(2));
        }
    };
    let scenario = match load(path) {
        Ok(s) => s,
        Err(code) => return Ok(code),
    };
    let stem = path
        .unwrap_or(Path::new(DEFAULT_NAME))
        .file_stem()
        .map_or_else(|| "run".to_owned(), |s| s.to_string_lossy().into_owned());
    let output = output.unwrap_or_else(|| PathBuf::from(format!("{stem}.mcap")));
    if output == Path::new("-") {
        out::error(
            "error: -o -: a log can't be written to standard output (an MCAP log is indexed \
             at the end, in a file); give a file name",
        );
        return Ok(ExitCode::from(2));
    }
    if let Some(input) = path
        && crate::files::same_file(input, &output)
    {
        out::error(&format!(
            "error: -o {}: that is the scenario being run; choose another output file",
            output.display()
        ));
        return Ok(ExitCode::from(2));
    }
    let interrupted = Arc::new(AtomicBool::new(false));
    {
        let flag = Arc::clone(&interrupted);
        // SIGINT, SIGTERM and SIGHUP (ctrlc's `termination` feature) all stop the run at the
        // next frame and finish the log. Installed before the log is created, so that no such
        // signal leaves its temporary file behind. If a handler can't be installed (one
        // already is), the signal just ends the process, and an old output file stays whole.
        let _ = ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst));
    }
    let frames = frames.unwrap_or(scenario.frames);
    // Every frame's log time must be a whole number of nanoseconds that fits in a u64.
    if let Err(e) = scenario.world.last_time_ns(frames) {
        out::error(&format!("error: --frames {frames}: {e}"));
        return Ok(ExitCode::from(2));
    }
    // Created before the first step: an unwritable path fails now, not after the run. The
    // log goes to a temporary file renamed onto `output` when it is complete, so an existing
    // file there stays whole until then, whatever stops the run.
    let mut recorder = match Recorder::create(&output, scenario.world.dt, channels) {
        Ok(r) => r,
        Err(e) => {
            out::error(&format!("error: cannot write the log: {e}"));
            return Ok(ExitCode::from(2));
        }
    };
    if draw_every_frame {
        recorder.draw_every_frame();
    }
    let progress = (std::io::stderr().is_terminal() && frames >= PROGRESS_FROM).then(|| {
        let bar = indicatif::ProgressBar::new(frames + 1);
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "{bar:40} {pos}/{len} frames {per_sec} eta {eta}",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        bar
    });
    if validate && (scenario.world.active_region.is_some() || scenario.world.sleep_after.is_some())
    {
        out::note(
            "warning: frozen and sleeping bodies are not tested, so /validation may list \
             their pairs as differences; `ricochet validate` turns both off",
        )?;
    }
    let mut validation = if validate {
        recorder
            .add_validation_channel()
            .with_context(|| format!("adding /validation to {}", output.display()))?;
        Some(crate::validate::Validation::new(&scenario))
    } else {
        None
    };
    let mut sim = Simulation::new(&scenario);
    sim.capture_detect_poses = validate;
    sim.set_threads(
        threads.unwrap_or_else(|| {
            std::thread::available_parallelism().map_or(1, std::num::NonZero::get)
        }),
    );
    // `run` is the scenario's game with no commands: the frame loop every mode shares.
    let mut game = GameLoop::new(sim, ScenarioGame);
    // The frames/s below are the frame loop's (and the log's finish), as `bench --record`
    // times them: building the world (20 ms of the 10,000-asteroid level's 50 ms) is not a
    // frame.
    let started = Instant::now();
    let mut contacts = 0u64;
    let mut peak_bodies = 0usize;
    let mut ran = 0u64;
    let mut overflow = None;
    for _ in 0..=frames {
        if interrupted.load(Ordering::SeqCst) {
            break;
        }
        let out = match game.step() {
            Ok(out) => out,
            Err(Overflowed { frame, bad }) => {
                // Nothing after an overflow can be trusted: the log ends with the last good
                // frame.
                overflow = Some((frame, bad));
                break;
            }
        };
        let sim = game.sim();
        contacts += out.contacts.len() as u64;
        peak_bodies = peak_bodies.max(sim.world().len());
        recorder
            .record(sim, &out)
            .with_context(|| format!("writing frame {} to {}", out.frame, output.display()))?;
        if let Some(v) = &mut validation {
            let report = v.frame(sim, &out);
            recorder
                .record_validation(crate::validate::verdict(&report))
                .with_context(|| format!("writing frame {} to {}", out.frame, output.display()))?;
        }
        ran += 1;
        if let Some(bar) = &progress {
            bar.inc(1);
        }
    }
    if let Some(bar) = progress {
        bar.finish_and_clear();
    }
    recorder
        .finish()
        .with_context(|| format!("finishing {}", output.display()))?;
    let sim = game.sim();
    if let Some((frame, bad)) = overflow {
        out::error(&format!(
            "error: frame {frame}: {}; the simulation overflowed. {} holds {}",
            crate::validate::describe(sim, &bad),
            output.display(),
            match frame {
                0 => "no frame".to_owned(),
                f => format!("frames 0 to {}", f - 1),
            }
        ));
        return Ok(ExitCode::from(1));
    }
    let wall = started.elapsed().as_secs_f64();
    let stepped = ran.saturating_sub(1);
    let note = if interrupted.load(Ordering::SeqCst) {
        " (interrupted; the log is complete up to here)"
    } else {
        ""
    };
    out::note(&format!(
        "{}: {stepped} frames, {} bodies at the end ({peak_bodies} at most), {contacts} contacts, {:.3} s wall, {:.0} frames/s -> {}{note}",
        out::escape_controls(&scenario.name),
        sim.world().len(),
        wall,
        ran as f64 / wall.max(1e-9),
        output.display()
    ))?;
    if let Some(v) = validation
        && !v.finish(&scenario, stepped)?
    {
        return Ok(ExitCode::from(1));
    }
    Ok(ExitCode::SUCCESS)
}
