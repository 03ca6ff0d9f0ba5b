//! A run measured against the reference as both step, side by side in simulation time:
//! nothing is kept per frame, so memory is the same for 100 frames or 100,000,000. The
//! reference steps each frame the run's next frame covers ([`FrameMap::covering_frame`])
//! before the run steps it; at a time both reach (a run frame `b·m`, reference frame
//! `a·m`) the reference's sample is its current frame's. Either run stops at its first
//! overflow, as `ricochet run` does.

use ricochet_sim::{Scenario, WorldBounds};

use super::error::{Measures, Measuring};
use super::time::{FrameMap, Ratio};
use super::trace::{Overflow, Sample, Stepper};

/// Why a run was not measured.
#[derive(Debug)]
pub enum Stopped {
    /// The run overflowed: its row says where.
    Run(Overflow),
    /// The reference overflowed: nothing can be measured against it.
    Reference(Overflow),
}

/// A run measured: its error and its final digest.
#[derive(Debug)]
pub struct Measured {
    /// The error against the reference.
    pub error: Measures,
    /// [`ricochet_sim::World::digest`] at the run's end.
    pub digest: u64,
}

/// Runs `run` (at `dt`) and `reference` (at `dt_ref`) side by side and measures the first
/// against the second (`bounds`: the run's world).
pub fn measure(
    run: &Scenario,
    dt: Ratio,
    reference: &Scenario,
    dt_ref: Ratio,
    bounds: Option<&WorldBounds>,
) -> Result<Measured, Stopped> {
    let map = FrameMap::new(dt, dt_ref);
    let mut measuring = Measuring::new(bounds);
    let (mut ours, mut theirs) = (Stepper::new(run), Stepper::new(reference));
    // The reference's sample at its current frame, when that frame is a common time.
    let mut at: Option<(u64, Sample)> = None;
    while let Some(k) = ours.next_frame() {
        while theirs
            .next_frame()
            .is_some_and(|j| map.covering_frame(j) <= k)
        {
            step_reference(map, &mut theirs, &mut at, &mut measuring)?;
        }
        let j = map.reference_frame(k);
        let r = at.as_ref().filter(|(f, _)| Some(*f) == j).map(|(_, s)| s);
        let frame = ours.step(r.is_some() || k == 0).map_err(Stopped::Run)?;
        if let (0, Some(s)) = (k, &frame.sample) {
            measuring.start(s.energy);
        }
        if let (Some(s), Some(r)) = (&frame.sample, r) {
            measuring.frame(s, r);
        }
        for t in frame.touches {
            measuring.run_touch(k, t);
        }
    }
    // The reference's frames after the run's last: their touch events still count.
    while theirs.next_frame().is_some() {
        step_reference(map, &mut theirs, &mut at, &mut measuring)?;
    }
    theirs.finish().map_err(Stopped::Reference)?;
    Ok(Measured {
        digest: ours.finish().map_err(Stopped::Run)?,
        error: measuring.finish(),
    })
}

/// Steps the reference's next frame, if it has one: its sample kept when the frame is a
/// common time, its touch events given to `measuring`.
fn step_reference(
    map: FrameMap,
    theirs: &mut Stepper,
    at: &mut Option<(u64, Sample)>,
    measuring: &mut Measuring,
) -> Result<(), Stopped> {
    let Some(j) = theirs.next_frame() else {
        return Ok(());
    };
    let frame = theirs
        .step(map.is_common_reference_frame(j))
        .map_err(Stopped::Reference)?;
    *at = frame.sample.map(|s| (j, s));
    let covering = map.covering_frame(j);
    for t in frame.touches {
        measuring.reference_touch(covering, t);
    }
    Ok(())
}

/// The reference alone: its own row's measures (every frame compared with itself: no
/// error, its energy drift) and its digest.
pub fn alone(reference: &Scenario) -> Result<Measured, Overflow> {
    let mut run = Stepper::new(reference);
    let mut error = Measures::default();
    let mut first = None;
    while let Some(k) = run.next_frame() {
        let last = k == reference.frames;
        let frame = run.step(k == 0 || last)?;
        if let Some(s) = frame.sample {
            let e0 = *first.get_or_insert(s.energy);
            error.energy_drift = s.energy - e0;
        }
        error.matched_frames += 1;
    }
    Ok(Measured {
        digest: run.finish()?,
        error,
    })
}
