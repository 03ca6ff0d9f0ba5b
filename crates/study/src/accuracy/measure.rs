//! The measurements of the accuracy study: every scene swept over timesteps and substeps,
//! each run timed, and the stability studies far from the origin and at high speed.
//!
//! Wall time is measured with [`Instant`]: it is a benchmark figure, and never reaches a log
//! or a test assertion. Errors are deterministic (libm, no FMA): the same bits on every
//! machine and build.

use std::time::{Duration, Instant};

use anyhow::{Context, ensure};
use ricochet_geom::Vec2;
use ricochet_scenes::accuracy::{
    BOX_HALF, DROP_SECONDS, FLOOR_HALF, Field, G, Harmonic, ORBIT, PROJECTILE_T, PROJECTILE_V0,
    PROJECTILE_X0, SPRING, drop, exact_landing_step, projectile,
};
use ricochet_sim::{Phase, Response, Scenario, Simulation};

use super::{
    BULLET_SPEED, FRAME_HZ, OFFSETS, OffsetResult, Row, SPEEDS, SUBSTEP_HZ, SUBSTEPS, SpeedResult,
    Study,
};

/// Each figure's timed runs add up to at least this much wall time. A debug build's times
/// mean little: it times less, to keep `cargo test` quick.
const TIMING_BUDGET: Duration =
    Duration::from_millis(if cfg!(debug_assertions) { 20 } else { 100 });
/// And there are at least this many timed runs.
const MIN_RUNS: u32 = if cfg!(debug_assertions) { 1 } else { 3 };
/// The longest stretch of simulated time a timed run covers, seconds.
const TIMED_SECONDS: f64 = 10.0;

/// Runs the whole study; `progress` hears the name of each part as it starts (`projectile`,
/// `spring`, ...).
pub fn measure(mut progress: impl FnMut(&str)) -> anyhow::Result<Study> {
    let mut rows = Vec::new();
    progress("projectile");
    rows.extend(projectile_rows()?);
    progress("spring");
    rows.extend(harmonic_rows(&SPRING)?);
    progress("orbit");
    rows.extend(harmonic_rows(&ORBIT)?);
    progress("drop");
    rows.extend(drop_rows()?);
    progress("bullets");
    let field = Field::new().map_err(anyhow::Error::msg)?;
    rows.extend(bullet_rows(&field)?);
    progress("stability (offsets, bullet speeds)");
    let offsets = offset_study(&field)?;
    let speeds = speed_study(&field)?;
    let script_matches = set_force_script_matches()?;
    Ok(Study {
        rows,
        offsets,
        speeds,
        script_matches,
    })
}

/// The errors of one run, by kind, in a fixed order.
type Errors = Vec<(&'static str, f64)>;

/// The errors of a run and its wall time per simulated second.
struct Timed {
    errors: Errors,
    wall: f64,
}

/// Runs `once` (one complete run of `sim_seconds` simulated seconds, measuring its errors)
/// once untimed, to measure and warm up, then again and again, each run timed on its own,
/// until the runs add up to [`TIMING_BUDGET`] and there are at least [`MIN_RUNS`]. The wall
/// time is the fastest run's: on a shared machine it is the run least disturbed by other
/// processes. Every repeat must measure the same bits: the simulation is deterministic. The
/// error bookkeeping (a few flops per frame) is inside the timing, in every scene alike.
fn timed(
    sim_seconds: f64,
    mut once: impl FnMut() -> anyhow::Result<Errors>,
) -> anyhow::Result<Timed> {
    let errors = once()?;
    let mut fastest = f64::INFINITY;
    let mut total = Duration::ZERO;
    let mut runs = 0;
    while runs < MIN_RUNS || total < TIMING_BUDGET {
        let start = Instant::now();
        let again = once()?;
        let took = start.elapsed();
        let same = again.len() == errors.len()
            && again
                .iter()
                .zip(&errors)
                .all(|(a, b)| a.0 == b.0 && a.1.to_bits() == b.1.to_bits());
        ensure!(
            same,
            "a repeated run measured {again:?}, the first {errors:?}"
        );
        fastest = fastest.min(took.as_secs_f64());
        total += took;
        runs += 1;
    }
    Ok(Timed {
        errors,
        wall: fastest / sim_seconds,
    })
}

/// The rows of one scene and method: the timestep sweep (one sim step per frame), then the
/// substep rows (60 Hz frames, k sim steps each). `run(frame_hz, substeps)` measures one.
fn sweep(
    scene: &'static str,
    method: &str,
    mut run: impl FnMut(u32, u32) -> anyhow::Result<Timed>,
) -> anyhow::Result<Vec<Row>> {
    let mut rows = Vec::new();
    let plans = FRAME_HZ.iter().map(|&hz| (method.to_owned(), hz, 1)).chain(
        SUBSTEPS
            .iter()
            .map(|&k| (format!("{method}+substeps"), SUBSTEP_HZ, k)),
    );
    for (method, frame_hz, substeps) in plans {
        let t = run(frame_hz, substeps)
            .with_context(|| format!("{scene} {method} at {frame_hz} Hz x {substeps}"))?;
        for (kind, error) in t.errors {
            rows.push(Row {
                scene,
                method: method.clone(),
                frame_hz,
                substeps,
                kind,
                error,
                wall: t.wall,
            });
        }
    }
    Ok(rows)
}

/// Sim steps in `seconds` at `hz`: the durations are chosen to be whole numbers of steps.
fn steps_in(seconds: f64, hz: u32) -> u64 {
    let n = seconds * f64::from(hz);
    debug_assert!((n - n.round()).abs() < 1e-6, "{seconds} s at {hz} Hz");
    n.round() as u64
}

// ---------------------------------------------------------------------------------------------
// Projectile.

/// Runs the projectile to t = 2 s and returns its position.
fn projectile_end(scenario: &Scenario, steps: u64) -> Vec2 {
    let mut sim = Simulation::new(scenario);
    for _ in 0..=steps {
        sim.step();
    }
    sim.world().position[0]
}

fn projectile_rows() -> anyhow::Result<Vec<Row>> {
    let g = Vec2::new(0.0, -G);
    let t = PROJECTILE_T;
    let exact = PROJECTILE_X0 + PROJECTILE_V0 * t + g * (0.5 * t * t);
    let mut rows = sweep("projectile", "euler", |hz, k| {
        let scenario = projectile(hz * k, 0.0);
        let n = steps_in(t, hz * k);
        let dt = scenario.world.dt;
        // Semi-implicit Euler in exact arithmetic: v_i = v0 + i g dt, x_n = x0 + sum v_i dt.
        let nf = n as f64;
        let recurrence =
            PROJECTILE_X0 + PROJECTILE_V0 * (nf * dt) + g * (dt * dt * nf * (nf + 1.0) * 0.5);
        timed(t, || {
            let p = projectile_end(&scenario, n);
            Ok(vec![
                ("position", (p - exact).length()),
                ("vs_recurrence", (p - recurrence).length()),
            ])
        })
    })?;
    // rapier2d on the same scene and dt: its PhysicsPipeline, one substep, no damping.
    rows.extend(sweep("projectile", "rapier", |hz, k| {
        let scenario = projectile(hz * k, 0.0);
        let n = steps_in(t, hz * k);
        timed(t, || {
            let p = ricochet_oracle::rapier_free_flight(&scenario, n)[0].1;
            Ok(vec![("position", (p - exact).length())])
        })
    })?);
    Ok(rows)
}

// ---------------------------------------------------------------------------------------------
// Spring and orbit.

/// One run: `hz * k` sim steps per second, errors sampled at every displayed frame.
fn harmonic_run(
    h: &Harmonic,
    scenario: &Scenario,
    hz: u32,
    k: u32,
    state: bool,
    seconds: f64,
) -> anyhow::Result<Errors> {
    let mut sim = Simulation::new(scenario);
    let dt = sim.dt();
    let steps = steps_in(seconds, hz * k);
    let e0 = h.energy(h.x0, h.v0);
    let (mut position, mut energy) = (0.0_f64, 0.0_f64);
    sim.step();
    for s in 1..=steps {
        // What a `set_force` event at frame s does, before anything moves.
        let body = sim.world().entity[0];
        let force = h.force(s, dt, state.then(|| sim.world().position[0]));
        sim.set_force(body, force)?;
        sim.step();
        if s % u64::from(k) == 0 {
            let (x, _) = h.exact(s as f64 * dt);
            let (p, v) = (sim.world().position[0], sim.world().velocity(0));
            position = position.max((p - x).length());
            energy = energy.max((h.energy(p, v) - e0).abs() / e0);
        }
    }
    Ok(vec![("position", position), ("energy", energy)])
}

fn harmonic_rows(h: &Harmonic) -> anyhow::Result<Vec<Row>> {
    let mut rows = Vec::new();
    for (method, state) in [("prescribed", false), ("state", true)] {
        rows.extend(sweep(h.scene, method, |hz, k| {
            let scenario = h.scenario(hz * k, Vec::new());
            // Measured over the whole run; timed over at most its first 10 s, which cost the
            // same per step: short runs are the ones other processes disturb least.
            let errors = harmonic_run(h, &scenario, hz, k, state, h.seconds)?;
            let seconds = h.seconds.min(TIMED_SECONDS);
            let t = timed(seconds, || {
                harmonic_run(h, &scenario, hz, k, state, seconds)
            })?;
            Ok(Timed {
                errors,
                wall: t.wall,
            })
        })?);
    }
    Ok(rows)
}

/// The prescribed spring at 30 Hz driven by a real script of `set_force` events ends on the
/// same bits as the same run with the force written before each step.
fn set_force_script_matches() -> anyhow::Result<bool> {
    let h = &SPRING;
    let hz = 30;
    let dt = 1.0 / f64::from(hz);
    let steps = steps_in(h.seconds, hz);
    let scripted = h.scenario(hz, h.force_script(hz, steps));
    ensure!(scripted.world.dt == dt, "dt is not 1/30 as computed here");
    let mut sim = Simulation::new(&scripted);
    for _ in 0..=steps {
        sim.step();
    }
    let direct = h.scenario(hz, Vec::new());
    let mut other = Simulation::new(&direct);
    other.step();
    for s in 1..=steps {
        let body = other.world().entity[0];
        other.set_force(body, h.force(s, dt, None))?;
        other.step();
    }
    Ok(sim.world().digest() == other.world().digest())
}

// ---------------------------------------------------------------------------------------------
// A box dropping onto a floor.

/// The exact landing step at `hz`; an error when it is a near tie.
fn landing_step(hz: u32) -> anyhow::Result<u64> {
    exact_landing_step(hz).with_context(|| format!("the landing at {hz} Hz is a near tie"))
}

/// One drop run: the step on which the box was first pushed up (a `y` contact), and the
/// largest distance from the rest height over the displayed frames from then on.
fn drop_run(scenario: &Scenario, k: u32, steps: u64) -> (Option<u64>, f64) {
    let mut sim = Simulation::new(scenario);
    let (floor, ball) = (0, 1);
    let mut landed = None;
    let mut rest_error = 0.0_f64;
    sim.step();
    // The floor's top as its bounds compute it, plus the half height (one rounding each).
    let rest = sim.world().position[floor].y + FLOOR_HALF + BOX_HALF;
    for s in 1..=steps {
        let out = sim.step();
        if landed.is_none() && out.contacts.iter().any(|c| c.phase == Phase::Y) {
            landed = Some(s);
        }
        if landed.is_some() && s % u64::from(k) == 0 {
            rest_error = rest_error.max((sim.world().position[ball].y - rest).abs());
        }
    }
    (landed, rest_error)
}

fn drop_errors(landed: Option<u64>, rest_error: f64, exact: u64) -> Errors {
    let landing = landed.map_or(f64::INFINITY, |s| s as f64 - exact as f64);
    vec![
        ("landing_frame", landing),
        (
            "rest_height",
            if landed.is_some() {
                rest_error
            } else {
                f64::INFINITY
            },
        ),
    ]
}

fn drop_rows() -> anyhow::Result<Vec<Row>> {
    sweep("drop", "euler", |hz, k| {
        let scenario = drop(hz * k, 0.0);
        let exact = landing_step(hz * k)?;
        let steps = steps_in(DROP_SECONDS, hz * k);
        timed(DROP_SECONDS, || {
            let (landed, rest) = drop_run(&scenario, k, steps);
            Ok(drop_errors(landed, rest, exact))
        })
    })
}

// ---------------------------------------------------------------------------------------------
// Bullets through a field of rocks.

/// Steps until every bullet is `BULLET_RANGE` past its start (plus one frame), and counts
/// the bullets whose recorded hits are not exactly `{their exact first hit}`.
fn wrong_hits(field: &Field, scenario: &Scenario, steps: u64) -> f64 {
    let n_rocks = field.rocks.len();
    let mut hits: Vec<Vec<usize>> = vec![Vec::new(); field.bullets.len()];
    let mut sim = Simulation::new(scenario);
    for _ in 0..=steps {
        let out = sim.step();
        for c in &out.contacts {
            if !matches!(c.response, Response::Destroy(_)) {
                continue;
            }
            let (a, b) = (c.a.index as usize, c.b.index as usize);
            // Bodies are rocks, then bullets, in file order; nothing spawns.
            let (rock, bullet) = if a < n_rocks { (a, b) } else { (b, a) };
            hits[bullet - n_rocks].push(rock);
        }
    }
    let wrong = hits
        .iter()
        .zip(&field.first_hits)
        .filter(|(got, want)| {
            let want: Vec<usize> = want.iter().copied().collect();
            **got != want
        })
        .count();
    wrong as f64
}

fn bullet_rows(field: &Field) -> anyhow::Result<Vec<Row>> {
    let mut rows = Vec::new();
    for (method, swept) in [("swept", true), ("discrete", false)] {
        rows.extend(sweep("bullets", method, |hz, k| {
            let h = hz * k;
            let scenario = field.scenario(h, BULLET_SPEED, swept, 0.0);
            let steps = Field::steps(BULLET_SPEED, h);
            timed(steps as f64 / f64::from(h), || {
                Ok(vec![(
                    "wrong_first_hits",
                    wrong_hits(field, &scenario, steps),
                )])
            })
        })?);
    }
    Ok(rows)
}

// ---------------------------------------------------------------------------------------------
// Stability: far from the origin, and fast.

fn offset_study(field: &Field) -> anyhow::Result<Vec<OffsetResult>> {
    let hz = 60;
    let n = steps_in(PROJECTILE_T, hz);
    let origin = projectile_end(&projectile(hz, 0.0), n);
    let exact_landing = landing_step(hz)?;
    let drop_steps = steps_in(DROP_SECONDS, hz);
    let bullet_steps = Field::steps(BULLET_SPEED, hz);
    let mut results = Vec::new();
    for offset in OFFSETS {
        let p = projectile_end(&projectile(hz, offset), n);
        let (landed, rest) = drop_run(&drop(hz, offset), 1, drop_steps);
        let d = drop_errors(landed, rest, exact_landing);
        let bullets = field.scenario(hz, BULLET_SPEED, true, offset);
        results.push(OffsetResult {
            offset,
            projectile: (p - Vec2::splat(offset) - origin).length(),
            landing: d[0].1,
            rest: d[1].1,
            swept_wrong: wrong_hits(field, &bullets, bullet_steps),
        });
    }
    Ok(results)
}

fn speed_study(field: &Field) -> anyhow::Result<Vec<SpeedResult>> {
    let hz = 60;
    let mut results = Vec::new();
    for speed in SPEEDS {
        let steps = Field::steps(speed, hz);
        let seconds = steps as f64 / f64::from(hz);
        let swept = field.scenario(hz, speed, true, 0.0);
        let discrete = field.scenario(hz, speed, false, 0.0);
        let s = timed(seconds, || {
            Ok(vec![("wrong_first_hits", wrong_hits(field, &swept, steps))])
        })?;
        let d = timed(seconds, || {
            Ok(vec![(
                "wrong_first_hits",
                wrong_hits(field, &discrete, steps),
            )])
        })?;
        results.push(SpeedResult {
            speed,
            swept_wrong: s.errors[0].1,
            discrete_wrong: d.errors[0].1,
            swept_wall: s.wall,
            discrete_wall: d.wall,
        });
    }
    Ok(results)
}
