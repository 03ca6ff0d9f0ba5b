//! Frame reports added up over a run, and the printable table.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use ricochet_sim::{Scenario, Simulation};

use crate::motion::{MotionReport, compare_motion};
use crate::referee::{FrameReport, Referee};
use crate::{Tolerances, rules};

/// How many unexplained differences a summary keeps word for word (all are counted).
pub const MAX_DETAILS: usize = 50;

/// A whole run's validation: the frame reports added up, and the free-flight comparison.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ValidationSummary {
    /// Scenario name.
    pub scenario: String,
    /// Frames checked (frame 0 included).
    pub frames: u64,
    /// Contact records recomputed by parry.
    pub contacts_compared: u64,
    /// Unexplained differences.
    pub mismatches: u64,
    /// Largest depth error over the run, world units.
    pub worst_depth_error: f64,
    /// Largest normal error over the run, radians.
    pub worst_normal_error: f64,
    /// `all`-pass pairs both engines found.
    pub pairs_confirmed: u64,
    /// `swept` contacts confirmed as parry's first touch.
    pub swept_confirmed: u64,
    /// Compared contacts per phase.
    pub by_phase: BTreeMap<&'static str, u64>,
    /// Differences explained, per rule (every rule of [`rules::ALL`] is listed, zero or not).
    pub explained: BTreeMap<&'static str, u64>,
    /// Per rule, the deepest parry depth among the differences it explained.
    pub explained_depth: BTreeMap<&'static str, f64>,
    /// Compared contacts per shape pairing.
    pub by_pairing: BTreeMap<String, u64>,
    /// The first [`MAX_DETAILS`] unexplained differences.
    pub details: Vec<String>,
    /// The free-flight comparison, when it was run.
    pub motion: Option<MotionReport>,
}

impl ValidationSummary {
    /// An empty summary for `scenario`, every rule at zero.
    #[must_use]
    pub fn new(scenario: &str) -> ValidationSummary {
        ValidationSummary {
            scenario: scenario.to_owned(),
            explained: rules::ALL.iter().map(|(name, _)| (*name, 0)).collect(),
            ..ValidationSummary::default()
        }
    }

    /// Adds one frame's report.
    pub fn add(&mut self, r: &FrameReport) {
        self.frames += 1;
        self.contacts_compared += r.contacts_compared;
        self.mismatches += r.mismatches;
        self.worst_depth_error = self.worst_depth_error.max(r.worst_depth_error);
        self.worst_normal_error = self.worst_normal_error.max(r.worst_normal_error);
        self.pairs_confirmed += r.pairs_confirmed;
        self.swept_confirmed += r.swept_confirmed;
        for (phase, n) in &r.by_phase {
            *self.by_phase.entry(phase).or_default() += n;
        }
        for (rule, n) in &r.explained {
            *self.explained.entry(rule).or_default() += n;
        }
        for (rule, d) in &r.explained_depth {
            let deepest = self
                .explained_depth
                .entry(rule)
                .or_insert(f64::NEG_INFINITY);
            *deepest = deepest.max(*d);
        }
        for (pairing, n) in &r.by_pairing {
            *self.by_pairing.entry(pairing.clone()).or_default() += n;
        }
        let room = MAX_DETAILS.saturating_sub(self.details.len());
        self.details.extend(r.details.iter().take(room).cloned());
    }

    /// No unexplained difference, and free flight (if run) within its bounds.
    #[must_use]
    pub fn passed(&self) -> bool {
        self.mismatches == 0 && self.motion.as_ref().is_none_or(MotionReport::passed)
    }
}

/// Runs `scenario` for `frames` frames after frame 0 with detect poses captured, checks
/// every frame with a [`Referee`], and compares free flight over the same frames.
#[must_use]
pub fn validate(scenario: &Scenario, frames: u64, tol: Tolerances) -> ValidationSummary {
    let mut sim = Simulation::new(scenario);
    sim.capture_detect_poses = true;
    let mut referee = Referee::new(scenario, tol);
    let mut summary = ValidationSummary::new(&scenario.name);
    for _ in 0..=frames {
        let out = sim.step();
        summary.add(&referee.check_frame(&sim, &out));
    }
    summary.motion = Some(compare_motion(scenario, frames));
    summary
}

/// A printable table of a summary: contacts compared, worst errors, each rule's count,
/// pairings, free flight, and the unexplained differences.
#[must_use]
pub fn summary_table(s: &ValidationSummary) -> String {
    let mut t = String::new();
    let verdict = if s.passed() { "PASS" } else { "FAIL" };
    // Writing to a String cannot fail.
    let _ = writeln!(t, "validation of {}: {verdict}", s.scenario);
    let phases: Vec<String> = s.by_phase.iter().map(|(p, n)| format!("{p} {n}")).collect();
    let rows = [
        ("frames checked", s.frames.to_string()),
        (
            "contacts compared",
            format!("{} ({})", s.contacts_compared, phases.join(", ")),
        ),
        ("all-pass pairs confirmed", s.pairs_confirmed.to_string()),
        ("swept hits confirmed", s.swept_confirmed.to_string()),
        ("unexplained mismatches", s.mismatches.to_string()),
        ("worst depth error", format!("{:.3e}", s.worst_depth_error)),
        (
            "worst normal error (rad)",
            format!("{:.3e}", s.worst_normal_error),
        ),
    ];
    for (label, value) in rows {
        let _ = writeln!(t, "{label:<26} {value}");
    }
    let _ = writeln!(
        t,
        "\n{:<16} {:>8} {:>12}  meaning",
        "rule", "count", "deepest"
    );
    for (name, meaning) in rules::ALL {
        let n = s.explained.get(name).copied().unwrap_or(0);
        let deepest = match s.explained_depth.get(name) {
            Some(d) => format!("{d:.3e}"),
            None => "-".to_owned(),
        };
        let _ = writeln!(t, "{name:<16} {n:>8} {deepest:>12}  {meaning}");
    }
    if !s.by_pairing.is_empty() {
        let _ = writeln!(t, "\n{:<20} {:>10}", "pairing", "contacts");
        for (p, n) in &s.by_pairing {
            let _ = writeln!(t, "{p:<20} {n:>10}");
        }
    }
    if let Some(m) = &s.motion {
        let _ = writeln!(
            t,
            "\nfree flight, {} frames: {}",
            m.frames,
            if m.passed() { "pass" } else { "FAIL" }
        );
        let _ = writeln!(
            t,
            "{:<20} {:>10} {:>12} {:>8} {:>12} {:>8} {:>12}",
            "body", "kind", "position", "/bound", "angle", "/bound", "raw angle"
        );
        for b in &m.bodies {
            let _ = writeln!(
                t,
                "{:<20} {:>10} {:>12.3e} {:>8.3} {:>12.3e} {:>8.3} {:>12.3e}",
                b.name,
                b.kind,
                b.max_position_error,
                b.worst_position_ratio,
                b.max_angle_error,
                b.worst_angle_ratio,
                b.raw_angle_difference
            );
        }
    }
    if !s.details.is_empty() {
        let _ = writeln!(t, "\nunexplained (first {}):", s.details.len());
        for d in &s.details {
            let _ = writeln!(t, "  {d}");
        }
    }
    t
}
