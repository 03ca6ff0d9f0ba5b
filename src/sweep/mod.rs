//! `ricochet sweep`: run time against error for the user's own scenario. Each `--set` gives
//! a key of the scenario file and values ([`set`]); their cross product is run, each
//! combination written into the file's text and loaded like any scenario file (built when
//! it runs, never all ahead; at most [`MAX_COMBINATIONS`]), against one reference run.
//! [`trace`] steps a run, [`compare`] steps it beside a run of the reference and [`error`]
//! measures it as both go (nothing kept per frame), [`report`] prints and writes the
//! result. Frame counts keep their time in seconds when the timestep changes, and runs are
//! compared at the times both reach ([`time`]).
//!
//! `--cluster` runs each combination, and the reference, as an item process (`--item`,
//! [`item`]) on a Dask cluster, like `ricochet test --cluster`; the rows come back in any
//! order and are put in combination order here. An item runs the reference beside its
//! combination, untimed, as a local sweep does; the reference's own item gives its step
//! time, digest and drift.

mod compare;
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
use compare::Stopped;
use item::Which;
use set::{Setting, Sweep, Target};
use time::Ratio;
use trace::Overflow;

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

/// The most combinations a sweep runs: each is a run of the scenario beside a run of the
/// reference, and its row (about half a kilobyte) is kept for the table, the CSV and the
/// chart, so 100,000 rows are some 50 MB and, at a millisecond a run, minutes of work.
pub const MAX_COMBINATIONS: u64 = 100_000;

/// How many combinations the sweeps cross to, if at most [`MAX_COMBINATIONS`].
fn count(sweeps: &[Sweep]) -> Result<usize, String> {
    let n = sweeps
        .iter()
        .try_fold(1u64, |n, s| n.checked_mul(s.values.len() as u64));
    match n {
        Some(n) if n <= MAX_COMBINATIONS => Ok(usize::try_from(n).unwrap_or(usize::MAX)),
        _ => {
            let sizes: Vec<String> = sweeps.iter().map(|s| s.values.len().to_string()).collect();
            Err(format!(
                "too many combinations: {} = {}, more than the {MAX_COMBINATIONS} a sweep runs; \
                 sweep fewer values (shards split a sweep's runs, not this limit)",
                sizes.join(" × "),
                n.map_or_else(|| "more than 2^64".to_owned(), |n| n.to_string())
            ))
        }
    }
}

/// Combination `index`'s value of each sweep (the first `--set` outermost, the last
/// changing fastest).
fn combination(sweeps: &[Sweep], mut index: usize) -> Vec<usize> {
    let mut digits = vec![0; sweeps.len()];
    for (d, s) in digits.iter_mut().zip(sweeps).rev() {
        *d = index % s.values.len();
        index /= s.values.len();
    }
    digits
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

    let total = match count(&sweeps) {
        Ok(n) => n,
        Err(e) => return Ok(bad(&format!("--set: {e}"))),
    };
    // Each value is checked alone (the file's own for the other keys) before anything
    // runs, so a bad value fails at once; a combination is built only when it runs.
    for s in &sweeps {
        for v in &s.values {
            if let Err(e) = variant(&text, &file, file_dt, &[(&s.target, v)]) {
                return Ok(bad(&format!("with {}: {e}", label(&[(s, v)]))));
            }
        }
    }
    let values_of = |index: usize| -> Vec<(&Sweep, &Setting)> {
        sweeps
            .iter()
            .zip(combination(&sweeps, index))
            .map(|(s, i)| (s, &s.values[i]))
            .collect()
    };
    let texts_of = |index: usize| -> Vec<String> {
        values_of(index)
            .iter()
            .map(|(_, v)| v.text().to_owned())
            .collect()
    };
    let runs: Vec<usize> = (0..total)
        .filter(|i| shard.is_none_or(|(k, n)| i % n == k))
        .collect();
    let measure_row = |index: usize| -> Result<report::Row, Failed> {
        let values = values_of(index);
        let targets: Vec<(&Target, &Setting)> =
            values.iter().map(|(s, v)| (&s.target, *v)).collect();
        let v = variant(&text, &file, file_dt, &targets)
            .map_err(|e| Failed::Bad(format!("with {}: {e}", label(&values))))?;
        let measured = compare::measure(
            &v.scenario,
            v.dt,
            &reference.scenario,
            reference.dt,
            v.scenario.world.bounds.as_ref(),
        );
        let (error, digest, overflow) = match measured {
            Ok(m) => (m.error, m.digest, None),
            Err(Stopped::Run(o)) => (error::Measures::default(), 0, Some(o)),
            Err(Stopped::Reference(o)) => return Err(Failed::Reference(o)),
        };
        // An overflowed run is not measured, so not timed either.
        let step_seconds = match overflow {
            None => trace::time(&v.scenario, args.repeat),
            Some(_) => f64::NAN,
        };
        Ok(report::Row {
            index,
            values: texts_of(index),
            dt: v.dt,
            frames: v.scenario.frames,
            rounded: v.rounded,
            step_seconds,
            digest,
            error,
            overflow,
        })
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
    let reference_row = || {
        let (error, digest, overflow, step_seconds) = match compare::alone(&reference.scenario) {
            Ok(m) => (
                m.error,
                m.digest,
                None,
                trace::time(&reference.scenario, args.repeat),
            ),
            Err(o) => (error::Measures::default(), 0, Some(o), f64::NAN),
        };
        report::Row {
            index: 0,
            values: reference_values_text.clone(),
            dt: reference.dt,
            frames: reference.scenario.frames,
            rounded: reference.rounded,
            step_seconds,
            digest,
            error,
            overflow,
        }
    };
    let reference_overflowed = |o: &Overflow| {
        out::error(&format!(
            "error: the reference ({reference_label}): frame {}: {}; the simulation \
             overflowed: there is nothing to measure against, nothing was written",
            o.frame, o.what
        ));
        ExitCode::from(1)
    };

    if let Some(which) = args.item {
        return match which {
            Which::Reference => {
                item::print(true, reference_row())?;
                Ok(ExitCode::SUCCESS)
            }
            Which::Combination(i) if i < total => match measure_row(i) {
                Ok(row) => {
                    item::print(false, row)?;
                    Ok(ExitCode::SUCCESS)
                }
                Err(Failed::Bad(e)) => Ok(bad(&e)),
                Err(Failed::Reference(o)) => Ok(reference_overflowed(&o)),
            },
            Which::Combination(i) => Ok(bad(&format!(
                "--item {i}: the sweep has {total} combinations (0 to {})",
                total.saturating_sub(1)
            ))),
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
    // Before any run: a device, one file named twice, or the scenario itself is bad input.
    if let Err(e) = files::check_outputs(&[("--csv", &csv), ("--svg", &svg)], &[&args.scenario]) {
        return Ok(bad(&format!("{e:#}")));
    }

    let (reference_row, rows) = match &args.cluster {
        Some(scheduler) => {
            let cluster = Cluster {
                verify: args.verify,
                ..Cluster::new(scheduler.clone())
            };
            let named: Vec<(usize, Vec<String>)> = runs.iter().map(|&i| (i, texts_of(i))).collect();
            match on_cluster(args, &keys, &cluster, &named) {
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
            let reference_row = reference_row();
            if let Some(o) = &reference_row.overflow {
                bar.finish_and_clear();
                return Ok(reference_overflowed(o));
            }
            bar.inc(1);
            let mut rows = Vec::with_capacity(runs.len());
            for &index in &runs {
                bar.set_message(label(&values_of(index)));
                match measure_row(index) {
                    Ok(row) => rows.push(row),
                    Err(failed) => {
                        bar.finish_and_clear();
                        return Ok(match failed {
                            Failed::Bad(e) => bad(&e),
                            Failed::Reference(o) => reference_overflowed(&o),
                        });
                    }
                }
                bar.inc(1);
            }
            bar.finish_and_clear();
            (reference_row, rows)
        }
    };
    if let Some(o) = &reference_row.overflow {
        return Ok(reference_overflowed(o));
    }

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
    // As `run` and `test`: an overflow fails the command (exit code 1), after the rows
    // that were measured are written.
    let mut overflowed = false;
    for r in &rows {
        if let Some(o) = &r.overflow {
            overflowed = true;
            let values: Vec<String> = keys
                .iter()
                .zip(&r.values)
                .map(|(k, v)| format!("{k}={v}"))
                .collect();
            out::error(&format!(
                "error: with {}: frame {}: {}; the simulation overflowed, not measured",
                values.join(" "),
                o.frame,
                out::escape_controls(&o.what)
            ));
        }
    }
    Ok(if overflowed {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    })
}

/// Why a combination's row could not be made.
enum Failed {
    /// Its scenario does not load (bad input: exit code 2).
    Bad(String),
    /// The reference overflowed beside it.
    Reference(Overflow),
}

/// The sweep's runs as items on the cluster: the reference, then each combination of
/// `runs` (this shard's). Returns the reference's row and the combinations' rows in
/// combination order; `None` when an item failed or `--verify` caught a disagreement
/// (printed, one line each, naming the item and the workers).
fn on_cluster(
    args: &Args,
    keys: &[String],
    cluster: &Cluster,
    runs: &[(usize, Vec<String>)],
) -> Result<Option<(report::Row, Vec<report::Row>)>, cluster::ClusterError> {
    let which = |i: usize| match i {
        0 => Which::Reference,
        _ => Which::Combination(runs[i - 1].0),
    };
    // Every value as `--flag=VALUE` and the scenario after `--`: a path or a value that
    // starts with `-` is still a value on the worker.
    let argv = |i: usize| {
        let mut a: Vec<std::ffi::OsString> = vec!["sweep".into()];
        for s in &args.set {
            a.push(format!("--set={s}").into());
        }
        for r in &args.reference {
            a.push(format!("--reference={r}").into());
        }
        a.extend([
            format!("--repeat={}", args.repeat).into(),
            format!("--item={}", which(i)).into(),
            "--".into(),
            args.scenario.clone().into_os_string(),
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
