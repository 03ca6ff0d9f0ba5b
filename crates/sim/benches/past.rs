//! Lag compensation on the `asteroids-10000` bench scene (issue #35's target: keeping 32
//! frames costs at most 10% of the step, and a query at a past frame is within 2x of the
//! same query now).
//!
//! - `step/0` and `step/32`: one step with `keep_history(0)` (off) and `keep_history(32)`
//!   (its ring full: every step evicts and reuses the oldest frame).
//! - `cast_ray`, `overlap_aabb`: 64 queries (fixed rays 100 units long, boxes 10 units
//!   wide, spread over the world), now and at a frame 16 steps back, each set of trees
//!   built before the timing (`index_past`: the first query at a frame, which builds them).
//!
//! Run: `cargo bench -p ricochet-sim --bench past`

use divan::{Bencher, black_box};
use ricochet_sim::{Bounds, QueryFilter, Simulation, Vec2};

fn main() {
    divan::main();
}

/// The frame the scene is stepped to before timing.
const WARM: u64 = 300;

/// The scene stepped to [`WARM`], keeping `keep` frames. Bullets live past any bench's
/// length (the scene's `frames`), so the body count stays the same.
fn scene(keep: usize) -> Simulation {
    let mut sim = Simulation::new(&ricochet_scenes::bench::asteroids(10_000, 1_000_000));
    sim.keep_history(keep).expect("within MAX_HISTORY");
    for _ in 0..WARM {
        sim.step();
    }
    sim
}

/// 64 fixed points spread over the world (side 2000), and directions.
fn probes() -> Vec<(Vec2, Vec2)> {
    let mut s = 0x2545_f491_u64;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..64)
        .map(|_| {
            let p = Vec2::new(next() * 2000.0, next() * 2000.0);
            let a = next() * std::f64::consts::TAU;
            (p, Vec2::new(libm::cos(a), libm::sin(a)))
        })
        .collect()
}

#[divan::bench(args = [0, 32])]
fn step(b: Bencher, keep: usize) {
    let mut sim = scene(keep);
    b.bench_local(|| black_box(sim.step()));
}

fn rays(q: impl Fn(Vec2, Vec2) -> Option<ricochet_sim::RayHit>, probes: &[(Vec2, Vec2)]) -> usize {
    probes.iter().filter(|&&(p, d)| q(p, d).is_some()).count()
}

fn boxes(q: impl Fn(Bounds) -> Vec<ricochet_sim::Entity>, probes: &[(Vec2, Vec2)]) -> usize {
    let half = Vec2::splat(5.0);
    probes
        .iter()
        .map(|&(p, _)| {
            q(Bounds {
                min: p - half,
                max: p + half,
            })
            .len()
        })
        .sum()
}

#[divan::bench]
fn cast_ray_now(b: Bencher) {
    let (sim, probes, all) = (scene(32), probes(), QueryFilter::all());
    let q = |p, d| sim.cast_ray(p, d, 100.0, &all);
    rays(q, &probes);
    b.bench_local(|| black_box(rays(q, &probes)));
}

#[divan::bench]
fn cast_ray_past(b: Bencher) {
    let (sim, probes, all) = (scene(32), probes(), QueryFilter::all());
    let past = sim.past(WARM - 16).expect("kept");
    let q = |p, d| past.cast_ray(p, d, 100.0, &all);
    rays(q, &probes);
    b.bench_local(|| black_box(rays(q, &probes)));
}

#[divan::bench]
fn overlap_aabb_now(b: Bencher) {
    let (sim, probes, all) = (scene(32), probes(), QueryFilter::all());
    let q = |bounds| sim.overlap_aabb(bounds, &all);
    boxes(q, &probes);
    b.bench_local(|| black_box(boxes(q, &probes)));
}

#[divan::bench]
fn overlap_aabb_past(b: Bencher) {
    let (sim, probes, all) = (scene(32), probes(), QueryFilter::all());
    let past = sim.past(WARM - 16).expect("kept");
    let q = |bounds| past.overlap_aabb(bounds, &all);
    boxes(q, &probes);
    b.bench_local(|| black_box(boxes(q, &probes)));
}

/// The first query at a past frame: its trees built over every body, then one ray.
#[divan::bench(sample_count = 20)]
fn index_past(b: Bencher) {
    let sim = scene(32);
    let (p, d) = probes()[0];
    b.with_inputs(|| sim.clone()).bench_local_values(|s| {
        let past = s.past(WARM - 16).expect("kept");
        black_box(past.cast_ray(p, d, 100.0, &QueryFilter::all()));
        s
    });
}

/// The first query now after a step: the moving trees rebuilt, then one ray.
#[divan::bench(sample_count = 20)]
fn index_now(b: Bencher) {
    let sim = scene(32);
    let (p, d) = probes()[0];
    b.with_inputs(|| sim.clone()).bench_local_values(|s| {
        black_box(s.cast_ray(p, d, 100.0, &QueryFilter::all()));
        s
    });
}
