//! `ricochet sweep`: run time against error for the user's own scenario. Each `--set` gives
//! a key of the scenario file and values ([`set`]); their cross product is run, each
//! combination written into the file's text and loaded like any scenario file, against one
//! reference run; [`trace`] steps a run, [`error`] measures it against the reference,
//! [`report`] prints and writes the result. Frame counts keep their time in seconds when
//! the timestep changes, and runs are compared at the times both reach ([`time`]).
//!
//! `--cluster` runs each combination, and the reference, as an item process (`--item`,
//! [`item`]) on a Dask cluster, like `ricochet test --cluster`; the rows come back in any
//! order and are put in combination order here. An item measures against the reference, so
//! each combination's item runs the reference again, untimed: the reference's trace (every
//! frame's positions, energy and contacts) would otherwise have to travel between workers
//! in a format of its own, and it costs one untimed run per combination. The reference's
//! own item gives its step time and digest.

mod error;
mod item;
mod report;
mod set;
mod shape;
mod time;
mod trace;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use ricochet_sim::{Scenario, load_scenario};
use toml_edit::DocumentMut;

use crate::suite::cluster::{self, Cluster, Returned};
use crate::{files, out};
use item::Which;
use set::{Setting, Sweep, Target};
use time::Ratio;

/// `ricochet sweep`'s arguments.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The scenario file (TOML).
    pub scenario: PathBuf,
    /// A key of the scenario file and the values to run it with, comma-separated; repeat
    /// `--set` to cross several keys (every combination runs). Keys: world.dt (or world.hz),
    /// frames, world.FIELD (world.gravity.y: .x/.y pick a component), templates.NAME.FIELD,
    /// bodies.NAME.FIELD (every body of that name), e.g. templates.enemy.controller.speed.
    /// Values: numbers or fractions (1/60); a shape takes circle:R, aabb:HX HY, obb:HX HY,
    /// capsule:R;AX AY;BX BY, polygon:X1 Y1;X2 Y2;... or `file` (the file's own). Frame
    /// counts in the file (frames, script frames, lifetimes, sleep_after) are rescaled to
    /// keep their time in seconds at another dt.
    #[arg(long = "set", value_name = "KEY=V1,V2,…", required = true)]
    pub set: Vec<String>,
    /// The reference run's value of a key (repeatable). Default: the file as written, at
    /// the smallest dt swept.
    #[arg(long, value_name = "KEY=V")]
    pub reference: Vec<String>,
    /// Where to write the CSV (one row per combination). Default: SCENARIO.sweep.csv in
    /// the current directory (SCENARIO.sweep-KofN.csv for a shard).
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Where to write the chart. Default: beside the CSV, .svg.
    #[arg(long, value_name = "FILE")]
    pub svg: Option<PathBuf>,
    /// Run only the K-th of N slices of the combinations (K from 0): combination i is in
    /// shard i mod N. Each shard runs the reference itself; the CSV's `index` column puts
    /// the shards' rows back in order.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<String>,
    /// Timed runs per combination; the step time is their median. 0: no timing (the
    /// step-time columns are empty and the chart's x axis is steps per simulated second),
    /// so the CSV and SVG are the same bytes on every run, machine or cluster.
    #[arg(long, default_value_t = 3, value_name = "N",
          value_parser = clap::value_parser!(u32).range(0..=100))]
    pub repeat: u32,
    /// Run the combinations (and the reference) on this Dask distributed cluster's workers
    /// (tcp://HOST:PORT of its scheduler), one item each, like `ricochet test --cluster`;
    /// needs `pip install ./python` (docs/suites.md). The rows are merged in combination
    /// order: the same CSV and SVG as a local run (step times aside).
    #[arg(long, value_name = "tcp://HOST:PORT", conflicts_with = "item")]
    pub cluster: Option<String>,
    /// With --cluster: re-run one item in ten on a second worker and fail (exit code 1,
    /// nothing written) if any digests differ, naming both workers.
    #[arg(long, requires = "cluster")]
    pub verify: bool,
    /// Run one combination (its index, from 0) or `reference`, and print its row as one
    /// JSON line (docs/suites.md): what a cluster worker runs.
    #[arg(long, value_name = "N|reference", hide = true,
          conflicts_with_all = ["csv", "svg", "shard"])]
    pub item: Option<Which>,
}

/// Bad input: printed, exit code 2.
fn bad(message: &str) -> ExitCode {
    out::error(&format!("error: {message}"));
    ExitCode::from(2)
}

fn parse_shard(text: &str) -> Option<(usize, usize)> {
    let (k, n) = text.split_once('/')?;
    let (k, n) = (k.trim().parse().ok()?, n.trim().parse().ok()?);
    (k < n).then_some((k, n))
}

/// One combination: the scenario with its values written in, and its timestep.
struct Variant {
    scenario: Scenario,
    dt: Ratio,
    rounded: u64,
}

/// Writes `values` into the file's text, rescales its frame counts, and loads it.
fn variant(
    text: &str,
    file: &str,
    file_dt: Option<Ratio>,
    values: &[(&Target, &Setting)],
) -> Result<Variant, String> {
    let mut doc: DocumentMut = text.parse().map_err(|e| format!("{file}: {e}"))?;
    let mut dt = file_dt;
    for (target, value) in values {
        set::apply(&mut doc, target, value)?;
        if let Setting::Timestep { dt: d, .. } = value {
            dt = Some(*d);
        }
    }
    let (Some(dt), Some(file_dt)) = (dt, file_dt) else {
        return Err(format!(
            "{file}: its dt is not a fraction of a second with a denominator up to \
             1,000,000: sweep world.dt with values that are"
        ));
    };
    let rounded = set::rescale_frames(&mut doc, file_dt.over(dt));
    let scenario = load_scenario(&doc.to_string(), file).map_err(|e| e.to_string())?;
    Ok(Variant {
        scenario,
        dt,
        rounded,
    })
}

fn label(values: &[(&Sweep, &Setting)]) -> String {
    values
        .iter()
        .map(|(s, v)| format!("{}={}", s.key, v.text()))
        .collect::<Vec<_>>()
        .join(" ")
}

/// Every combination of the sweeps' values, the first `--set` outermost.
fn combinations(sweeps: &[Sweep]) -> Vec<Vec<usize>> {
    let mut all = vec![Vec::new()];
    for s in sweeps {
        all = all
            .into_iter()
            .flat_map(|c: Vec<usize>| {
                (0..s.values.len()).map(move |i| {
                    let mut c = c.clone();
                    c.push(i);
                    c
                })
            })
            .collect();
    }
    all
}

fn default_path(scenario: &Path, shard: Option<(usize, usize)>, ext: &str) -> PathBuf {
    let stem = scenario.file_stem().map_or_else(
        || "scenario".to_owned(),
        |s| s.to_string_lossy().into_owned(),
    );
    match shard {
        Some((k, n)) => PathBuf::from(format!("{stem}.sweep-{k}of{n}.{ext}")),
        None => PathBuf::from(format!("{stem}.sweep.{ext}")),
    }
}

/// Runs the sweep.
pub fn run(args: &Args) -> anyhow::Result<ExitCode> {
    let file = args.scenario.display().to_string();
    let text = match std::fs::read_to_string(&args.scenario) {
        Ok(t) => t,
        Err(e) => return Ok(bad(&format!("{file}: {e}"))),
    };
    let original = match load_scenario(&text, &file) {
        Ok(s) => s,
        Err(e) => return Ok(bad(&e.to_string())),
    };
    let file_dt = Ratio::of(original.world.dt);
    let shard = match args.shard.as_deref().map(|s| (s, parse_shard(s))) {
        None => None,
        Some((_, Some(kn))) => Some(kn),
        Some((s, None)) => {
            return Ok(bad(&format!(
                "--shard {s}: write K/N with 0 <= K < N (0/3, 1/3, 2/3)"
            )));
        }
    };
    let mut sweeps = Vec::new();
    for arg in &args.set {
        match set::parse(arg) {
            Ok(s) => sweeps.push(s),
            Err(e) => return Ok(bad(&format!("--set {arg}: {e}"))),
        }
    }
    let mut reference_sets = Vec::new();
    for arg in &args.reference {
        match set::parse(arg) {
            Ok(s) if s.values.len() == 1 => reference_sets.push(s),
            Ok(_) => return Ok(bad(&format!("--reference {arg}: give one value"))),
            Err(e) => return Ok(bad(&format!("--reference {arg}: {e}"))),
        }
    }
    let keys: Vec<String> = sweeps.iter().map(|s| s.key.clone()).collect();
    let timestep_key = sweeps.iter().position(|s| s.target == Target::Timestep);

    // The reference: the file, at the finest dt swept, then the --reference values.
    let finest = sweeps
        .iter()
        .filter(|s| s.target == Target::Timestep)
        .flat_map(|s| &s.values)
        .min_by(|a, b| match (a, b) {
            (Setting::Timestep { dt: x, .. }, Setting::Timestep { dt: y, .. }) => {
                x.seconds().total_cmp(&y.seconds())
            }
            _ => std::cmp::Ordering::Equal,
        });
    let mut reference_values: Vec<(&Target, &Setting)> = Vec::new();
    if let Some(f) = finest {
        reference_values.push((&Target::Timestep, f));
    }
    for s in &reference_sets {
        reference_values.push((&s.target, &s.values[0]));
    }
    let reference_label = reference_values
        .iter()
        .map(|(t, v)| {
            let key = match t {
                Target::Timestep => "world.dt".to_owned(),
                Target::Field(p) => p.join("."),
            };
            format!("{key}={}", v.text())
        })
        .collect::<Vec<_>>()
        .join(" ");
    let reference = match variant(&text, &file, file_dt, &reference_values) {
        Ok(v) => v,
        Err(e) => return Ok(bad(&format!("the reference ({reference_label}): {e}"))),
    };

    // Every combination is checked before anything runs: a bad value fails at once.
    let all = combinations(&sweeps);
    let mut runs = Vec::new();
    for (index, combo) in all.iter().enumerate() {
        let values: Vec<(&Sweep, &Setting)> = sweeps
            .iter()
            .zip(combo)
            .map(|(s, &i)| (s, &s.values[i]))
            .collect();
        let targets: Vec<(&Target, &Setting)> =
            values.iter().map(|(s, v)| (&s.target, *v)).collect();
        let v = match variant(&text, &file, file_dt, &targets) {
            Ok(v) => v,
            Err(e) => return Ok(bad(&format!("with {}: {e}", label(&values)))),
        };
        if shard.is_none_or(|(k, n)| index % n == k) {
            let texts = values.iter().map(|(_, v)| v.text().to_owned()).collect();
            runs.push((index, texts, v));
        }
    }
    let bounds = original.world.bounds;
    let row = |index, values, v: &Variant, t: &trace::Trace, r: &trace::Trace| report::Row {
        index,
        values,
        dt: v.dt,
        frames: v.scenario.frames,
        rounded: v.rounded,
        step_seconds: t.step_seconds,
        digest: t.digest,
        error: error::measure(t, r, v.scenario.world.bounds.as_ref()),
    };
    let reference_values_text: Vec<String> = sweeps
        .iter()
        .map(|s| {
            reference_values
                .iter()
                .rfind(|(t, _)| **t == s.target)
                .map_or("file", |(_, v)| v.text())
                .to_owned()
        })
        .collect();
    let reference_row = |t: &trace::Trace| report::Row {
        index: 0,
        values: reference_values_text.clone(),
        dt: reference.dt,
        frames: reference.scenario.frames,
        rounded: reference.rounded,
        step_seconds: t.step_seconds,
        digest: t.digest,
        error: error::measure(t, t, bounds.as_ref()),
    };

    if let Some(which) = args.item {
        return match which {
            Which::Reference => {
                let t = trace::run(&reference.scenario, reference.dt, args.repeat);
                item::print(true, reference_row(&t))?;
                Ok(ExitCode::SUCCESS)
            }
            Which::Combination(i) => {
                let Some((index, values, v)) = runs.into_iter().find(|r| r.0 == i) else {
                    return Ok(bad(&format!(
                        "--item {i}: the sweep has {} combinations (0 to {})",
                        all.len(),
                        all.len().saturating_sub(1)
                    )));
                };
                // Untimed: only its trace is needed, to measure against.
                let r = trace::run(&reference.scenario, reference.dt, 0);
                let t = trace::run(&v.scenario, v.dt, args.repeat);
                item::print(false, row(index, values, &v, &t, &r))?;
                Ok(ExitCode::SUCCESS)
            }
        };
    }

    let csv = args
        .csv
        .clone()
        .unwrap_or_else(|| default_path(&args.scenario, shard, "csv"));
    let svg = args
        .svg
        .clone()
        .unwrap_or_else(|| csv.with_extension("svg"));
    files::check_outputs(&[("--csv", &csv), ("--svg", &svg)], &[&args.scenario])?;

    let (reference_row, rows) = match &args.cluster {
        Some(scheduler) => {
            let cluster = Cluster {
                verify: args.verify,
                ..Cluster::new(scheduler.clone())
            };
            match on_cluster(args, &keys, &cluster, &runs) {
                Ok(Some(done)) => done,
                Ok(None) => return Ok(ExitCode::from(1)),
                Err(e) => {
                    out::error(&format!("error: {e}"));
                    return Ok(ExitCode::from(2));
                }
            }
        }
        None => {
            let bar = if std::io::IsTerminal::is_terminal(&std::io::stderr()) {
                ProgressBar::with_draw_target(
                    Some(runs.len() as u64 + 1),
                    ProgressDrawTarget::stderr(),
                )
            } else {
                ProgressBar::hidden()
            };
            bar.set_style(
                ProgressStyle::with_template("{bar:30} {pos}/{len} {msg}")
                    .context("progress bar template")?,
            );
            bar.set_message(format!("reference {reference_label}"));
            let ref_trace = trace::run(&reference.scenario, reference.dt, args.repeat);
            bar.inc(1);
            let mut rows = Vec::new();
            for (index, values, v) in runs {
                bar.set_message(
                    keys.iter()
                        .zip(&values)
                        .map(|(k, v)| format!("{k}={v}"))
                        .collect::<Vec<_>>()
                        .join(" "),
                );
                let t = trace::run(&v.scenario, v.dt, args.repeat);
                rows.push(row(index, values, &v, &t, &ref_trace));
                bar.inc(1);
            }
            bar.finish_and_clear();
            (reference_row(&ref_trace), rows)
        }
    };

    out::print(&report::table(&keys, &reference_row, &rows))?;
    files::write_all(&[
        (&csv, report::csv_text(&keys, &rows).as_bytes()),
        (
            &svg,
            report::svg_text(&file, &keys, timestep_key, &rows).as_bytes(),
        ),
    ])?;
    out::print(&format!(
        "{}; wrote {} and {}\n",
        report::summary(&rows, &keys, shard),
        csv.display(),
        svg.display()
    ))?;
    Ok(ExitCode::SUCCESS)
}

/// The sweep's runs as items on the cluster: the reference, then each combination of
/// `runs` (this shard's). Returns the reference's row and the combinations' rows in
/// combination order; `None` when an item failed or `--verify` caught a disagreement
/// (printed, one line each, naming the item and the workers).
fn on_cluster(
    args: &Args,
    keys: &[String],
    cluster: &Cluster,
    runs: &[(usize, Vec<String>, Variant)],
) -> Result<Option<(report::Row, Vec<report::Row>)>, cluster::ClusterError> {
    let which = |i: usize| match i {
        0 => Which::Reference,
        _ => Which::Combination(runs[i - 1].0),
    };
    let argv = |i: usize| {
        let mut a: Vec<std::ffi::OsString> =
            vec!["sweep".into(), args.scenario.clone().into_os_string()];
        for s in &args.set {
            a.extend(["--set".into(), s.into()]);
        }
        for r in &args.reference {
            a.extend(["--reference".into(), r.into()]);
        }
        a.extend([
            "--repeat".into(),
            args.repeat.to_string().into(),
            "--item".into(),
            which(i).to_string().into(),
        ]);
        a
    };
    let stop = std::sync::atomic::AtomicBool::new(false);
    let mut lines: Vec<Option<item::ItemLine>> = vec![None; runs.len() + 1];
    let mut failures = Vec::new();
    cluster::run(
        cluster,
        runs.len() + 1,
        &stop,
        argv,
        |i, returned: Returned<item::ItemLine>| {
            let name = match which(i) {
                Which::Reference => "the reference".to_owned(),
                Which::Combination(c) => {
                    let values = keys.iter().zip(&runs[i - 1].1);
                    let label: Vec<String> = values.map(|(k, v)| format!("{k}={v}")).collect();
                    format!("item {c} ({})", label.join(" "))
                }
            };
            match returned {
                Returned::Line(l) if l.reference == (i == 0) => lines[i] = Some(l),
                Returned::Line(_) => {
                    failures.push(format!("{name}: the worker returned another item's line"));
                }
                Returned::Unverified { why, .. } => {
                    failures.push(format!("{name}: --verify: {why}"))
                }
                Returned::Failed(why) => failures.push(format!("{name}: {why}")),
            }
        },
    )?;
    if !failures.is_empty() {
        for f in &failures {
            out::error(&format!("error: {}", out::escape_controls(f)));
        }
        out::error(&format!(
            "error: {} of {} items failed on the cluster; nothing was written",
            failures.len(),
            runs.len() + 1
        ));
        return Ok(None);
    }
    let mut rows = lines.into_iter().map(|l| l.map(|l| l.row));
    let Some(Some(reference)) = rows.next() else {
        return Ok(None);
    };
    Ok(Some((reference, rows.flatten().collect())))
}
