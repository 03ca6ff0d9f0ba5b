//! `ricochet validate` and `ricochet run --validate`: rapier2d as the referee.
//!
//! Every frame, every logged contact is recomputed by parry at its own poses, the `all`
//! pass's set of pairs is compared with rapier's at the detect poses, and swept hits are
//! cast along the frame's motion (see `crates/oracle` and `docs/validation.md`). Free flight
//! is compared with rapier's integrator at the end. Exit code 1 on any difference that no
//! documented rule explains.

use std::path::Path;
use std::process::ExitCode;

use ricochet_oracle::{FrameReport, Referee, Tolerances, compare_motion, summary_table};
use ricochet_sim::{FrameOutput, NonFinite, Scenario, Simulation};

use crate::out::WriteError;

/// Test-only hook: when this environment variable is set, every contact's depth is scaled by
/// 1.01 before the referee sees it, as a broken narrow phase would report it. The tests use
/// it to prove that `validate` fails on a wrong narrow phase.
pub const CORRUPT_CONTACTS_HOOK: &str = "RICOCHET_TEST_CORRUPT_CONTACTS";

/// Checks one frame, applying the test hook if it is set.
pub fn check(referee: &mut Referee, sim: &Simulation, out: &FrameOutput) -> FrameReport {
    if std::env::var_os(CORRUPT_CONTACTS_HOOK).is_some() {
        let mut broken = out.clone();
        for c in &mut broken.contacts {
            c.depth *= 1.01;
        }
        return referee.check_frame(sim, &broken);
    }
    referee.check_frame(sim, out)
}

/// A referee for a run, and the summary it adds up.
pub struct Validation {
    referee: Referee,
    summary: ricochet_oracle::ValidationSummary,
}

impl Validation {
    /// A referee for `scenario` with the default tolerances.
    pub fn new(scenario: &Scenario) -> Validation {
        Validation {
            referee: Referee::new(scenario, Tolerances::default()),
            summary: ricochet_oracle::ValidationSummary::new(&scenario.name),
        }
    }

    /// Checks one frame and adds it to the summary.
    pub fn frame(&mut self, sim: &Simulation, out: &FrameOutput) -> FrameReport {
        let r = check(&mut self.referee, sim, out);
        self.summary.add(&r);
        r
    }

    /// Adds free flight over `frames`, prints the table, and returns whether it passed. A
    /// closed pipe on stdout is not an error (the verdict is still the exit code); another
    /// failed write is.
    pub fn finish(mut self, scenario: &Scenario, frames: u64) -> Result<bool, WriteError> {
        self.summary.motion = Some(compare_motion(scenario, frames));
        match crate::out::print(&summary_table(&self.summary)) {
            Err(e) if !e.is_closed() => Err(e),
            _ => Ok(self.summary.passed()),
        }
    }
}

/// A non-finite body for people: `body NAME #id:generation has a non-finite FIELD [x, y]`.
pub fn describe(sim: &Simulation, bad: &NonFinite) -> String {
    ricochet_record::session::describe(sim, bad)
}

/// The referee's verdict on a frame, as `/validation` records it.
pub fn verdict(r: &FrameReport) -> ricochet_log::messages::ricochet::Validation {
    ricochet_log::messages::ricochet::Validation {
        frame: r.frame,
        contacts_compared: r.contacts_compared,
        mismatches: r.mismatches,
        worst_depth_error: r.worst_depth_error,
        worst_normal_error: r.worst_normal_error,
        pairs_confirmed: r.pairs_confirmed,
        swept_confirmed: r.swept_confirmed,
        explained: r
            .explained
            .iter()
            .map(|(k, v)| ((*k).to_owned(), *v))
            .collect(),
        details: r.details.clone(),
    }
}

/// `ricochet validate SCENARIO`: simulate without writing a log, referee every frame.
pub fn run(path: &Path, frames: Option<u64>) -> anyhow::Result<ExitCode> {
    let mut scenario = match crate::load::load(Some(path)) {
        Ok(s) => s,
        Err(code) => return Ok(code),
    };
    if scenario.world.active_region.is_some() || scenario.world.sleep_after.is_some() {
        // Frozen and sleeping bodies are not tested on purpose; rapier tests every pair.
        crate::out::note(
            "validate: active_region and sleep_after are turned off for the referee, which \
             compares every pair (they are tested to change nothing they do not freeze)",
        )?;
        scenario.world.active_region = None;
        scenario.world.sleep_after = None;
    }
    let frames = frames.unwrap_or(scenario.frames);
    if let Err(e) = scenario.world.last_time_ns(frames) {
        crate::out::error(&format!("error: --frames {frames}: {e}"));
        return Ok(ExitCode::from(2));
    }
    let mut sim = Simulation::new(&scenario);
    sim.capture_detect_poses = true;
    let mut v = Validation::new(&scenario);
    for _ in 0..=frames {
        let out = sim.step();
        if let Some(bad) = sim.first_non_finite_after(&out) {
            // No comparison with a NaN or an infinity can pass: say so and fail.
            crate::out::error(&format!(
                "error: frame {}: {}; the simulation overflowed, nothing after it can be \
                 compared",
                out.frame,
                describe(&sim, &bad)
            ));
            return Ok(ExitCode::from(1));
        }
        v.frame(&sim, &out);
    }
    Ok(if v.finish(&scenario, frames)? {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}
