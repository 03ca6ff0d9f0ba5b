//! `ricochet bench --record`: the cost of the log. Each built-in scene runs twice in this
//! process: the simulation alone, then stepped and recorded with every channel, as
//! `ricochet run` records (writer thread included; the drawing at its pace, or in every
//! frame with `--draw-every-frame`). Prints frames per second both ways, the
//! log's size on disk per moving body per frame, and the raw (uncompressed) message bytes
//! per channel. Figures, never assertions.
//!
//! `asteroids-10000` is the 10,000-asteroid level: circles and 5-8-gons in a
//! 2000 x 2000 wrap-around world (plus a ship and 100 bullets).

use std::collections::BTreeMap;
use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::Context;
use ricochet_log::LogFile;
use ricochet_scenes::bench::Scene;
use ricochet_sim::{BodyKind, Simulation};

use crate::channels::Channels;
use crate::out;
use crate::record::Recorder;

/// One scene's figures.
struct Figures {
    name: String,
    frames: u64,
    moving: usize,
    sim_fps: f64,
    run_fps: f64,
    bytes: u64,
    raw: BTreeMap<String, u64>,
}

fn per_body_frame(bytes: u64, f: &Figures) -> f64 {
    bytes as f64 / f.frames as f64 / f.moving.max(1) as f64
}

fn measure(
    name: &str,
    scene: Scene,
    frames: u64,
    dir: &Path,
    draw_every_frame: bool,
) -> anyhow::Result<Figures> {
    let scenario = scene.build(frames);
    let mut sim = Simulation::new(&scenario);
    let started = Instant::now();
    for _ in 0..=frames {
        std::hint::black_box(sim.step());
    }
    let sim_secs = started.elapsed().as_secs_f64();
    let path = dir.join(format!("{name}.mcap"));
    let mut sim = Simulation::new(&scenario);
    let moving = sim
        .world()
        .kind
        .iter()
        .filter(|k| **k != BodyKind::Static)
        .count();
    let started = Instant::now();
    let mut recorder = Recorder::create(&path, scenario.world.dt, Channels::default())?;
    if draw_every_frame {
        recorder.draw_every_frame();
    }
    for _ in 0..=frames {
        let out = sim.step();
        recorder.record(&sim, &out)?;
    }
    recorder.finish()?;
    let run_secs = started.elapsed().as_secs_f64();
    let bytes = std::fs::metadata(&path)?.len();
    let log = LogFile::open(&path)?;
    let mut raw = BTreeMap::new();
    let mut messages = log.messages()?;
    while let Some(m) = messages.next_raw() {
        let m = m?;
        *raw.entry(m.topic().to_owned()).or_insert(0) += m.bytes().len() as u64;
    }
    Ok(Figures {
        name: name.to_owned(),
        frames: frames + 1,
        moving,
        sim_fps: (frames + 1) as f64 / sim_secs,
        run_fps: (frames + 1) as f64 / run_secs,
        bytes,
        raw,
    })
}

/// Runs `--record` on the named scenes, `frames` frames each after frame 0; keeps the logs
/// in `keep` if given (else in a temporary directory).
pub fn run(
    scenes: &[String],
    frames: u64,
    keep: Option<&Path>,
    draw_every_frame: bool,
) -> anyhow::Result<ExitCode> {
    if let Some(code) = crate::bench::bad_frames(frames)? {
        return Ok(code);
    }
    let names: Vec<String> = if scenes.is_empty() {
        vec!["asteroids-10000".to_owned()]
    } else {
        scenes.to_vec()
    };
    let temp = tempfile::tempdir().context("creating a temporary directory for the logs")?;
    if let Some(dir) = keep {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("creating --keep directory {}", dir.display()))?;
    }
    let dir = keep.unwrap_or(temp.path());
    let mut rows = Vec::new();
    for name in &names {
        let scene = match Scene::parse(name) {
            Ok(s) => s,
            Err(e) => {
                out::error(&format!("error: {e:#}"));
                return Ok(ExitCode::from(2));
            }
        };
        out::note(&format!("bench --record: {name}, {frames} frames"))?;
        rows.push(measure(name, scene, frames, dir, draw_every_frame)?);
    }
    let mut text = String::from(
        "| scene | frames | moving bodies | simulation frames/s | recorded frames/s | log MB | bytes/moving body/frame (disk) | raw bytes/moving body/frame by channel |\n|---|---|---|---|---|---|---|---|\n",
    );
    for f in &rows {
        let raw: Vec<String> = f
            .raw
            .iter()
            .map(|(t, b)| format!("{t} {:.1}", per_body_frame(*b, f)))
            .collect();
        text.push_str(&format!(
            "| {} | {} | {} | {:.0} | {:.0} | {:.1} | {:.1} | {} |\n",
            f.name,
            f.frames,
            f.moving,
            f.sim_fps,
            f.run_fps,
            f.bytes as f64 / 1e6,
            per_body_frame(f.bytes, f),
            raw.join(", ")
        ));
    }
    out::print(&text)?;
    Ok(ExitCode::SUCCESS)
}
