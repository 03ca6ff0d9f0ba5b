//! `ricochet bench`: Ricochet's full step against rapier2d's collision-only pipeline, on
//! built-in scenes of parametric size, in the same process on the same frames.
//!
//! Scenes are generated here as a [`Scenario`] (seeded, so every run builds the same scene):
//!
//! - `asteroids-N`: `N` asteroids (circles and convex polygons of radius 0.5 to 3, random
//!   velocities and spins), 100 bullets (layer `bullet`, in `fast_layers`: swept), one ship,
//!   in a wrap-around world of side `sqrt(N) * 20`. Asteroids ignore each other; bullets and
//!   the ship `report` against asteroids, so nothing is destroyed and the body count stays
//!   the same for the whole run (a benchmark of a shrinking world would measure nothing).
//! - `platformer-T-A`: `T` static 1×1 AABB tiles in floors 5 units apart (every floor but the
//!   lowest has a one-tile gap every 8 tiles, offset from floor to floor), `A` dynamic 0.8×0.8
//!   boxes under gravity that patrol (`walker`), fall through the gaps and `separate` from the
//!   tiles per axis; actors `report` against each other. The world wraps along x.
//! - `rain-N`: `N` shapes of all five kinds (circle, aabb, obb, capsule, polygon), spinning
//!   and falling through `max(10, N/10)` static shapes of all five kinds; every pair `report`s
//!   (so nothing moves anything), in a wrap-around world of side `sqrt(N) * 8`.
//!
//! Each scene: frame 0 (the initial state) is stepped by both engines untimed (rapier's
//! first step builds its tree from scratch). Then for each of `frames` frames: Ricochet's
//! `Simulation::step()` is timed; every moving body's pose is copied into rapier (untimed);
//! rapier's `CollisionPipeline::step` is timed; the two contact sets are compared
//! ([`ricochet_oracle::bench::compare_contacts`] documents the rule) on every frame,
//! frame 0 included.
//!
//! Every scene runs in a fresh process (this executable again, see [`CHILD_ENV`]), so that
//! its memory figures do not include heap the allocator kept from an earlier scene. Memory
//! is that process's peak resident set (`VmHWM` in `/proc/self/status`, also reset at the
//! scene's start by writing `5` to `/proc/self/clear_refs`): `ricochet_mb` is read once
//! Ricochet's world is built and has stepped frame 0, before rapier's world exists (the
//! scenario and the simulation's copy of it both count: `Simulation::new` clones it);
//! `peak_mem_mb` at the end of the scene, both engines alive. Both include the process's own
//! few megabytes.
//!
//! Wall time is measured with [`Instant`]: it is a benchmark figure printed and written here,
//! and never reaches a log or a test assertion.

use std::fmt::Write as _;
use std::path::Path;
use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::{Context, bail};
use ricochet_geom::{Shape, Vec2};
use ricochet_oracle::bench::{CONTACT_TOLERANCE, ContactAgreement, RapierScene, compare_contacts};
use ricochet_sim::{
    BodyDef, BodyKind, Controller, LayerId, Layers, Response, Scenario, Simulation, WorldBounds,
    WorldDef,
};
use serde::{Deserialize, Serialize};

/// The scenes `ricochet bench` runs when none is named.
pub const DEFAULT_SCENES: [&str; 3] = ["asteroids-10000", "platformer-10000-100", "rain-10000"];

/// The CSV header, one row per scene below it.
pub const CSV_HEADER: &str = "scene,frames,ricochet_median_ms,ricochet_p95_ms,rapier_median_ms,\
                              rapier_p95_ms,ratio,contact_agreement,peak_mem_mb,\
                              ricochet_alone_median_ms";

/// Seconds per step of every scene.
const DT: f64 = 1.0 / 60.0;
/// Set in the environment of the process that runs one scene (`run` starts one per scene):
/// it runs the scenes in-process and prints each result as a JSON line. Set it yourself to
/// run everything in one process, under a profiler for example.
pub const CHILD_ENV: &str = "RICOCHET_BENCH_CHILD";
/// What starts a result line on a child's stdout.
const ROW_PREFIX: &str = "ricochet-bench-row ";
/// Bullets in an `asteroids-N` scene.
const BULLETS: usize = 100;
/// Bullet speed, units/s: 1 unit a frame, five times a bullet's size.
const BULLET_SPEED: f64 = 60.0;
/// Vertical distance between two platformer floors.
const FLOOR_SPACING: f64 = 5.0;

/// A built-in scene and its size.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum SceneKind {
    Asteroids { asteroids: usize },
    Platformer { tiles: usize, actors: usize },
    Rain { shapes: usize },
}

/// Parses `asteroids-N`, `platformer-T-A` or `rain-N`.
fn parse_scene(name: &str) -> anyhow::Result<SceneKind> {
    let count = |s: &str| -> anyhow::Result<usize> {
        let n: usize = s
            .replace('_', "")
            .parse()
            .with_context(|| format!("scene {name:?}: {s:?} is not a count"))?;
        if n == 0 {
            bail!("scene {name:?}: counts must be at least 1");
        }
        Ok(n)
    };
    let parts: Vec<&str> = name.split('-').collect();
    match parts.as_slice() {
        ["asteroids", n] => Ok(SceneKind::Asteroids {
            asteroids: count(n)?,
        }),
        ["platformer", t, a] => Ok(SceneKind::Platformer {
            tiles: count(t)?,
            actors: count(a)?,
        }),
        ["rain", n] => Ok(SceneKind::Rain { shapes: count(n)? }),
        _ => bail!(
            "unknown scene {name:?}: expected asteroids-N, platformer-TILES-ACTORS or rain-N \
             (for example asteroids-10000, platformer-10000-1000, rain-10000)"
        ),
    }
}

/// SplitMix64: a tiny seeded generator, so a scene is the same on every run and machine.
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `[lo, hi)`.
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    /// Uniform in `0..n`.
    fn below(&mut self, n: usize) -> usize {
        ((self.next_u64() >> 32) as usize * n) >> 32
    }

    /// A random direction times `speed`.
    fn velocity(&mut self, speed: f64) -> Vec2 {
        let (s, c) = libm::sincos(self.range(0.0, std::f64::consts::TAU));
        Vec2::new(c, s) * speed
    }
}

/// A convex polygon of `n` vertices on a circle of `radius`, at jittered angles (points on a
/// circle in counter-clockwise order are always strictly convex).
fn round_polygon(rng: &mut Rng, n: usize, radius: f64) -> Shape {
    let step = std::f64::consts::TAU / n as f64;
    let phase = rng.range(0.0, step);
    let vertices: Vec<Vec2> = (0..n)
        .map(|k| {
            let a = phase + step * k as f64 + rng.range(-0.25, 0.25) * step;
            let (s, c) = libm::sincos(a);
            Vec2::new(c, s) * radius
        })
        .collect();
    Shape::polygon(&vertices).expect("points on a circle, counter-clockwise, are convex")
}

/// Layers with names and the listed `report`/`separate` pairs; everything else ignored.
fn layers(names: &[&str], pairs: &[(LayerId, LayerId, Response)]) -> Layers {
    let mut l = Layers::new(names.iter().map(|n| (*n).to_owned()).collect());
    for &(a, b, r) in pairs {
        l.set(a, b, r);
    }
    l
}

fn scenario(name: &str, world: WorldDef, bodies: Vec<BodyDef>, frames: u64) -> Scenario {
    Scenario {
        name: name.to_owned(),
        world,
        frames,
        templates: std::collections::BTreeMap::new(),
        bodies,
        script: Vec::new(),
    }
}

/// `asteroids-N`: see the module docs.
fn asteroids(name: &str, n: usize, frames: u64) -> Scenario {
    const SHIP: LayerId = 0;
    const ASTEROID: LayerId = 1;
    const BULLET: LayerId = 2;
    let mut rng = Rng(0xa57e_0001 ^ n as u64);
    let side = (n as f64).sqrt() * 20.0;
    let mut l = layers(
        &["ship", "asteroid", "bullet"],
        &[
            (SHIP, ASTEROID, Response::Report),
            (BULLET, ASTEROID, Response::Report),
        ],
    );
    l.set_fast(BULLET);
    let world = WorldDef {
        dt: DT,
        gravity: Vec2::ZERO,
        bounds: Some(WorldBounds {
            min: Vec2::ZERO,
            max: Vec2::splat(side),
            wrap: true,
        }),
        layers: l,
        ..WorldDef::default()
    };
    let mut bodies = Vec::with_capacity(n + BULLETS + 1);
    bodies.push(BodyDef {
        name: "ship".to_owned(),
        layer: SHIP,
        shape: Shape::polygon(&[
            Vec2::new(1.0, 0.0),
            Vec2::new(-0.7, 0.6),
            Vec2::new(-0.7, -0.6),
        ])
        .expect("a counter-clockwise triangle"),
        position: Vec2::splat(side * 0.5),
        velocity: Vec2::new(2.0, 1.0),
        angular_velocity: 0.5,
        ..BodyDef::default()
    });
    for k in 0..n {
        let radius = rng.range(0.5, 3.0);
        let shape = if k % 2 == 0 {
            Shape::circle(radius).expect("a positive radius")
        } else {
            let sides = 5 + rng.below(4);
            round_polygon(&mut rng, sides, radius)
        };
        bodies.push(BodyDef {
            name: "asteroid".to_owned(),
            layer: ASTEROID,
            shape,
            position: Vec2::new(rng.range(0.0, side), rng.range(0.0, side)),
            angle: rng.range(0.0, std::f64::consts::TAU),
            velocity: {
                let speed = rng.range(0.5, 5.0);
                rng.velocity(speed)
            },
            angular_velocity: rng.range(-1.0, 1.0),
            ..BodyDef::default()
        });
    }
    // Long enough that no bullet expires during the run: the body count stays the same.
    let lifetime = u32::try_from(frames.saturating_add(60)).unwrap_or(u32::MAX);
    for _ in 0..BULLETS {
        bodies.push(BodyDef {
            name: "bullet".to_owned(),
            layer: BULLET,
            shape: Shape::circle(0.1).expect("a positive radius"),
            position: Vec2::new(rng.range(0.0, side), rng.range(0.0, side)),
            velocity: rng.velocity(BULLET_SPEED),
            lifetime: Some(lifetime),
            ..BodyDef::default()
        });
    }
    scenario(name, world, bodies, frames)
}

/// `platformer-T-A`: see the module docs.
fn platformer(name: &str, tiles: usize, actors: usize, frames: u64) -> Scenario {
    const TILE: LayerId = 0;
    const ACTOR: LayerId = 1;
    let mut rng = Rng(0x91a7_0002 ^ ((tiles as u64) << 20) ^ actors as u64);
    // Floors sqrt(8 T) tiles wide, so the level is about as wide as it is tall in world units
    // (floors are 5 apart); a multiple of 8, so the gap pattern continues across the wrap.
    let width = ((8.0 * tiles as f64).sqrt().ceil() as usize)
        .div_ceil(8)
        .max(2)
        * 8;
    let mut bodies = Vec::with_capacity(tiles + actors);
    let mut floor = 0usize;
    'floors: loop {
        for col in 0..width {
            if bodies.len() == tiles {
                break 'floors;
            }
            if floor > 0 && (col + 3 * floor) % 8 == 4 {
                continue;
            }
            bodies.push(BodyDef {
                name: "tile".to_owned(),
                layer: TILE,
                kind: BodyKind::Static,
                shape: Shape::aabb(Vec2::splat(0.5)).expect("positive half extents"),
                position: Vec2::new(col as f64 + 0.5, floor as f64 * FLOOR_SPACING),
                ..BodyDef::default()
            });
        }
        floor += 1;
    }
    // Actors start above the complete floors (`floor` is the first incomplete one).
    let floors = floor.max(1);
    for k in 0..actors {
        let f = rng.below(floors) as f64;
        let speed = rng.range(1.0, 3.0) * if rng.unit() < 0.5 { -1.0 } else { 1.0 };
        bodies.push(BodyDef {
            name: "actor".to_owned(),
            layer: ACTOR,
            shape: Shape::aabb(Vec2::splat(0.4)).expect("positive half extents"),
            // Half of them standing on the floor (its top is at +0.5), half dropping from
            // up to 2.5 above it (the next floor's bottom is at +4.5).
            position: Vec2::new(
                rng.range(0.5, width as f64 - 0.5),
                f * FLOOR_SPACING + 0.9 + if k % 2 == 0 { 0.0 } else { rng.range(0.1, 2.5) },
            ),
            controller: Some(Controller::Walker { speed }),
            ..BodyDef::default()
        });
    }
    let world = WorldDef {
        dt: DT,
        gravity: Vec2::new(0.0, -20.0),
        bounds: Some(WorldBounds {
            min: Vec2::new(0.0, -10.0),
            max: Vec2::new(width as f64, floor as f64 * FLOOR_SPACING + 10.0),
            wrap: true,
        }),
        layers: layers(
            &["tile", "actor"],
            &[
                (TILE, ACTOR, Response::Separate),
                (ACTOR, ACTOR, Response::Report),
            ],
        ),
        ..WorldDef::default()
    };
    scenario(name, world, bodies, frames)
}

/// One shape of kind `k % 5` (circle, aabb, obb, capsule, polygon) about `size` across.
fn any_shape(rng: &mut Rng, k: usize, size: f64) -> Shape {
    let r = |rng: &mut Rng| rng.range(0.5, 1.0) * size;
    match k % 5 {
        0 => Shape::circle(r(rng)).expect("a positive radius"),
        1 => Shape::aabb(Vec2::new(r(rng), r(rng))).expect("positive half extents"),
        2 => Shape::obb(Vec2::new(r(rng), r(rng) * 0.5)).expect("positive half extents"),
        3 => {
            let half = r(rng);
            let radius = r(rng) * 0.4;
            Shape::capsule(Vec2::new(-half, 0.0), Vec2::new(half, 0.0), radius)
                .expect("a positive radius")
        }
        _ => {
            let sides = 3 + rng.below(6);
            let radius = r(rng);
            round_polygon(rng, sides, radius)
        }
    }
}

/// `rain-N`: see the module docs.
fn rain(name: &str, n: usize, frames: u64) -> Scenario {
    const DROP: LayerId = 0;
    const GROUND: LayerId = 1;
    let mut rng = Rng(0x7a14_0003 ^ n as u64);
    let side = ((n as f64).sqrt() * 8.0).max(40.0);
    let statics = (n / 10).max(10);
    let mut bodies = Vec::with_capacity(n + statics);
    for k in 0..statics {
        // Bars, platforms, pegs, rails and rocks, three times a drop's size.
        let shape = any_shape(&mut rng, k, 2.4);
        bodies.push(BodyDef {
            name: "ground".to_owned(),
            layer: GROUND,
            kind: BodyKind::Static,
            shape,
            position: Vec2::new(rng.range(0.0, side), rng.range(0.0, side)),
            angle: rng.range(-0.6, 0.6),
            ..BodyDef::default()
        });
    }
    for k in 0..n {
        let shape = any_shape(&mut rng, k, 0.8);
        bodies.push(BodyDef {
            name: "drop".to_owned(),
            layer: DROP,
            shape,
            position: Vec2::new(rng.range(0.0, side), rng.range(0.0, side)),
            angle: rng.range(0.0, std::f64::consts::TAU),
            velocity: Vec2::new(rng.range(-1.0, 1.0), rng.range(-2.0, 0.0)),
            angular_velocity: rng.range(-2.0, 2.0),
            ..BodyDef::default()
        });
    }
    let world = WorldDef {
        dt: DT,
        gravity: Vec2::new(0.0, -9.81),
        bounds: Some(WorldBounds {
            min: Vec2::ZERO,
            max: Vec2::splat(side),
            wrap: true,
        }),
        layers: layers(
            &["drop", "ground"],
            &[
                (DROP, GROUND, Response::Report),
                (DROP, DROP, Response::Report),
            ],
        ),
        ..WorldDef::default()
    };
    scenario(name, world, bodies, frames)
}

/// The scene `name` (already parsed) for a run of `frames` frames.
fn build(name: &str, kind: SceneKind, frames: u64) -> Scenario {
    match kind {
        SceneKind::Asteroids { asteroids: n } => asteroids(name, n, frames),
        SceneKind::Platformer { tiles, actors } => platformer(name, tiles, actors, frames),
        SceneKind::Rain { shapes } => rain(name, shapes, frames),
    }
}

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
fn percentiles(times: &[Duration]) -> (f64, f64) {
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

/// How one scene's contact sets compared (the run's [`ContactAgreement`], sent from the
/// child process as JSON).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
struct Agreement {
    compared: u64,
    agreed: u64,
    both: u64,
    touching: u64,
    rapier_cached: u64,
    at_record_poses: u64,
    excluded: u64,
    ricochet_only: u64,
    rapier_only: u64,
    details: Vec<String>,
}

impl From<&ContactAgreement> for Agreement {
    fn from(a: &ContactAgreement) -> Agreement {
        Agreement {
            compared: a.compared,
            agreed: a.agreed,
            both: a.both,
            touching: a.touching,
            rapier_cached: a.rapier_cached,
            at_record_poses: a.at_record_poses,
            excluded: a.excluded,
            ricochet_only: a.ricochet_only,
            rapier_only: a.rapier_only,
            details: a.details.clone(),
        }
    }
}

/// One scene's figures.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct Row {
    scene: String,
    bodies: usize,
    frames: u64,
    ricochet_median_ms: f64,
    ricochet_p95_ms: f64,
    rapier_median_ms: f64,
    rapier_p95_ms: f64,
    agreement: Agreement,
    ricochet_mb: Option<f64>,
    peak_mb: Option<f64>,
    /// Median of `frames` more Ricochet steps with rapier idle: Ricochet with the caches to
    /// itself (between interleaved steps, rapier's step evicts Ricochet's data).
    ricochet_alone_median_ms: f64,
}

impl Row {
    fn ratio(&self) -> f64 {
        self.rapier_median_ms / self.ricochet_median_ms
    }

    fn agrees(&self) -> bool {
        self.agreement.agreed == self.agreement.compared
    }
}

/// Runs one scene: both engines, `frames` timed frames after frame 0.
fn run_scene(name: &str, kind: SceneKind, frames: u64) -> anyhow::Result<Row> {
    reset_peak();
    let setup = Instant::now();
    let scenario = build(name, kind, frames);
    let mut sim = Simulation::from_scenario(scenario);
    let bodies = sim.world.len();
    eprintln!("bench: {name}: {bodies} bodies, {frames} frames");
    let out0 = sim.step();
    let ricochet_mb = status_mb("VmHWM");
    let mut rapier = RapierScene::new(&sim).with_context(|| format!("{name}: rapier scene"))?;
    rapier.step();
    let mut agreement = compare_contacts(&sim, &out0, &rapier.penetrating(), CONTACT_TOLERANCE);
    drop(out0);
    eprintln!(
        "bench: {name}: set up in {:.1} s",
        setup.elapsed().as_secs_f64()
    );
    let mut ricochet_times = Vec::with_capacity(usize::try_from(frames).unwrap_or(0));
    let mut rapier_times = Vec::with_capacity(ricochet_times.capacity());
    let started = Instant::now();
    let mut last_note = Instant::now();
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
        if last_note.elapsed() > Duration::from_secs(30) {
            eprintln!(
                "bench: {name}: frame {frame}/{frames} after {:.0} s",
                started.elapsed().as_secs_f64()
            );
            last_note = Instant::now();
        }
    }
    let peak_mb = status_mb("VmHWM");
    // The same number of frames again, Ricochet alone (rapier's world stays, untouched).
    let mut alone_times = Vec::with_capacity(ricochet_times.len());
    for _ in 0..frames {
        let t = Instant::now();
        let out = sim.step();
        alone_times.push(t.elapsed());
        drop(out);
    }
    let (ricochet_alone_median_ms, _) = percentiles(&alone_times);
    let (ricochet_median_ms, ricochet_p95_ms) = percentiles(&ricochet_times);
    let (rapier_median_ms, rapier_p95_ms) = percentiles(&rapier_times);
    Ok(Row {
        scene: name.to_owned(),
        bodies,
        frames,
        ricochet_median_ms,
        ricochet_p95_ms,
        rapier_median_ms,
        rapier_p95_ms,
        agreement: Agreement::from(&agreement),
        ricochet_mb,
        peak_mb,
        ricochet_alone_median_ms,
    })
}

/// About three significant digits, without an exponent down to 0.001.
fn sig3(x: f64) -> String {
    let a = x.abs();
    if a >= 100.0 || a == 0.0 || !a.is_finite() {
        format!("{x:.0}")
    } else if a >= 10.0 {
        format!("{x:.1}")
    } else if a >= 1.0 {
        format!("{x:.2}")
    } else if a >= 0.1 {
        format!("{x:.3}")
    } else if a >= 0.01 {
        format!("{x:.4}")
    } else if a >= 0.001 {
        format!("{x:.5}")
    } else {
        format!("{x:.2e}")
    }
}

fn mb(v: Option<f64>) -> String {
    v.map_or_else(|| "n/a".to_owned(), |v| format!("{v:.1}"))
}

fn table(rows: &[Row]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{:<26} {:>8} {:>6} {:>10} {:>10} {:>10} {:>10} {:>8} {:>19} {:>9} {:>9} {:>10}",
        "scene",
        "bodies",
        "frames",
        "ricochet",
        "p95",
        "rapier",
        "p95",
        "ratio",
        "contacts agree",
        "ricochet",
        "peak",
        "alone"
    );
    let _ = writeln!(
        s,
        "{:<26} {:>8} {:>6} {:>10} {:>10} {:>10} {:>10} {:>8} {:>19} {:>9} {:>9} {:>10}",
        "",
        "",
        "",
        "ms/frame",
        "ms",
        "ms/frame",
        "ms",
        "",
        "agreed/compared",
        "MB",
        "MB",
        "ms/frame"
    );
    for r in rows {
        let _ = writeln!(
            s,
            "{:<26} {:>8} {:>6} {:>10.3} {:>10.3} {:>10.3} {:>10.3} {:>8} {:>19} {:>9} {:>9} {:>10.3}",
            r.scene,
            r.bodies,
            r.frames,
            r.ricochet_median_ms,
            r.ricochet_p95_ms,
            r.rapier_median_ms,
            r.rapier_p95_ms,
            sig3(r.ratio()),
            format!("{}/{}", r.agreement.agreed, r.agreement.compared),
            mb(r.ricochet_mb),
            mb(r.peak_mb),
            r.ricochet_alone_median_ms
        );
    }
    s
}

fn csv_text(rows: &[Row]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "{CSV_HEADER}");
    for r in rows {
        let _ = writeln!(
            s,
            "{},{},{:.4},{:.4},{:.4},{:.4},{:.6},{}/{},{},{:.4}",
            r.scene,
            r.frames,
            r.ricochet_median_ms,
            r.ricochet_p95_ms,
            r.rapier_median_ms,
            r.rapier_p95_ms,
            r.ratio(),
            r.agreement.agreed,
            r.agreement.compared,
            r.peak_mb.map_or_else(String::new, |v| format!("{v:.1}")),
            r.ricochet_alone_median_ms
        );
    }
    s
}

/// Runs one scene in a fresh process (this executable, `bench SCENE --frames N`, with
/// [`CHILD_ENV`] set), so that its memory figures start from a clean heap; its progress goes
/// to this process's stderr, its row comes back as one JSON line on its stdout.
fn run_child(name: &str, frames: u64) -> anyhow::Result<Row> {
    let exe = std::env::current_exe().context("finding the ricochet executable")?;
    let output = std::process::Command::new(exe)
        .args(["bench", name, "--frames", &frames.to_string()])
        .env(CHILD_ENV, "1")
        .stdin(std::process::Stdio::null())
        .stderr(std::process::Stdio::inherit())
        .output()
        .with_context(|| format!("{name}: starting the benchmark process"))?;
    let stdout = String::from_utf8_lossy(&output.stdout);
    let Some(line) = stdout.lines().find_map(|l| l.strip_prefix(ROW_PREFIX)) else {
        bail!(
            "{name}: the benchmark process ended ({}) without a result",
            output.status
        );
    };
    serde_json::from_str(line).with_context(|| format!("{name}: reading the benchmark result"))
}

fn report_scene(row: &Row) {
    let a = &row.agreement;
    eprintln!(
        "bench: {}: contacts {}/{} agree ({} in both, {} touching, {} where rapier kept stale \
         contact points, {} checked at their own poses, {} excluded as wrapped; {} Ricochet \
         only, {} rapier only)",
        row.scene,
        a.agreed,
        a.compared,
        a.both,
        a.touching,
        a.rapier_cached,
        a.at_record_poses,
        a.excluded,
        a.ricochet_only,
        a.rapier_only
    );
    for d in &a.details {
        eprintln!("  {d}");
    }
}

/// Runs the named scenes (or [`DEFAULT_SCENES`]), `frames` timed frames each, prints the
/// table, writes the CSV. Each scene runs in its own process (see [`CHILD_ENV`]). Exit code
/// 0 when every scene's contact sets agree, 1 when one does not, 2 for an unknown scene name
/// or a zero frame count.
pub fn run(scenes: &[String], frames: u64, csv: Option<&Path>) -> anyhow::Result<ExitCode> {
    let names: Vec<String> = if scenes.is_empty() {
        DEFAULT_SCENES.iter().map(|s| (*s).to_owned()).collect()
    } else {
        scenes.to_vec()
    };
    let mut parsed = Vec::new();
    for name in &names {
        match parse_scene(name) {
            Ok(kind) => parsed.push((name.clone(), kind)),
            Err(e) => {
                eprintln!("error: {e:#}");
                return Ok(ExitCode::from(2));
            }
        }
    }
    if frames == 0 {
        eprintln!("error: --frames must be at least 1");
        return Ok(ExitCode::from(2));
    }
    let in_process = std::env::var_os(CHILD_ENV).is_some();
    let mut rows = Vec::new();
    for (name, kind) in &parsed {
        if in_process {
            let row = run_scene(name, *kind, frames)?;
            println!("{ROW_PREFIX}{}", serde_json::to_string(&row)?);
            rows.push(row);
        } else {
            let row = run_child(name, frames)?;
            report_scene(&row);
            rows.push(row);
        }
    }
    let agree = rows.iter().all(Row::agrees);
    if in_process {
        return Ok(ExitCode::from(if agree { 0 } else { 1 }));
    }
    print!("{}", table(&rows));
    println!(
        "median and p95 (nearest rank) of each engine's time per frame, frame 0 untimed; ratio = \
         rapier median / ricochet median; memory = VmHWM of the scene's own process (ricochet: \
         after its setup and frame 0, before rapier's world exists; peak: at the end); alone = \
         median of as many further Ricochet frames with rapier idle (caches to itself)"
    );
    if let Some(path) = csv {
        std::fs::write(path, csv_text(&rows))
            .with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(ExitCode::from(if agree { 0 } else { 1 }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scene_names_parse() {
        assert_eq!(
            parse_scene("asteroids-10000").unwrap(),
            SceneKind::Asteroids { asteroids: 10000 }
        );
        assert_eq!(
            parse_scene("platformer-1_000_000-1000").unwrap(),
            SceneKind::Platformer {
                tiles: 1_000_000,
                actors: 1000
            }
        );
        assert_eq!(
            parse_scene("rain-5").unwrap(),
            SceneKind::Rain { shapes: 5 }
        );
        for bad in [
            "asteroids",
            "asteroids-0",
            "asteroids-x",
            "platformer-10",
            "snow-5",
        ] {
            assert!(parse_scene(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn scenes_have_the_asked_sizes_and_are_deterministic() {
        let s = build("p", parse_scene("platformer-1000-30").unwrap(), 10);
        assert_eq!(s.bodies.len(), 1030);
        let tiles = s
            .bodies
            .iter()
            .filter(|b| b.kind == BodyKind::Static)
            .count();
        assert_eq!(tiles, 1000);
        let a = build("a", parse_scene("asteroids-300").unwrap(), 10);
        assert_eq!(a.bodies.len(), 300 + BULLETS + 1);
        assert_eq!(a, build("a", parse_scene("asteroids-300").unwrap(), 10));
        let r = build("r", parse_scene("rain-100").unwrap(), 10);
        assert_eq!(r.bodies.len(), 110);
        let kinds: std::collections::BTreeSet<&str> = r
            .bodies
            .iter()
            .map(|b| match &b.shape {
                Shape::Primitive(p) => p.kind().name(),
                Shape::Compound(_) => "compound",
            })
            .collect();
        assert_eq!(kinds.len(), 5, "{kinds:?}");
    }

    #[test]
    fn percentiles_are_nearest_rank() {
        let t: Vec<Duration> = (1..=100).map(Duration::from_millis).collect();
        let (median, p95) = percentiles(&t);
        assert!((median - 50.5).abs() < 1e-9);
        assert!((p95 - 95.0).abs() < 1e-9);
        let (median, p95) = percentiles(&[Duration::from_millis(3)]);
        assert_eq!((median, p95), (3.0, 3.0));
    }

    #[test]
    fn no_compound_reaches_rapier() {
        for s in [
            build("a", SceneKind::Asteroids { asteroids: 50 }, 1),
            build("r", SceneKind::Rain { shapes: 50 }, 1),
        ] {
            assert!(
                s.bodies
                    .iter()
                    .all(|b| matches!(b.shape, Shape::Primitive(_)))
            );
        }
    }
}
