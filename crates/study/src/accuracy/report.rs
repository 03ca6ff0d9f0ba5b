//! The study as people read it: the tables `ricochet accuracy` prints, the acceptance
//! checks, and the CSV (one row per measured error).

use std::fmt::Write as _;

use ricochet_sim::SLOP;

use super::{OffsetResult, POSITION_TOLERANCE, Row, SpeedResult, series};

/// The CSV header, one row per [`Row`] below it.
pub const CSV_HEADER: &str = "scene,method,dt,substeps,error_kind,error,wall_s_per_sim_s";

/// What the error kinds of the table mean (docs/accuracy.md says more).
pub const KINDS: &str = "\
error kinds (against the exact answer; dt is the displayed frame's, sim dt = dt / substeps):
  position          projectile: |x - (x0 + v0 t + g t^2/2)| at t = 2 s, units.
                    spring, orbit: largest |x - x(t)| over the displayed frames, units.
  vs_recurrence     projectile: |x - semi-implicit-Euler recurrence|, units (rounding only).
  energy            spring, orbit: largest |E - E0| / E0, E = m v^2/2 + m w^2 x^2/2.
  landing_frame     drop: sim step of the first floor contact minus the exact step.
  rest_height       drop: largest |y - (floor top + half height)| after landing, units.
  wrong_first_hits  bullets: bullets (of 24) whose hits differ from the exact first hit.
  prescribed: force set every step from the exact solution (a set_force per frame);
  state: force -m w^2 x from the body's own position (a real spring / central force).
  ratio: previous row's error / this row's: 2 is first order, 4 second order.
";

/// The acceptance checks: (passed, what).
#[must_use]
pub fn checks(rows: &[Row], script_matches: bool) -> Vec<(bool, String)> {
    let mut out = Vec::new();
    let proj = series(rows, "projectile", "euler", "position");
    let ratios: Vec<f64> = proj.windows(2).map(|w| w[0].error / w[1].error).collect();
    out.push((
        !ratios.is_empty() && ratios.iter().all(|r| (1.9..=2.1).contains(r)),
        format!(
            "projectile position error halves when dt halves (first order): ratios {}",
            ratios
                .iter()
                .map(|r| format!("{r:.4}"))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    ));
    let drop_ok = rows
        .iter()
        .filter(|r| r.scene == "drop")
        .all(|r| match r.kind {
            "landing_frame" => r.error == 0.0,
            _ => r.error <= SLOP,
        });
    out.push((
        drop_ok,
        "drop: landing frame exact and rest height within SLOP = 1e-9, every dt and substep"
            .to_owned(),
    ));
    let swept_ok = rows
        .iter()
        .filter(|r| r.scene == "bullets" && r.method.starts_with("swept"))
        .all(|r| r.error == 0.0);
    out.push((
        swept_ok,
        "bullets: swept hits equal the exact first hits, every dt and substep".to_owned(),
    ));
    out.push((
        script_matches,
        "a script of set_force events gives the same bits as writing the force each step"
            .to_owned(),
    ));
    out
}

/// `1/60`.
fn per(hz: u32) -> String {
    format!("1/{hz}")
}

/// An error for people: `0`, or three significant digits.
fn sci(x: f64) -> String {
    if x == 0.0 {
        "0".to_owned()
    } else {
        format!("{x:.2e}")
    }
}

/// The table of every row, with the ratio to the previous row of its series.
#[must_use]
pub fn table(rows: &[Row]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{:<11} {:<20} {:>7} {:>8} {:>8} {:<17} {:>10} {:>7} {:>13}",
        "scene",
        "method",
        "dt",
        "substeps",
        "sim dt",
        "error kind",
        "error",
        "ratio",
        "wall s/sim s"
    );
    for (i, r) in rows.iter().enumerate() {
        // The ratio to the previous row of the same series: about 2 for a first-order error.
        let prev = rows[..i]
            .iter()
            .rev()
            .find(|p| p.scene == r.scene && p.method == r.method && p.kind == r.kind);
        let ratio = match prev {
            Some(p) if r.kind != "vs_recurrence" && r.error != 0.0 && p.error.is_finite() => {
                format!("{:.3}", p.error / r.error)
            }
            _ => "-".to_owned(),
        };
        let _ = writeln!(
            s,
            "{:<11} {:<20} {:>7} {:>8} {:>8} {:<17} {:>10} {:>7} {:>13}",
            r.scene,
            r.method,
            per(r.frame_hz),
            r.substeps,
            per(r.frame_hz * r.substeps),
            r.kind,
            sci(r.error),
            ratio,
            format!("{:.3e}", r.wall)
        );
    }
    s
}

/// The table of the offset study and the offsets up to which the tolerances hold.
#[must_use]
pub fn offset_table(results: &[OffsetResult]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "far from the origin (60 Hz; every coordinate + offset; tolerances: projectile {POSITION_TOLERANCE:e} units, \
         landing exact, rest height {SLOP:e}, swept hits exact)"
    );
    let _ = writeln!(
        s,
        "{:>8} {:>22} {:>14} {:>12} {:>16} {:>4}",
        "offset", "projectile vs origin", "landing frame", "rest height", "swept wrong hits", "ok"
    );
    for r in results {
        let ok = offset_ok(r);
        let _ = writeln!(
            s,
            "{:>8} {:>22} {:>14} {:>12} {:>16} {:>4}",
            if r.offset == 0.0 {
                "0".to_owned()
            } else {
                format!("{:.0e}", r.offset)
            },
            sci(r.projectile),
            r.landing,
            sci(r.rest),
            r.swept_wrong,
            if ok { "yes" } else { "NO" }
        );
    }
    // The largest offset up to which every offset meets every tolerance.
    let limit = results
        .iter()
        .take_while(|r| offset_ok(r))
        .last()
        .map_or(0.0, |r| r.offset);
    let contacts = results
        .iter()
        .take_while(|r| contacts_ok(r))
        .last()
        .map_or(0.0, |r| r.offset);
    let _ = writeln!(
        s,
        "every tolerance met up to offset {limit:e}; contacts alone (landing, rest, swept hits) \
         up to {contacts:e}"
    );
    s
}

/// Landing frame exact, rest height within SLOP, swept hits exact.
fn contacts_ok(r: &OffsetResult) -> bool {
    r.landing == 0.0 && r.rest <= SLOP && r.swept_wrong == 0.0
}

/// Every tolerance of the offset study met.
fn offset_ok(r: &OffsetResult) -> bool {
    r.projectile <= POSITION_TOLERANCE && contacts_ok(r)
}

/// The table of the speed study and the speed up to which swept hits are exact.
#[must_use]
pub fn speed_table(results: &[SpeedResult]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "fast bullets (60 Hz, 24 bullets through 40 rocks; wrong = recorded hits differ from the exact first hit)"
    );
    let _ = writeln!(
        s,
        "{:>8} {:>16} {:>12} {:>15} {:>14} {:>17}",
        "speed",
        "units per frame",
        "swept wrong",
        "discrete wrong",
        "swept s/sim s",
        "discrete s/sim s"
    );
    for r in results {
        let _ = writeln!(
            s,
            "{:>8} {:>16} {:>12} {:>15} {:>14} {:>17}",
            format!("{:.0e}", r.speed),
            format!("{:.3e}", r.speed / 60.0),
            r.swept_wrong,
            r.discrete_wrong,
            format!("{:.3e}", r.swept_wall),
            format!("{:.3e}", r.discrete_wall)
        );
    }
    let limit = results
        .iter()
        .take_while(|r| r.swept_wrong == 0.0)
        .last()
        .map_or(0.0, |r| r.speed);
    let _ = writeln!(
        s,
        "swept hits exact up to {limit:e} units/s ({} of {} speeds tested)",
        results.iter().filter(|r| r.swept_wrong == 0.0).count(),
        results.len()
    );
    s
}

/// The CSV: [`CSV_HEADER`], then one line per row.
#[must_use]
pub fn csv_text(rows: &[Row]) -> String {
    let mut s = format!("{CSV_HEADER}\n");
    for r in rows {
        let _ = writeln!(
            s,
            "{},{},{:e},{},{},{:e},{:e}",
            r.scene,
            r.method,
            r.dt(),
            r.substeps,
            r.kind,
            r.error,
            r.wall
        );
    }
    s
}
