//! The measurement of `ricochet bench`: one scene stepped by Ricochet, rapier and Box2D, each
//! step timed, the contact sets compared on every frame, the process's peak memory read.
//!
//! Frame 0 (the initial state) is stepped by all three untimed (rapier's and Box2D's first
//! steps pair every shape from scratch), and the simulation is cloned there (a clone steps
//! bit for bit as the original). Then for each of `frames` frames: Ricochet's
//! `Simulation::step()` is timed; every moving body's pose is copied into rapier (untimed);
//! rapier's `CollisionPipeline::step` is timed; the two contact sets are compared
//! ([`ricochet_oracle::bench::compare_contacts`] documents the rule). Then as many frames
//! again with rapier idle, Ricochet alone: one thread, and the same frames with two threads
//! on a clone. Last, Box2D in a pass of its own (three engines interleaved would evict each
//! other's caches and slow all three): the frame-0 clone steps the same frames again,
//! untimed, and after each the changed poses are copied into Box2D (`b2Body_SetTransform`,
//! timed apart as `box2d_sync`: it moves a shape's broad-phase proxy when the shape leaves its
//! fat box, part of Box2D's broad phase that its step does not see); Box2D steps once, and
//! its own profile (`b2World_GetProfile`) gives its broad plus narrow phase
//! (`pairs + collide`) and its whole step; its contact set is compared
//! ([`ricochet_box2d::compare_box2d`] documents the rule). Every frame is compared, frame 0
//! included.
//!
//! Memory is the process's peak resident set (`VmHWM` in `/proc/self/status`, reset at the
//! scene's start by writing `5` to `/proc/self/clear_refs`): `ricochet_mb` is read once
//! Ricochet's world is built and has stepped frame 0, before rapier's and Box2D's worlds exist
//! (the scenario and the simulation's copy of it both count: `Simulation::new` clones it);
//! `peak_mb` at the end of the scene (the high-water mark of the whole run). Both include the process's own few
//! megabytes; the caller runs each scene in a fresh process so that they do not include heap
//! the allocator kept from an earlier scene. `box2d_mb` is what Box2D itself allocated
//! (`b2GetByteCount`), after its world is built.
//!
//! Wall time is measured with [`Instant`] (Box2D's profile reads its own clock): it is a
//! benchmark figure, and never reaches a log or a test assertion.

use std::time::{Duration, Instant};

use anyhow::Context;
use ricochet_box2d::{BOX2D_CONTACT_TOLERANCE, Box2dAgreement, Box2dScene, compare_box2d};
use ricochet_oracle::bench::{CONTACT_TOLERANCE, ContactAgreement, RapierScene, compare_contacts};
use ricochet_scenes::bench::Scene;
use ricochet_sim::Simulation;
use serde::{Deserialize, Serialize};

/// A field of `/proc/self/status` (`VmHWM`, `VmRSS`), in megabytes; `None` off Linux.
fn status_mb(field: &str) -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with(field))?;
    let kb: f64 = line
        .trim_start_matches(field)
        .trim_start_matches(':')
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    Some(kb / 1024.0)
}

/// Resets `VmHWM` to the current resident set (Linux 4.0 and later).
fn reset_peak() {
    // Off Linux, or without permission, the peak simply keeps counting from process start.
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}

/// Per-frame times: median and 95th percentile (nearest rank), milliseconds.
#[must_use]
pub fn percentiles(times: &[Duration]) -> (f64, f64) {
    if times.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    let mut ms: Vec<f64> = times.iter().map(|t| t.as_secs_f64() * 1e3).collect();
    ms.sort_by(f64::total_cmp);
    let n = ms.len();
    let median = if n % 2 == 1 {
        ms[n / 2]
    } else {
        0.5 * (ms[n / 2 - 1] + ms[n / 2])
    };
    let rank = (n * 95).div_ceil(100).max(1);
    (median, ms[rank - 1])
}
/// One scene's figures.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Row {
    /// The scene's name as asked.
    pub scene: String,
    /// Bodies in the scene.
    pub bodies: usize,
    /// Timed frames.
    pub frames: u64,
    /// Ricochet's median time per frame.
    pub ricochet_median_ms: f64,
    /// Ricochet's 95th percentile (nearest rank).
    pub ricochet_p95_ms: f64,
    /// Rapier's median time per frame.
    pub rapier_median_ms: f64,
    /// Rapier's 95th percentile (nearest rank).
    pub rapier_p95_ms: f64,
    /// How the contact sets compared over the run.
    pub agreement: ContactAgreement,
    /// Peak resident set after Ricochet's setup and frame 0, MB (`None` off Linux).
    pub ricochet_mb: Option<f64>,
    /// Peak resident set at the end of the scene, MB (`None` off Linux).
    pub peak_mb: Option<f64>,
    /// Median of `frames` more Ricochet steps with rapier and Box2D idle: Ricochet with the
    /// caches to itself (between interleaved steps, the other engines evict Ricochet's data).
    pub ricochet_alone_median_ms: f64,
    /// The same frames as `ricochet_alone_median_ms`, stepped by a clone of the simulation
    /// with two threads (`Simulation::set_threads`; the parallel stages give the same bytes),
    /// median. The ratios are one thread against one thread.
    pub ricochet_alone_2t_median_ms: f64,
    /// Box2D's broad plus narrow phase per frame (`pairs + collide` of its profile), median.
    pub box2d_collide_median_ms: f64,
    /// Box2D's broad plus narrow phase, 95th percentile (nearest rank).
    pub box2d_collide_p95_ms: f64,
    /// Box2D's whole step per frame (`step` of its profile: collide, solver, continuous,
    /// sensors), median.
    pub box2d_step_median_ms: f64,
    /// Copying the changed poses into Box2D (`b2Body_SetTransform`, which moves broad-phase
    /// proxies), median per frame. Not part of either figure above.
    pub box2d_sync_median_ms: f64,
    /// How the contact sets compared with Box2D's over the run.
    pub box2d_agreement: Box2dAgreement,
    /// What Box2D allocated for its world (`b2GetByteCount`), MB.
    pub box2d_mb: f64,
}

impl Row {
    /// Rapier's median over Ricochet's.
    #[must_use]
    pub fn ratio(&self) -> f64 {
        self.rapier_median_ms / self.ricochet_median_ms
    }

    /// Box2D's collide median over Ricochet's median.
    #[must_use]
    pub fn box2d_ratio(&self) -> f64 {
        self.box2d_collide_median_ms / self.ricochet_median_ms
    }

    /// Whether every compared contact agreed, with rapier and with Box2D.
    #[must_use]
    pub fn agrees(&self) -> bool {
        self.agreement.all_agree() && self.box2d_agreement.all_agree()
    }
}
/// Box2D's profile figures (milliseconds) as durations, for [`percentiles`].
fn durations(ms: &[f64]) -> Vec<Duration> {
    ms.iter()
        .map(|&ms| Duration::from_secs_f64(ms.max(0.0) * 1e-3))
        .collect()
}

/// The most timed frames a scene may run: each frame keeps seven timings (8 bytes each) for
/// the medians, so a million frames hold 56 MB, and take hours on the largest scenes.
/// `bench asteroids-10 --frames 18446744073709551615` used to panic reserving them.
pub const MAX_FRAMES: u64 = 1_000_000;

/// Runs one scene: all three engines, `frames` timed frames after frame 0 (at most
/// [`MAX_FRAMES`]).
/// `name` is the scene's name as asked (it names the row); `progress` hears what the run is
/// doing (`NAME: N bodies, F frames`, the setup time, a note every 30 s).
pub fn run_scene(
    name: &str,
    scene: Scene,
    frames: u64,
    mut progress: impl FnMut(&str),
) -> anyhow::Result<Row> {
    anyhow::ensure!(
        (1..=MAX_FRAMES).contains(&frames),
        "{name}: --frames must be 1 to {MAX_FRAMES}, got {frames}"
    );
    reset_peak();
    let setup = Instant::now();
    // Built for both timed passes (interleaved, then alone): a scene built for `frames`
    // ends its asteroids' bullets 60 frames into the second, and "alone" then timed a
    // scene 101 bodies short for 40 of its 100 frames.
    let scenario = scene.build(frames.saturating_mul(2));
    let mut sim = Simulation::from_scenario(scenario);
    let bodies = sim.world().len();
    progress(&format!("{name}: {bodies} bodies, {frames} frames"));
    let out0 = sim.step();
    let ricochet_mb = status_mb("VmHWM");
    // Box2D runs in a pass of its own, on a clone stepping the same frames again: three
    // engines interleaved would evict each other's caches and slow all three.
    let mut replay = sim.clone();
    let mut rapier = RapierScene::new(&sim).with_context(|| format!("{name}: rapier scene"))?;
    rapier.step();
    let mut agreement = compare_contacts(&sim, &out0, &rapier.penetrating(), CONTACT_TOLERANCE);
    progress(&format!(
        "{name}: set up in {:.1} s",
        setup.elapsed().as_secs_f64()
    ));
    let mut ricochet_times = Vec::with_capacity(usize::try_from(frames).unwrap_or(0));
    let mut rapier_times = Vec::with_capacity(ricochet_times.capacity());
    let started = Instant::now();
    let mut last_note = Instant::now();
    let mut note = |what: &str, frame: u64| {
        if last_note.elapsed() > Duration::from_secs(30) {
            progress(&format!(
                "{name}: {what} frame {frame}/{frames} after {:.0} s",
                started.elapsed().as_secs_f64()
            ));
            last_note = Instant::now();
        }
    };
    for frame in 1..=frames {
        let t = Instant::now();
        let out = sim.step();
        ricochet_times.push(t.elapsed());
        rapier
            .sync(&sim)
            .with_context(|| format!("{name}: frame {frame}"))?;
        let t = Instant::now();
        rapier.step();
        rapier_times.push(t.elapsed());
        agreement.add(&compare_contacts(
            &sim,
            &out,
            &rapier.penetrating(),
            CONTACT_TOLERANCE,
        ));
        note("rapier", frame);
    }
    // The same number of frames again, Ricochet alone (rapier's world stays, untouched),
    // then the same frames with two threads, on a clone taken here.
    let mut twin = sim.clone();
    twin.set_threads(2);
    let alone = |sim: &mut Simulation| {
        let mut times = Vec::with_capacity(ricochet_times.len());
        for _ in 0..frames {
            let t = Instant::now();
            let out = sim.step();
            times.push(t.elapsed());
            drop(out);
        }
        percentiles(&times).0
    };
    let ricochet_alone_median_ms = alone(&mut sim);
    let ricochet_alone_2t_median_ms = alone(&mut twin);
    drop((sim, twin, rapier));
    // Box2D on the clone taken after frame 0: the same frames and poses (a clone steps bit
    // for bit as the original), Ricochet's steps untimed.
    let mut box2d = Box2dScene::new(&replay).with_context(|| format!("{name}: Box2D scene"))?;
    box2d
        .step()
        .with_context(|| format!("{name}: Box2D frame 0"))?;
    let box2d_mb = ricochet_box2d::allocated_mb().with_context(|| format!("{name}: Box2D"))?;
    let mut box2d_agreement = compare_box2d(
        &replay,
        &out0,
        &box2d
            .touching()
            .with_context(|| format!("{name}: Box2D frame 0"))?,
        BOX2D_CONTACT_TOLERANCE,
    );
    drop(out0);
    let mut box2d_collide = Vec::with_capacity(ricochet_times.len());
    let mut box2d_step = Vec::with_capacity(ricochet_times.len());
    let mut box2d_sync = Vec::with_capacity(ricochet_times.len());
    for frame in 1..=frames {
        let out = replay.step();
        let box2d_frame = || format!("{name}: Box2D frame {frame}");
        let t = Instant::now();
        box2d.sync(&replay).with_context(box2d_frame)?;
        box2d_sync.push(t.elapsed());
        box2d.step().with_context(box2d_frame)?;
        box2d_collide.push(box2d.times().collide_ms);
        box2d_step.push(box2d.times().step_ms);
        box2d_agreement.add(&compare_box2d(
            &replay,
            &out,
            &box2d.touching().with_context(box2d_frame)?,
            BOX2D_CONTACT_TOLERANCE,
        ));
        note("Box2D", frame);
    }
    let peak_mb = status_mb("VmHWM");
    let (ricochet_median_ms, ricochet_p95_ms) = percentiles(&ricochet_times);
    let (rapier_median_ms, rapier_p95_ms) = percentiles(&rapier_times);
    let (box2d_collide_median_ms, box2d_collide_p95_ms) = percentiles(&durations(&box2d_collide));
    let (box2d_step_median_ms, _) = percentiles(&durations(&box2d_step));
    let (box2d_sync_median_ms, _) = percentiles(&box2d_sync);
    Ok(Row {
        scene: name.to_owned(),
        bodies,
        frames,
        ricochet_median_ms,
        ricochet_p95_ms,
        rapier_median_ms,
        rapier_p95_ms,
        agreement,
        ricochet_mb,
        peak_mb,
        ricochet_alone_median_ms,
        ricochet_alone_2t_median_ms,
        box2d_collide_median_ms,
        box2d_collide_p95_ms,
        box2d_step_median_ms,
        box2d_sync_median_ms,
        box2d_agreement,
        box2d_mb,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_are_nearest_rank() {
        let t: Vec<Duration> = (1..=100).map(Duration::from_millis).collect();
        let (median, p95) = percentiles(&t);
        assert!((median - 50.5).abs() < 1e-9);
        assert!((p95 - 95.0).abs() < 1e-9);
        let (median, p95) = percentiles(&[Duration::from_millis(3)]);
        assert_eq!((median, p95), (3.0, 3.0));
    }
}
