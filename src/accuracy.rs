//! `ricochet accuracy`: run time against error, on scenes whose exact answer is known.
//!
//! Every scene is a scenario written here as TOML text, loaded with
//! [`ricochet_sim::load_scenario`] and stepped by [`ricochet_sim::Simulation`], the same
//! path `ricochet run` takes. Frame 0 is the initial state; every later `step()` advances one
//! `dt`. The scenes and what their errors mean are described in `docs/accuracy.md`:
//!
//! - `projectile`: gravity only; the position at t = 2 s against `x0 + v0 t + g t²/2`.
//! - `spring` and `orbit`: `x'' = -ω² x` (a body on a spring; a circular orbit round the
//!   origin). The simulation has no spring or central force, so the force is written into the
//!   body before every step, either *prescribed* from the exact solution (what a `set_force`
//!   event per frame does; checked bit for bit against such a script) or computed from the
//!   body's *state* (`-m ω² x`), as a game loop driving the library would.
//! - `drop`: a box falls onto a static floor (per-axis `separate`): the landing frame against
//!   the semi-implicit-Euler recurrence, and the rest height against `top + half height`.
//! - `bullets`: bullets cross a field of rocks; each bullet's recorded hits against its exact
//!   first hit (analytic ray–circle entry), with and without `fast_layers` (swept tests).
//!
//! Wall time is measured with [`Instant`]: it is a benchmark figure printed and written here,
//! and never reaches a log or a test assertion.

use std::f64::consts::PI;
use std::fmt::Write as _;
use std::path::Path;
use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::{Context, ensure};
use ricochet_geom::Vec2;
use ricochet_sim::{Phase, Response, SLOP, Scenario, Simulation, load_scenario};

/// The frame rates of the timestep sweep: dt = 1/30 s to 1/960 s.
const FRAME_HZ: [u32; 6] = [30, 60, 120, 240, 480, 960];
/// The frame rate the substep rows keep.
const SUBSTEP_HZ: u32 = 60;
/// Sim steps per displayed frame in the substep rows.
const SUBSTEPS: [u32; 3] = [1, 2, 4];
/// Each figure's timed runs add up to at least this much wall time. A debug build's times
/// mean little: it times less, to keep `cargo test` quick.
const TIMING_BUDGET: Duration =
    Duration::from_millis(if cfg!(debug_assertions) { 20 } else { 100 });
/// And there are at least this many timed runs.
const MIN_RUNS: u32 = if cfg!(debug_assertions) { 1 } else { 3 };
/// The longest stretch of simulated time a timed run covers, seconds.
const TIMED_SECONDS: f64 = 10.0;
/// Gravity, units/s² (downwards).
const G: f64 = 9.81;
/// The coordinate offsets of the stability study, up to just inside
/// `ricochet_geom::MAX_COORDINATE` (1e15), beyond which scenarios are rejected.
const OFFSETS: [f64; 14] = [
    0.0, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 9e14,
];
/// The bullet speeds of the stability study, units/s.
const SPEEDS: [f64; 9] = [1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10];
/// The bullet speed of the timestep sweep, units/s.
const BULLET_SPEED: f64 = 300.0;
/// Position tolerance of the stability study: what rounding may add to a run, in units.
const POSITION_TOLERANCE: f64 = 1e-6;

/// What the error kinds of the table mean (docs/accuracy.md says more).
const KINDS: &str = "\
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

/// Runs the accuracy sweep: prints the tables, writes the CSV and the SVG.
pub fn run(csv: Option<&Path>, svg: Option<&Path>) -> anyhow::Result<ExitCode> {
    let start = Instant::now();
    let mut rows = Vec::new();
    eprintln!("accuracy: projectile");
    rows.extend(projectile_rows()?);
    eprintln!("accuracy: spring");
    rows.extend(harmonic_rows(&SPRING)?);
    eprintln!("accuracy: orbit");
    rows.extend(harmonic_rows(&ORBIT)?);
    eprintln!("accuracy: drop");
    rows.extend(drop_rows()?);
    eprintln!("accuracy: bullets");
    let field = Field::new()?;
    rows.extend(bullet_rows(&field)?);
    eprintln!("accuracy: stability (offsets, bullet speeds)");
    let offsets = offset_study(&field)?;
    let speeds = speed_study(&field)?;
    let script_matches = set_force_script_matches()?;

    print!("{KINDS}");
    println!();
    print!("{}", table(&rows));
    println!();
    print!("{}", offset_table(&offsets));
    println!();
    print!("{}", speed_table(&speeds));
    println!();

    let checks = checks(&rows, script_matches);
    let mut ok = true;
    println!("checks:");
    for (pass, what) in &checks {
        ok &= *pass;
        println!("  {} {what}", if *pass { "PASS" } else { "FAIL" });
    }

    if let Some(path) = csv {
        std::fs::write(path, csv_text(&rows))
            .with_context(|| format!("writing {}", path.display()))?;
        println!("wrote {}", path.display());
    }
    if let Some(path) = svg {
        std::fs::write(path, svg_text(&rows))
            .with_context(|| format!("writing {}", path.display()))?;
        println!("wrote {}", path.display());
    }
    println!(
        "total wall time {:.1} s ({} build)",
        start.elapsed().as_secs_f64(),
        if cfg!(debug_assertions) {
            "debug"
        } else {
            "release"
        }
    );
    Ok(if ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

// ---------------------------------------------------------------------------------------------
// Rows, timing and helpers.

/// One measured figure: one error of one run.
#[derive(Clone, Debug)]
struct Row {
    scene: &'static str,
    /// `euler`, `prescribed`, `state`, `swept`, `discrete`, with `+substeps` for the rows
    /// that keep 60 Hz frames and take `substeps` sim steps per frame.
    method: String,
    /// Displayed frames per second: the frame dt is `1 / frame_hz`.
    frame_hz: u32,
    /// Sim steps per displayed frame: the sim's dt is `1 / (frame_hz * substeps)`.
    substeps: u32,
    kind: &'static str,
    error: f64,
    /// Wall seconds per simulated second.
    wall: f64,
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

/// A number as TOML: Rust's shortest round-trip form, which always has a `.` or an exponent,
/// so it reads back as the same `f64`.
fn num(x: f64) -> String {
    format!("{x:?}")
}

/// A vector as TOML.
fn vec2(v: Vec2) -> String {
    format!("[{}, {}]", num(v.x), num(v.y))
}

/// Loads generated scenario text; an error quotes the text.
fn load(text: &str, name: &str) -> anyhow::Result<Scenario> {
    load_scenario(text, name).with_context(|| format!("the generated scenario:\n{text}"))
}

/// Sim steps in `seconds` at `hz`: the durations are chosen to be whole numbers of steps.
fn steps_in(seconds: f64, hz: u32) -> u64 {
    let n = seconds * f64::from(hz);
    debug_assert!((n - n.round()).abs() < 1e-6, "{seconds} s at {hz} Hz");
    n.round() as u64
}

// ---------------------------------------------------------------------------------------------
// Projectile.

const PROJECTILE_X0: Vec2 = Vec2::new(0.0, 1.5);
const PROJECTILE_V0: Vec2 = Vec2::new(3.0, 12.0);
/// The projectile is compared at this time, seconds.
const PROJECTILE_T: f64 = 2.0;

fn projectile_text(hz: u32, offset: f64) -> String {
    let p = PROJECTILE_X0 + Vec2::splat(offset);
    format!(
        r#"name = "projectile"
hz = {hz}
layers = ["ball"]

[world]
gravity = [0.0, {g}]

[[bodies]]
name = "ball"
layer = "ball"
shape = {{ kind = "circle", radius = 0.1 }}
position = {p}
velocity = {v}
"#,
        g = num(-G),
        p = vec2(p),
        v = vec2(PROJECTILE_V0),
    )
}

/// Runs the projectile to t = 2 s and returns its position.
fn projectile_end(scenario: &Scenario, steps: u64) -> Vec2 {
    let mut sim = Simulation::new(scenario);
    for _ in 0..=steps {
        sim.step();
    }
    sim.world.position[0]
}

fn projectile_rows() -> anyhow::Result<Vec<Row>> {
    let g = Vec2::new(0.0, -G);
    let t = PROJECTILE_T;
    let exact = PROJECTILE_X0 + PROJECTILE_V0 * t + g * (0.5 * t * t);
    let mut rows = sweep("projectile", "euler", |hz, k| {
        let scenario = load(&projectile_text(hz * k, 0.0), "projectile.toml")?;
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
        let scenario = load(&projectile_text(hz * k, 0.0), "projectile.toml")?;
        let n = steps_in(t, hz * k);
        timed(t, || {
            let p = ricochet_oracle::rapier_free_flight(&scenario, n)[0].1;
            Ok(vec![("position", (p - exact).length())])
        })
    })?);
    Ok(rows)
}

// ---------------------------------------------------------------------------------------------
// Spring and orbit: x'' = -ω² x.

/// A harmonic scene: `x'' = -ω² x` from `x0`, `v0`, for `seconds`.
struct Harmonic {
    scene: &'static str,
    omega: f64,
    mass: f64,
    x0: Vec2,
    v0: Vec2,
    seconds: f64,
}

/// A body on a spring: amplitude 1, period 2 s, 5 periods.
const SPRING: Harmonic = Harmonic {
    scene: "spring",
    omega: PI,
    mass: 1.0,
    x0: Vec2::new(1.0, 0.0),
    v0: Vec2::ZERO,
    seconds: 10.0,
};

/// A circular orbit: radius 10, period 10 s, for 10,000 frames at 60 Hz (166.7 s, 16.7
/// orbits) whatever the timestep.
const ORBIT: Harmonic = Harmonic {
    scene: "orbit",
    omega: 2.0 * PI / 10.0,
    mass: 2.0,
    x0: Vec2::new(10.0, 0.0),
    v0: Vec2::new(0.0, 2.0 * PI),
    seconds: 10_000.0 / 60.0,
};

impl Harmonic {
    /// The exact position and velocity at `t`.
    fn exact(&self, t: f64) -> (Vec2, Vec2) {
        let (s, c) = libm::sincos(self.omega * t);
        (
            self.x0 * c + self.v0 * (s / self.omega),
            self.x0 * (-self.omega * s) + self.v0 * c,
        )
    }

    /// `m v²/2 + m ω² x²/2`, constant along the exact solution.
    fn energy(&self, x: Vec2, v: Vec2) -> f64 {
        0.5 * self.mass * (v.length_squared() + self.omega * self.omega * x.length_squared())
    }

    fn text(&self, hz: u32, script: &str) -> String {
        format!(
            r#"name = "{name}"
hz = {hz}
layers = ["mass"]
script = [{script}]

[[bodies]]
name = "mass"
layer = "mass"
mass = {m}
shape = {{ kind = "circle", radius = 0.1 }}
position = {p}
velocity = {v}
"#,
            name = self.scene,
            m = num(self.mass),
            p = vec2(self.x0),
            v = vec2(self.v0),
        )
    }

    /// The force of step `s` (from frame s-1 to frame s): prescribed from the exact position
    /// at the start of the step, or computed from the body's current position.
    fn force(&self, s: u64, dt: f64, state: Option<Vec2>) -> Vec2 {
        let x = state.unwrap_or_else(|| self.exact((s - 1) as f64 * dt).0);
        x * (-self.mass * self.omega * self.omega)
    }

    /// One run: `hz * k` sim steps per second, errors sampled at every displayed frame.
    fn run(&self, scenario: &Scenario, hz: u32, k: u32, state: bool, seconds: f64) -> Errors {
        let mut sim = Simulation::new(scenario);
        let dt = sim.dt();
        let steps = steps_in(seconds, hz * k);
        let e0 = self.energy(self.x0, self.v0);
        let (mut position, mut energy) = (0.0_f64, 0.0_f64);
        sim.step();
        for s in 1..=steps {
            // What a `set_force` event at frame s does, before anything moves.
            sim.world.force[0] = self.force(s, dt, state.then(|| sim.world.position[0]));
            sim.step();
            if s % u64::from(k) == 0 {
                let (x, _) = self.exact(s as f64 * dt);
                let (p, v) = (sim.world.position[0], sim.world.velocity[0]);
                position = position.max((p - x).length());
                energy = energy.max((self.energy(p, v) - e0).abs() / e0);
            }
        }
        vec![("position", position), ("energy", energy)]
    }
}

fn harmonic_rows(h: &Harmonic) -> anyhow::Result<Vec<Row>> {
    let mut rows = Vec::new();
    for (method, state) in [("prescribed", false), ("state", true)] {
        rows.extend(sweep(h.scene, method, |hz, k| {
            let scenario = load(&h.text(hz * k, ""), "harmonic.toml")?;
            // Measured over the whole run; timed over at most its first 10 s, which cost the
            // same per step: short runs are the ones other processes disturb least.
            let errors = h.run(&scenario, hz, k, state, h.seconds);
            let seconds = h.seconds.min(TIMED_SECONDS);
            let t = timed(seconds, || Ok(h.run(&scenario, hz, k, state, seconds)))?;
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
    let mut script = String::new();
    for s in 1..=steps {
        let f = h.force(s, dt, None);
        write!(
            script,
            "\n  {{ frame = {s}, action = \"set_force\", body = \"mass\", force = {} }},",
            vec2(f)
        )?;
    }
    script.push('\n');
    let scripted = load(&h.text(hz, &script), "spring-script.toml")?;
    ensure!(scripted.world.dt == dt, "dt is not 1/30 as computed here");
    let mut sim = Simulation::new(&scripted);
    for _ in 0..=steps {
        sim.step();
    }
    let direct = load(&h.text(hz, ""), "spring.toml")?;
    let mut other = Simulation::new(&direct);
    other.step();
    for s in 1..=steps {
        other.world.force[0] = h.force(s, dt, None);
        other.step();
    }
    Ok(sim.world.digest() == other.world.digest())
}

// ---------------------------------------------------------------------------------------------
// A box dropping onto a floor.

/// The box's half size. Neither it nor the floor's half height is a power of two, so the
/// sums that place the box flush round as they would in a game.
const BOX_HALF: f64 = 0.3;
/// The floor's half height; its top is at y = 0 (plus the offset).
const FLOOR_HALF: f64 = 0.45;
/// The height of the box's bottom above the floor's top at the start.
const DROP_HEIGHT: f64 = 4.75;
/// How long the drop runs, seconds (it lands after about 1 s).
const DROP_SECONDS: f64 = 2.0;

fn drop_text(hz: u32, offset: f64) -> String {
    format!(
        r#"name = "drop"
hz = {hz}
layers = ["box", "ground"]

[world]
gravity = [0.0, {g}]

[[collide]]
a = "box"
b = "ground"
response = "separate"

[[bodies]]
name = "floor"
layer = "ground"
kind = "static"
shape = {{ kind = "aabb", half_extents = [20.0, {fh}] }}
position = {floor}

[[bodies]]
name = "box"
layer = "box"
shape = {{ kind = "aabb", half_extents = [{h}, {h}] }}
position = {ball}
"#,
        g = num(-G),
        h = num(BOX_HALF),
        fh = num(FLOOR_HALF),
        floor = vec2(Vec2::new(offset, offset - FLOOR_HALF)),
        ball = vec2(Vec2::new(offset, offset + DROP_HEIGHT + BOX_HALF)),
    )
}

/// The first step whose semi-implicit-Euler position puts the box's bottom below the floor's
/// top: `bottom_n = bottom_0 - g dt² n(n+1)/2` (exact arithmetic, from rest).
fn exact_landing_step(hz: u32) -> anyhow::Result<u64> {
    let h = f64::from(hz);
    // Below the top when n(n+1) > 2 height hz² / g.
    let q = 2.0 * DROP_HEIGHT * h * h / G;
    let mut n: u64 = 1;
    while ((n * (n + 1)) as f64) <= q {
        n += 1;
    }
    // The gap on either side of the boundary, in units: far above rounding and SLOP.
    let gap = |m: u64| ((m * (m + 1)) as f64 - q).abs() * G / (2.0 * h * h);
    ensure!(
        gap(n) > 1e-6 && gap(n - 1) > 1e-6,
        "the landing at {hz} Hz is a near tie"
    );
    Ok(n)
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
    let rest = sim.world.position[floor].y + FLOOR_HALF + BOX_HALF;
    for s in 1..=steps {
        let out = sim.step();
        if landed.is_none() && out.contacts.iter().any(|c| c.phase == Phase::Y) {
            landed = Some(s);
        }
        if landed.is_some() && s % u64::from(k) == 0 {
            rest_error = rest_error.max((sim.world.position[ball].y - rest).abs());
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
        let scenario = load(&drop_text(hz * k, 0.0), "drop.toml")?;
        let exact = exact_landing_step(hz * k)?;
        let steps = steps_in(DROP_SECONDS, hz * k);
        timed(DROP_SECONDS, || {
            let (landed, rest) = drop_run(&scenario, k, steps);
            Ok(drop_errors(landed, rest, exact))
        })
    })
}

// ---------------------------------------------------------------------------------------------
// Bullets through a field of rocks.

/// The bullets' radius.
const BULLET_RADIUS: f64 = 0.05;
/// How far past the start every bullet has gone when a run ends, units.
const BULLET_RANGE: f64 = 125.0;

/// Rocks (centre, radius) and bullets (start, unit direction); the exact first hit of each
/// bullet (the index of a rock), or none.
struct Field {
    rocks: Vec<(Vec2, f64)>,
    bullets: Vec<(Vec2, Vec2)>,
    first_hits: Vec<Option<usize>>,
}

/// SplitMix64: a fixed, portable sequence (no `rand`, the same field on every machine).
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `[lo, hi)`.
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        let unit = (self.next() >> 11) as f64 / (1_u64 << 53) as f64;
        lo + (hi - lo) * unit
    }
}

/// Where a ray from `p` along unit `d` enters the circle (`c`, `r`): the distance along the
/// ray, and how far the ray's closest approach is from grazing (positive inside).
fn ray_entry(p: Vec2, d: Vec2, c: Vec2, r: f64) -> (Option<f64>, f64) {
    let to = c - p;
    let along = to.dot(d);
    let miss = (to.x * d.y - to.y * d.x).abs();
    let margin = r - miss;
    if margin <= 0.0 || along <= 0.0 {
        return (None, margin);
    }
    (Some(along - (r * r - miss * miss).sqrt()), margin)
}

impl Field {
    /// 40 rocks of radius 0.5 to 1.5 in x 5..95, y -15..15; 24 bullets from x = -10, spread
    /// over y -18..18, within ±0.1 rad of +x. A bullet whose ray grazes a rock, or enters
    /// two rocks at nearly the same distance, is re-aimed: the exact answer must be clear.
    fn new() -> anyhow::Result<Field> {
        let mut rng = SplitMix(0x005e_ed0f_a57e_501d);
        let rocks: Vec<(Vec2, f64)> = (0..40)
            .map(|_| {
                let c = Vec2::new(rng.uniform(5.0, 95.0), rng.uniform(-15.0, 15.0));
                (c, rng.uniform(0.5, 1.5))
            })
            .collect();
        let mut bullets = Vec::new();
        let mut first_hits = Vec::new();
        for i in 0..24 {
            let p = Vec2::new(-10.0, -18.0 + 36.0 * f64::from(i) / 23.0);
            let mut tries = 0;
            loop {
                tries += 1;
                ensure!(tries < 100, "no clear aim for bullet {i}");
                let a = rng.uniform(-0.1, 0.1);
                let (s, c) = libm::sincos(a);
                let d = Vec2::new(c, s);
                let mut entries: Vec<(f64, usize)> = Vec::new();
                let mut clear = true;
                for (k, &(centre, r)) in rocks.iter().enumerate() {
                    let (entry, margin) = ray_entry(p, d, centre, r + BULLET_RADIUS);
                    clear &= margin.abs() > 1e-3;
                    if let Some(e) = entry {
                        entries.push((e, k));
                    }
                }
                entries.sort_by(|a, b| a.0.total_cmp(&b.0));
                if entries.len() >= 2 && entries[1].0 - entries[0].0 < 1e-3 {
                    clear = false;
                }
                if clear {
                    bullets.push((p, d));
                    first_hits.push(entries.first().map(|e| e.1));
                    break;
                }
            }
        }
        Ok(Field {
            rocks,
            bullets,
            first_hits,
        })
    }

    /// The field as a scenario, moved by `offset` on both axes, bullets at `speed`.
    fn text(&self, hz: u32, speed: f64, swept: bool, offset: f64) -> String {
        let shift = Vec2::splat(offset);
        let mut s = format!(
            "name = \"bullets\"\nhz = {hz}\nlayers = [\"rock\", \"bullet\"]\n{}\n\
             [[collide]]\na = \"bullet\"\nb = \"rock\"\nresponse = \"destroy\"\n\
             destroy = \"a\"\n",
            if swept {
                "fast_layers = [\"bullet\"]\n"
            } else {
                ""
            }
        );
        for (k, &(c, r)) in self.rocks.iter().enumerate() {
            s += &format!(
                "\n[[bodies]]\nname = \"rock{k}\"\nlayer = \"rock\"\nkind = \"static\"\n\
                 shape = {{ kind = \"circle\", radius = {} }}\nposition = {}\n",
                num(r),
                vec2(c + shift)
            );
        }
        for (k, &(p, d)) in self.bullets.iter().enumerate() {
            s += &format!(
                "\n[[bodies]]\nname = \"bullet{k}\"\nlayer = \"bullet\"\n\
                 shape = {{ kind = \"circle\", radius = {} }}\nposition = {}\nvelocity = {}\n",
                num(BULLET_RADIUS),
                vec2(p + shift),
                vec2(d * speed)
            );
        }
        s
    }

    /// Steps until every bullet is `BULLET_RANGE` past its start (plus one frame), and counts
    /// the bullets whose recorded hits are not exactly `{their exact first hit}`.
    fn wrong_hits(&self, scenario: &Scenario, steps: u64) -> f64 {
        let n_rocks = self.rocks.len();
        let mut hits: Vec<Vec<usize>> = vec![Vec::new(); self.bullets.len()];
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
            .zip(&self.first_hits)
            .filter(|(got, want)| {
                let want: Vec<usize> = want.iter().copied().collect();
                **got != want
            })
            .count();
        wrong as f64
    }

    /// Sim steps (after frame 0) for every bullet to cover `BULLET_RANGE` at `speed`.
    fn steps(speed: f64, hz: u32) -> u64 {
        let seconds = BULLET_RANGE / (speed * libm::cos(0.1));
        (seconds * f64::from(hz)).ceil() as u64 + 1
    }
}

fn bullet_rows(field: &Field) -> anyhow::Result<Vec<Row>> {
    let mut rows = Vec::new();
    for (method, swept) in [("swept", true), ("discrete", false)] {
        rows.extend(sweep("bullets", method, |hz, k| {
            let h = hz * k;
            let scenario = load(&field.text(h, BULLET_SPEED, swept, 0.0), "bullets.toml")?;
            let steps = Field::steps(BULLET_SPEED, h);
            timed(steps as f64 / f64::from(h), || {
                Ok(vec![(
                    "wrong_first_hits",
                    field.wrong_hits(&scenario, steps),
                )])
            })
        })?);
    }
    Ok(rows)
}

// ---------------------------------------------------------------------------------------------
// Stability: far from the origin, and fast.

/// What the scenes measure `offset` units from the origin (both axes), at 60 Hz.
struct OffsetResult {
    offset: f64,
    /// How far the projectile's end position moved from the run at the origin (rounding).
    projectile: f64,
    /// The drop's landing step minus the exact one.
    landing: f64,
    /// The drop's largest distance from the rest height after landing.
    rest: f64,
    /// Bullets (swept, 300 units/s) whose hits are not the exact first hit.
    swept_wrong: f64,
}

fn offset_study(field: &Field) -> anyhow::Result<Vec<OffsetResult>> {
    let hz = 60;
    let n = steps_in(PROJECTILE_T, hz);
    let origin = projectile_end(&load(&projectile_text(hz, 0.0), "projectile.toml")?, n);
    let exact_landing = exact_landing_step(hz)?;
    let drop_steps = steps_in(DROP_SECONDS, hz);
    let bullet_steps = Field::steps(BULLET_SPEED, hz);
    let mut results = Vec::new();
    for offset in OFFSETS {
        let p = projectile_end(&load(&projectile_text(hz, offset), "projectile.toml")?, n);
        let (landed, rest) = drop_run(&load(&drop_text(hz, offset), "drop.toml")?, 1, drop_steps);
        let d = drop_errors(landed, rest, exact_landing);
        let bullets = load(&field.text(hz, BULLET_SPEED, true, offset), "bullets.toml")?;
        results.push(OffsetResult {
            offset,
            projectile: (p - Vec2::splat(offset) - origin).length(),
            landing: d[0].1,
            rest: d[1].1,
            swept_wrong: field.wrong_hits(&bullets, bullet_steps),
        });
    }
    Ok(results)
}

/// Bullets at `speed`, 60 Hz: wrong first hits and wall time, swept and discrete.
struct SpeedResult {
    speed: f64,
    swept_wrong: f64,
    discrete_wrong: f64,
    swept_wall: f64,
    discrete_wall: f64,
}

fn speed_study(field: &Field) -> anyhow::Result<Vec<SpeedResult>> {
    let hz = 60;
    let mut results = Vec::new();
    for speed in SPEEDS {
        let steps = Field::steps(speed, hz);
        let seconds = steps as f64 / f64::from(hz);
        let swept = load(&field.text(hz, speed, true, 0.0), "bullets.toml")?;
        let discrete = load(&field.text(hz, speed, false, 0.0), "bullets.toml")?;
        let s = timed(seconds, || {
            Ok(vec![("wrong_first_hits", field.wrong_hits(&swept, steps))])
        })?;
        let d = timed(seconds, || {
            Ok(vec![(
                "wrong_first_hits",
                field.wrong_hits(&discrete, steps),
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

// ---------------------------------------------------------------------------------------------
// Checks, tables, CSV.

/// The rows of one scene, method and kind, in sweep order.
fn series<'a>(rows: &'a [Row], scene: &str, method: &str, kind: &str) -> Vec<&'a Row> {
    rows.iter()
        .filter(|r| r.scene == scene && r.method == method && r.kind == kind)
        .collect()
}

/// The acceptance checks: (passed, what).
fn checks(rows: &[Row], script_matches: bool) -> Vec<(bool, String)> {
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

fn table(rows: &[Row]) -> String {
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

fn offset_table(results: &[OffsetResult]) -> String {
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

fn speed_table(results: &[SpeedResult]) -> String {
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
fn csv_text(rows: &[Row]) -> String {
    let mut s = "scene,method,dt,substeps,error_kind,error,wall_s_per_sim_s\n".to_owned();
    for r in rows {
        let _ = writeln!(
            s,
            "{},{},{:e},{},{},{:e},{:e}",
            r.scene,
            r.method,
            1.0 / f64::from(r.frame_hz),
            r.substeps,
            r.kind,
            r.error,
            r.wall
        );
    }
    s
}

// ---------------------------------------------------------------------------------------------
// The chart: a hand-written SVG, error against wall time per simulated second, log-log.

/// The series drawn: (scene, method, kind, legend text).
const CHART: [(&str, &str, &str, &str); 11] = [
    (
        "projectile",
        "euler",
        "position",
        "projectile: position at 2 s (units)",
    ),
    (
        "projectile",
        "rapier",
        "position",
        "projectile, rapier2d: position at 2 s (units)",
    ),
    (
        "spring",
        "prescribed",
        "position",
        "spring, prescribed: max position (units)",
    ),
    (
        "spring",
        "state",
        "position",
        "spring, state force: max position (units)",
    ),
    (
        "orbit",
        "prescribed",
        "position",
        "orbit, prescribed: max position (units)",
    ),
    (
        "orbit",
        "state",
        "position",
        "orbit, state force: max position (units)",
    ),
    (
        "orbit",
        "prescribed",
        "energy",
        "orbit, prescribed: max energy (relative)",
    ),
    (
        "orbit",
        "state",
        "energy",
        "orbit, state force: max energy (relative)",
    ),
    ("drop", "euler", "rest_height", "drop: rest height (units)"),
    (
        "bullets",
        "swept",
        "wrong_first_hits",
        "bullets, swept: wrong first hits (of 24)",
    ),
    (
        "bullets",
        "discrete",
        "wrong_first_hits",
        "bullets, discrete: wrong first hits (of 24)",
    ),
];

const COLOURS: [&str; 11] = [
    "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
    "#bcbd22", "#17becf", "#000000",
];

/// `10^k` as SVG text.
fn power_label(k: i32) -> String {
    match k {
        0 => "1".to_owned(),
        1 => "10".to_owned(),
        _ => format!("10<tspan dy=\"-7\" font-size=\"10\">{k}</tspan>"),
    }
}

fn svg_text(rows: &[Row]) -> String {
    let (width, height) = (1000.0, 640.0);
    let (left, right, top, bottom) = (80.0, 620.0, 60.0, 570.0);
    let drawn: Vec<&Row> = rows
        .iter()
        .filter(|r| {
            CHART.iter().any(|(scene, method, kind, _)| {
                r.scene == *scene
                    && r.kind == *kind
                    && (r.method == *method || r.method == format!("{method}+substeps"))
            })
        })
        .collect();
    let walls = drawn.iter().map(|r| libm::log10(r.wall));
    let x_lo = walls.clone().fold(f64::INFINITY, f64::min).floor() as i32;
    let x_hi = walls.fold(f64::NEG_INFINITY, f64::max).ceil() as i32;
    let errors = drawn
        .iter()
        .filter(|r| r.error > 0.0 && r.error.is_finite())
        .map(|r| libm::log10(r.error));
    let y_lo = errors.clone().fold(f64::INFINITY, f64::min).floor() as i32;
    let y_hi = errors.fold(f64::NEG_INFINITY, f64::max).ceil() as i32;
    let x_hi = x_hi.max(x_lo + 1);
    // One decade below the smallest error is the row of exact zeros.
    let y_zero = y_lo - 1;
    let y_hi = y_hi.max(y_zero + 1);
    let sx = |w: f64| {
        left + (libm::log10(w) - f64::from(x_lo)) / f64::from(x_hi - x_lo) * (right - left)
    };
    let sy_log =
        |l: f64| bottom - (l - f64::from(y_zero)) / f64::from(y_hi - y_zero) * (bottom - top);
    let sy = |e: f64| {
        if e > 0.0 {
            sy_log(libm::log10(e).max(f64::from(y_zero)))
        } else {
            sy_log(f64::from(y_zero))
        }
    };

    let mut s = String::new();
    let _ = writeln!(
        s,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" height=\"{height}\" \
         viewBox=\"0 0 {width} {height}\" font-family=\"sans-serif\" font-size=\"12\">"
    );
    let _ = writeln!(s, "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>");
    let _ = writeln!(
        s,
        "<text x=\"{}\" y=\"28\" font-size=\"16\" text-anchor=\"middle\">Ricochet accuracy: error \
         against run time (ricochet accuracy, {} build)</text>",
        width / 2.0,
        if cfg!(debug_assertions) {
            "debug"
        } else {
            "release"
        }
    );
    // Grid and ticks.
    for k in x_lo..=x_hi {
        let x = left + f64::from(k - x_lo) / f64::from(x_hi - x_lo) * (right - left);
        let _ = writeln!(
            s,
            "<line x1=\"{x:.1}\" y1=\"{top}\" x2=\"{x:.1}\" y2=\"{bottom}\" stroke=\"#e0e0e0\"/>\
             <text x=\"{x:.1}\" y=\"{}\" text-anchor=\"middle\">{}</text>",
            bottom + 18.0,
            power_label(k)
        );
    }
    for k in y_zero..=y_hi {
        let y = sy_log(f64::from(k));
        let label = if k == y_zero {
            "0 (exact)".to_owned()
        } else {
            power_label(k)
        };
        let _ = writeln!(
            s,
            "<line x1=\"{left}\" y1=\"{y:.1}\" x2=\"{right}\" y2=\"{y:.1}\" stroke=\"{}\"/>\
             <text x=\"{}\" y=\"{:.1}\" text-anchor=\"end\">{label}</text>",
            if k == y_zero { "#999999" } else { "#e0e0e0" },
            left - 6.0,
            y + 4.0
        );
    }
    let _ = writeln!(
        s,
        "<rect x=\"{left}\" y=\"{top}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"black\"/>",
        right - left,
        bottom - top
    );
    let _ = writeln!(
        s,
        "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">wall seconds per simulated second \
         (log scale; smaller dt is further right)</text>",
        (left + right) / 2.0,
        bottom + 42.0
    );
    let _ = writeln!(
        s,
        "<text transform=\"translate(22 {}) rotate(-90)\" text-anchor=\"middle\">error against \
         the exact answer (log scale; units per series in the legend)</text>",
        (top + bottom) / 2.0
    );
    // Series: a polyline over the dt sweep (1/30 to 1/960), open circles for the substep rows.
    for (n, (scene, method, kind, _)) in CHART.iter().enumerate() {
        let colour = COLOURS[n];
        let dash = if *kind == "energy" {
            " stroke-dasharray=\"6 3\""
        } else if *method == "discrete" {
            " stroke-dasharray=\"2 3\""
        } else {
            ""
        };
        let line = series(rows, scene, method, kind);
        let points: Vec<String> = line
            .iter()
            .filter(|r| r.error.is_finite())
            .map(|r| format!("{:.1},{:.1}", sx(r.wall), sy(r.error)))
            .collect();
        let _ = writeln!(
            s,
            "<polyline fill=\"none\" stroke=\"{colour}\" stroke-width=\"1.6\"{dash} points=\"{}\"/>",
            points.join(" ")
        );
        for r in line.iter().filter(|r| r.error.is_finite()) {
            let _ = writeln!(
                s,
                "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"3\" fill=\"{colour}\"/>",
                sx(r.wall),
                sy(r.error)
            );
        }
        for r in series(rows, scene, &format!("{method}+substeps"), kind)
            .iter()
            .filter(|r| r.error.is_finite())
        {
            let _ = writeln!(
                s,
                "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"5\" fill=\"none\" stroke=\"{colour}\"/>",
                sx(r.wall),
                sy(r.error)
            );
        }
    }
    // Legend.
    let lx = right + 20.0;
    for (n, (_, method, kind, text)) in CHART.iter().enumerate() {
        let y = top + 10.0 + 22.0 * n as f64;
        let dash = if *kind == "energy" {
            " stroke-dasharray=\"6 3\""
        } else if *method == "discrete" {
            " stroke-dasharray=\"2 3\""
        } else {
            ""
        };
        let _ = writeln!(
            s,
            "<line x1=\"{lx}\" y1=\"{y}\" x2=\"{}\" y2=\"{y}\" stroke=\"{}\" stroke-width=\"1.6\"{dash}/>\
             <circle cx=\"{}\" cy=\"{y}\" r=\"3\" fill=\"{}\"/>\
             <text x=\"{}\" y=\"{}\">{text}</text>",
            lx + 26.0,
            COLOURS[n],
            lx + 13.0,
            COLOURS[n],
            lx + 32.0,
            y + 4.0
        );
    }
    let notes = [
        "Filled points: dt = 1/30, 1/60, ... 1/960 s, one step per frame.",
        "Open circles: 60 Hz frames with 1, 2, 4 sim steps each.",
        "Errors of exactly 0 sit on the bottom line.",
        "Wall time: one 2-core machine; compare within one chart.",
    ];
    for (n, note) in notes.iter().enumerate() {
        let _ = writeln!(
            s,
            "<text x=\"{lx}\" y=\"{}\" font-size=\"11\" fill=\"#444444\">{note}</text>",
            top + 10.0 + 22.0 * CHART.len() as f64 + 12.0 + 16.0 * n as f64
        );
    }
    s.push_str("</svg>\n");
    s
}
