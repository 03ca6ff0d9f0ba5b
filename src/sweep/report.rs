//! What a sweep prints and writes: the table, the CSV (one row per combination), the chart
//! (the accuracy study's log-log chart, [`ricochet_study::accuracy::chart`]) and the
//! one-line summary.

use std::fmt::Write as _;

use ricochet_study::accuracy::chart::{Dash, LogLog, Series, build, draw};
use serde::{Deserialize, Serialize};

use super::error::Measures;
use super::time::Ratio;
use super::trace::Overflow;

/// One run of the sweep, measured (also the `row` of `sweep --item`'s line, `item.rs`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Row {
    /// Its index among all the sweep's combinations (the same in every shard).
    pub index: usize,
    /// Each `--set` key's value for it, as written, in the order of the keys.
    pub values: Vec<String>,
    /// Its timestep.
    #[serde(with = "super::item::ratio")]
    pub dt: Ratio,
    /// Steps after frame 0.
    pub frames: u64,
    /// Frame counts of the file that did not rescale to a whole frame (rounded).
    pub rounded: u64,
    /// Median wall seconds per step; NaN when not timed (`--repeat 0`).
    #[serde(with = "super::item::exact")]
    pub step_seconds: f64,
    /// The final [`ricochet_sim::World::digest`].
    #[serde(with = "super::item::hex")]
    pub digest: u64,
    /// Its error against the reference (nothing when it overflowed).
    pub error: Measures,
    /// Where it overflowed, if it did: then it was stopped there and not measured.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub overflow: Option<Overflow>,
}

impl Row {
    /// Wall seconds per simulated second: comparable across timesteps.
    #[must_use]
    pub fn wall_per_second(&self) -> f64 {
        self.step_seconds / self.dt.seconds()
    }
}

/// The CSV's columns after the keys'.
const COLUMNS: &str = "dt,frames,frames_rounded,step_us,wall_per_sim_s,digest,matched_frames,\
position_max,position_rms,worst_body,bodies_unmatched,energy_drift,energy_error,touch_appear,touch_vanish,\
touch_moved,false_positive_contacts,false_negative_contacts,overflowed_at_frame";

fn field(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_owned()
    }
}

/// The CSV: a header, then one row per combination, in index order.
#[must_use]
pub fn csv_text(keys: &[String], rows: &[Row]) -> String {
    let mut s = String::from("index");
    for k in keys {
        s.push(',');
        s.push_str(&field(k));
    }
    let _ = writeln!(s, ",{COLUMNS}");
    for r in rows {
        let e = &r.error;
        let _ = write!(s, "{}", r.index);
        for v in &r.values {
            let _ = write!(s, ",{}", field(v));
        }
        if let Some(o) = &r.overflow {
            // Not measured: no step time, digest or error, only where it stopped.
            let _ = writeln!(
                s,
                ",{},{},{},{}{}",
                r.dt,
                r.frames,
                r.rounded,
                ",".repeat(15),
                o.frame
            );
            continue;
        }
        // Not timed (`--repeat 0`): empty, so the file is the same bytes on every run.
        let (step, wall) = if r.step_seconds.is_nan() {
            (String::new(), String::new())
        } else {
            (
                format!("{:.3}", r.step_seconds * 1e6),
                format!("{:e}", r.wall_per_second()),
            )
        };
        let _ = writeln!(
            s,
            ",{},{},{},{step},{wall},{:016x},{},{:e},{:e},{},{},{:e},{:e},{},{},{},{},{}",
            r.dt,
            r.frames,
            r.rounded,
            r.digest,
            e.matched_frames,
            e.position_max,
            e.position_rms,
            field(&e.worst_body),
            e.bodies_unmatched,
            e.energy_drift,
            e.energy_error,
            e.events_appear,
            e.events_vanish,
            e.events_moved,
            e.false_positives,
            e.false_negatives,
        );
        // The empty last column: it did not overflow.
        s.insert(s.len() - 1, ',');
    }
    s
}

/// The table printed on stdout: the reference, then each run.
#[must_use]
pub fn table(keys: &[String], reference: &Row, rows: &[Row]) -> String {
    let mut s = String::new();
    let label = |r: &Row| {
        keys.iter()
            .zip(&r.values)
            .map(|(k, v)| format!("{k}={v}"))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let width = rows
        .iter()
        .map(|r| label(r).len())
        .chain([label(reference).len(), 9])
        .max()
        .unwrap_or(9);
    let _ = writeln!(
        s,
        "{:width$}  {:>9}  {:>10}  {:>10}  {:>9}  {:>10}  {:>10}  {:>11}  {:>11}  {:>16}",
        "run",
        "µs/step",
        "pos max",
        "pos rms",
        "unmatched",
        "energy err",
        "drift",
        "touch +/-/~",
        "contact +/-",
        "digest"
    );
    let line = |s: &mut String, name: &str, r: &Row, reference: bool| {
        let e = &r.error;
        if let Some(o) = &r.overflow {
            let _ = writeln!(
                s,
                "{name:width$}  overflowed at frame {}, not measured: {}",
                o.frame,
                crate::out::escape_controls(&o.what)
            );
            return;
        }
        let step = if r.step_seconds.is_nan() {
            "-".to_owned()
        } else {
            format!("{:.2}", r.step_seconds * 1e6)
        };
        let (err, touches, contacts) = if reference {
            (
                [
                    "-".to_owned(),
                    "-".to_owned(),
                    "-".to_owned(),
                    "-".to_owned(),
                ],
                "-".to_owned(),
                "-".to_owned(),
            )
        } else {
            (
                [
                    format!("{:.3e}", e.position_max),
                    format!("{:.3e}", e.position_rms),
                    e.bodies_unmatched.to_string(),
                    format!("{:.3e}", e.energy_error),
                ],
                format!("{}/{}/{}", e.events_appear, e.events_vanish, e.events_moved),
                format!("{}/{}", e.false_positives, e.false_negatives),
            )
        };
        let _ = writeln!(
            s,
            "{name:width$}  {step:>9}  {:>10}  {:>10}  {:>9}  {:>10}  {:>10.3e}  {touches:>11}  \
             {contacts:>11}  {:016x}",
            err[0], err[1], err[2], err[3], e.energy_drift, r.digest
        );
    };
    line(
        &mut s,
        &format!("reference {}", label(reference)),
        reference,
        true,
    );
    for r in rows {
        line(&mut s, &label(r), r, false);
    }
    s.push_str(
        "pos: named moving bodies' position error (units) at the times both runs reach; \
         unmatched: named body-frames alive in one run only; energy err: largest |E - E_ref|; drift: E(end) - E(0); touch +/-/~: touch events \
         that appear, vanish, move frames; contact +/-: pair-frames in contact only in this \
         run (false positives) / only in the reference (false negatives)\n",
    );
    s
}

/// A measure the chart draws: its legend, its dash, how to read it.
type Measure = (&'static str, Dash, fn(&Measures) -> f64);

/// The chart: for each combination of the keys other than the timestep, its largest
/// position error and its energy error against wall seconds per simulated second, one
/// point per timestep; and false contacts when any run has some.
#[must_use]
pub fn svg_text(
    scenario: &str,
    keys: &[String],
    timestep_key: Option<usize>,
    rows: &[Row],
) -> String {
    // Groups in first-seen order: the runs that differ only in their timestep.
    let mut groups: Vec<(String, Vec<&Row>)> = Vec::new();
    let overflowed = rows.iter().filter(|r| r.overflow.is_some()).count();
    let rows: Vec<&Row> = rows.iter().filter(|r| r.overflow.is_none()).collect();
    for &r in &rows {
        let name = keys
            .iter()
            .zip(&r.values)
            .enumerate()
            .filter(|(i, _)| Some(*i) != timestep_key)
            .map(|(_, (k, v))| format!("{k}={v}"))
            .collect::<Vec<_>>()
            .join(" ");
        match groups.iter_mut().find(|(n, _)| *n == name) {
            Some((_, g)) => g.push(r),
            None => groups.push((name, vec![r])),
        }
    }
    let any_false = rows
        .iter()
        .any(|r| r.error.false_positives + r.error.false_negatives > 0);
    // Without step times (`--repeat 0`) the cost axis is the steps per simulated second,
    // which the same run gives on any machine.
    let timed = rows.iter().all(|r| !r.step_seconds.is_nan());
    let cost = |r: &Row| {
        if timed {
            r.wall_per_second()
        } else {
            1.0 / r.dt.seconds()
        }
    };
    let mut series = Vec::new();
    for (name, group) in &groups {
        let mut group = group.clone();
        group.sort_by(|a, b| b.dt.seconds().total_cmp(&a.dt.seconds()));
        let prefix = if name.is_empty() {
            String::new()
        } else {
            format!("{name}: ")
        };
        let measures: [Measure; 3] = [
            ("position max (units)", Dash::Solid, |m| m.position_max),
            ("energy error", Dash::Long, |m| m.energy_error),
            ("false contacts (pair-frames)", Dash::Dotted, |m| {
                (m.false_positives + m.false_negatives) as f64
            }),
        ];
        for (what, dash, get) in measures {
            if dash == Dash::Dotted && !any_false {
                continue;
            }
            series.push(Series {
                legend: format!("{prefix}{what}"),
                dash,
                points: group.iter().map(|r| (cost(r), get(&r.error))).collect(),
                open: Vec::new(),
            });
        }
    }
    let shown = series.len().min(24);
    let mut notes = vec![
        "Points of one line: its timesteps, joined coarsest to finest.".to_owned(),
        "Errors against the reference run, at the times both reach.".to_owned(),
        "Errors of exactly 0 sit on the bottom line.".to_owned(),
    ];
    if overflowed > 0 {
        notes.push(format!(
            "{overflowed} runs overflowed: not measured, not drawn (see the CSV)."
        ));
    }
    if shown < series.len() {
        notes.push(format!(
            "The first {shown} of {} lines; all are in the CSV.",
            series.len()
        ));
        series.truncate(shown);
    }
    draw(&LogLog {
        title: format!(
            "ricochet sweep {scenario}: error against run time ({} build)",
            build()
        ),
        x_label: if timed {
            "wall seconds per simulated second (log scale)"
        } else {
            "steps per simulated second (log scale; not timed, --repeat 0)"
        }
        .to_owned(),
        y_label: "error against the reference run (log scale)".to_owned(),
        series,
        notes,
    })
}

/// The one-line summary: the largest position error and the most false contacts, with the
/// runs that have them, and the fastest step.
#[must_use]
pub fn summary(rows: &[Row], keys: &[String], shard: Option<(usize, usize)>) -> String {
    let label = |r: &Row| {
        keys.iter()
            .zip(&r.values)
            .map(|(k, v)| format!("{k}={v}"))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let mut s = format!("sweep: {} runs", rows.len());
    if let Some((k, n)) = shard {
        let _ = write!(s, " (shard {k}/{n})");
    }
    let overflowed: Vec<&Row> = rows.iter().filter(|r| r.overflow.is_some()).collect();
    let rows: Vec<&Row> = rows.iter().filter(|r| r.overflow.is_none()).collect();
    let worst = rows
        .iter()
        .filter(|r| r.error.position_max != 0.0)
        .max_by(|a, b| a.error.position_max.total_cmp(&b.error.position_max));
    match worst {
        Some(w) => {
            let _ = write!(
                s,
                "; largest position error {:.3e} ({}, {})",
                w.error.position_max,
                w.error.worst_body,
                label(w)
            );
        }
        None => s.push_str("; no position error"),
    }
    let false_contacts = |r: &Row| r.error.false_positives + r.error.false_negatives;
    match rows
        .iter()
        .filter(|r| false_contacts(r) > 0)
        .max_by_key(|r| false_contacts(r))
    {
        Some(f) => {
            let _ = write!(
                s,
                "; most false contacts {} + {} ({})",
                f.error.false_positives,
                f.error.false_negatives,
                label(f)
            );
        }
        None => s.push_str("; no false contact"),
    }
    if let Some(f) = rows
        .iter()
        .filter(|r| !r.step_seconds.is_nan())
        .min_by(|a, b| a.wall_per_second().total_cmp(&b.wall_per_second()))
    {
        let _ = write!(
            s,
            "; fastest {:.2} µs/step ({})",
            f.step_seconds * 1e6,
            label(f)
        );
    }
    if let (Some(first), n) = (overflowed.first(), overflowed.len()) {
        let frame = first.overflow.as_ref().map_or(0, |o| o.frame);
        let _ = write!(
            s,
            "; {n} overflowed, not measured (first: {} at frame {frame})",
            label(first)
        );
    }
    s
}
