//! `ricochet bench`: Ricochet's full step against rapier2d's collision-only pipeline and
//! Box2D v3's step, on built-in scenes of parametric size (`ricochet_scenes::bench`:
//! `asteroids-N`, `platformer-T-A`, `rain-N`), in the same process on the same frames. The measurement and
//! the report are [`ricochet_study::bench`]'s; this file parses the names, runs each scene in
//! its own process, prints the table and writes the CSV.
//!
//! Every scene runs in a fresh process (this executable again, see [`CHILD_ENV`]), so that
//! its memory figures do not include heap the allocator kept from an earlier scene.

use std::path::Path;
use std::process::ExitCode;

use anyhow::{Context, bail};

use crate::{files, out};
use ricochet_scenes::bench::{DEFAULT_SCENES, Scene};
use ricochet_study::bench::{MAX_FRAMES, Row, broad_phases, queries, report, run_scene, snapshots};

/// Set in the environment of the process that runs one scene (`run` starts one per scene):
/// it runs the scenes in-process and prints each result as a JSON line. Set it yourself to
/// run everything in one process, under a profiler for example.
pub const CHILD_ENV: &str = "RICOCHET_BENCH_CHILD";
/// What starts a result line on a child's stdout.
const ROW_PREFIX: &str = "ricochet-bench-row ";

/// Runs one scene in a fresh process (this executable, `bench SCENE --frames N`, with
/// [`CHILD_ENV`] set), so that its memory figures start from a clean heap; its progress goes
/// to this process's stderr, its row comes back as one JSON line on its stdout.
fn run_child(name: &str, frames: u64) -> anyhow::Result<Row> {
    let exe = std::env::current_exe().context("finding the ricochet executable")?;
    let output = std::process::Command::new(exe)
        .args(["bench", name, "--frames", &frames.to_string()])
        .env(CHILD_ENV, "1")
        .stdin(std::process::Stdio::null())
        .stderr(std::process::Stdio::inherit())
        .output()
        .with_context(|| format!("{name}: starting the benchmark process"))?;
    let stdout = String::from_utf8_lossy(&output.stdout);
    let Some(line) = stdout.lines().find_map(|l| l.strip_prefix(ROW_PREFIX)) else {
        bail!(
            "{name}: the benchmark process ended ({}) without a result",
            output.status
        );
    };
    serde_json::from_str(line).with_context(|| format!("{name}: reading the benchmark result"))
}
/// Exit code 2, after saying why, for a `--frames` of 0 or past [`MAX_FRAMES`] (`bench`
/// keeps every frame's timings, `bench --record` every frame's log).
pub fn bad_frames(frames: u64) -> anyhow::Result<Option<ExitCode>> {
    if frames == 0 {
        out::error("error: --frames must be at least 1");
        return Ok(Some(ExitCode::from(2)));
    }
    if frames > MAX_FRAMES {
        out::error(&format!(
            "error: --frames must be at most {MAX_FRAMES} (a scene keeps every frame's \
             timings, or with --record its log), got {frames}"
        ));
        return Ok(Some(ExitCode::from(2)));
    }
    Ok(None)
}

/// The named scenes (or `defaults`), parsed, or exit code 2 after saying why (an
/// unknown scene name, or a bad `--frames`).
fn parse_scenes(
    scenes: &[String],
    defaults: &[&str],
    frames: u64,
) -> anyhow::Result<Result<Vec<(String, Scene)>, ExitCode>> {
    let names: Vec<String> = if scenes.is_empty() {
        defaults.iter().map(|s| (*s).to_owned()).collect()
    } else {
        scenes.to_vec()
    };
    let mut parsed = Vec::new();
    for name in &names {
        match Scene::parse(name) {
            Ok(kind) => parsed.push((name.clone(), kind)),
            Err(e) => {
                out::error(&format!("error: {e:#}"));
                return Ok(Err(ExitCode::from(2)));
            }
        }
    }
    if let Some(code) = bad_frames(frames)? {
        return Ok(Err(code));
    }
    Ok(Ok(parsed))
}

/// Runs the named scenes (or [`DEFAULT_SCENES`]), `frames` timed frames each, prints the
/// table, writes the CSV. Each scene runs in its own process (see [`CHILD_ENV`]). Exit code
/// 0 when every scene's contact sets agree with both rapier's and Box2D's, 1 when one does
/// not, 2 for an unknown scene name, a count past [`ricochet_scenes::bench::MAX_COUNT`], or a
/// frame count of 0 or past [`MAX_FRAMES`].
pub fn run(scenes: &[String], frames: u64, csv: Option<&Path>) -> anyhow::Result<ExitCode> {
    let parsed = match parse_scenes(scenes, &DEFAULT_SCENES, frames)? {
        Ok(parsed) => parsed,
        Err(code) => return Ok(code),
    };
    if let Some(path) = csv {
        files::check_writable(path)?;
    }
    let in_process = std::env::var_os(CHILD_ENV).is_some();
    let mut rows = Vec::new();
    for (name, kind) in &parsed {
        if in_process {
            let row = run_scene(name, *kind, frames, |note| {
                // Progress only: a lost line must not stop the measurement.
                let _ = out::note(&format!("bench: {note}"));
            })?;
            out::print(&format!("{ROW_PREFIX}{}\n", serde_json::to_string(&row)?))?;
            rows.push(row);
        } else {
            let row = run_child(name, frames)?;
            out::eprint(&report::scene_summary(&row))?;
            rows.push(row);
        }
    }
    let agree = rows.iter().all(Row::agrees);
    if in_process {
        return Ok(ExitCode::from(if agree { 0 } else { 1 }));
    }
    out::print(&format!("{}{}\n", report::table(&rows), report::NOTES))?;
    if let Some(path) = csv {
        files::write(path, report::csv_text(&rows).as_bytes())?;
    }
    Ok(ExitCode::from(if agree { 0 } else { 1 }))
}

/// `bench --queries`: the named scenes (or [`DEFAULT_SCENES`]) stepped `frames` frames, then
/// the same seeded rays and boxes asked of Ricochet, rapier and Box2D in this process
/// ([`ricochet_study::bench::queries`]); prints the table. Exit code 0 when every answer
/// agrees, 1 when one does not, 2 for a bad scene name or frame count.
pub fn run_queries(scenes: &[String], frames: u64) -> anyhow::Result<ExitCode> {
    let parsed = match parse_scenes(scenes, &DEFAULT_SCENES, frames)? {
        Ok(parsed) => parsed,
        Err(code) => return Ok(code),
    };
    let mut rows = Vec::new();
    for (name, kind) in &parsed {
        let _ = out::note(&format!("bench --queries: {name}"));
        rows.push(queries::run_queries(name, *kind, frames)?);
    }
    out::print(&format!("{}{}\n", queries::table(&rows), queries::NOTES))?;
    let agree = rows
        .iter()
        .all(|r| r.ray_differences == [0, 0] && r.overlap_differences == [0, 0]);
    Ok(ExitCode::from(if agree { 0 } else { 1 }))
}

/// `bench --snapshots`: the named scenes (or asteroids-75 and asteroids-10000) snapshotted
/// at frame `frames` ([`ricochet_study::bench::snapshots`]); prints the table. Exit code 0,
/// 2 for a bad scene name or frame count.
pub fn run_snapshots(scenes: &[String], frames: u64) -> anyhow::Result<ExitCode> {
    let parsed = match parse_scenes(scenes, &["asteroids-75", "asteroids-10000"], frames)? {
        Ok(parsed) => parsed,
        Err(code) => return Ok(code),
    };
    let mut rows = Vec::new();
    for (name, kind) in &parsed {
        let _ = out::note(&format!("bench --snapshots: {name}"));
        rows.push(snapshots::run_snapshots(name, *kind, frames)?);
    }
    out::print(&format!(
        "{}{}\n",
        snapshots::table(&rows),
        snapshots::NOTES
    ))?;
    Ok(ExitCode::SUCCESS)
}

/// `bench --broad-phases`: every broad phase on the named scenes (or
/// [`broad_phases::DEFAULT_SCENES`]), `frames` timed frames each
/// ([`ricochet_study::bench::broad_phases`]); prints the tables. Exit code 0, 1 when two
/// broad phases disagree on the pairs (an error), 2 for a bad scene name or frame count.
pub fn run_broad_phases(scenes: &[String], frames: u64) -> anyhow::Result<ExitCode> {
    let parsed = match parse_scenes(scenes, &broad_phases::DEFAULT_SCENES, frames)? {
        Ok(parsed) => parsed,
        Err(code) => return Ok(code),
    };
    let mut rows = Vec::new();
    for (name, kind) in &parsed {
        let row = broad_phases::run_broad_phases(name, *kind, frames, |note| {
            let _ = out::note(&format!("bench --broad-phases: {note}"));
        })?;
        rows.push(row);
    }
    out::print(&format!(
        "{}{}\n",
        broad_phases::table(&rows),
        broad_phases::NOTES
    ))?;
    Ok(ExitCode::SUCCESS)
}
