//! The scene queries alone, for `perf record` and `perf stat -e instructions` (no rapier, no
//! Box2D in the process): `ricochet bench --queries`' three 10,000-body scenes stepped 10
//! frames, then `QUERY_PASSES` (default 200) passes of 2000 seeded rays (20 units, from a
//! point outside every body) and 2000 boxes (0.5–1.5 × the median body's half size), as the
//! bench draws them. Prints each scene's queries per second (the median pass) and a sum of
//! the answers, so nothing is optimised away. `QUERY_PASSES=0` measures the set-up alone,
//! to subtract from an instruction count; `QUERY_SCENE=rain` runs only the scenes whose
//! name holds `rain`. Then, per scene, the first box query after each of `QUERY_FRAMES`
//! (default 21) steps against the one after it: the first brings the moving bodies' tree up
//! to date (a refit, or a rebuild when it has grown too costly), once a frame; the median,
//! the mean and how many frames took over twice the median (the rebuilds).
//!
//! Run: `cargo bench -p ricochet-sim --bench queries` (or the built binary under `perf`).

use std::time::Instant;

use ricochet_sim::{Bounds, QueryFilter, Simulation, Vec2};

/// Queries of each kind per pass.
const QUERIES: usize = 2000;

/// A seeded xorshift, uniform in `[0, 1)`.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
}

fn main() {
    let passes: usize = std::env::var("QUERY_PASSES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(200);
    let frames: usize = std::env::var("QUERY_FRAMES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(FIRST_QUERY_FRAMES);
    let scenes = [
        (
            "asteroids-10000",
            ricochet_scenes::bench::asteroids(10_000, 10),
        ),
        (
            "platformer-10000-1000",
            ricochet_scenes::bench::platformer(10_000, 1_000, 10),
        ),
        ("rain-10000", ricochet_scenes::bench::rain(10_000, 10)),
    ];
    let all = QueryFilter::all();
    // `QUERY_SCENE=rain`: only the scenes whose name holds it (to profile one).
    let only = std::env::var("QUERY_SCENE").unwrap_or_default();
    for (name, scenario) in scenes {
        if !name.contains(only.as_str()) {
            continue;
        }
        let mut sim = Simulation::new(&scenario);
        for _ in 0..=10 {
            sim.step();
        }
        let w = sim.world();
        let mut reach: Vec<f64> = (0..w.len())
            .map(|i| {
                let b = w.shape(i).bounds(&ricochet_sim::Pose::default());
                let h = b.half_extents();
                h.x.max(h.y)
            })
            .collect();
        reach.sort_by(f64::total_cmp);
        let half = reach[reach.len() / 2];
        let margin = Vec2::splat(reach[reach.len() - 1] + 1.0);
        let world = sim.scenario().world.bounds.as_ref().map(|b| Bounds {
            min: b.min + margin,
            max: b.max - margin,
        });
        let area = world.unwrap_or_else(|| Bounds::of_points(&w.position));
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let point = |rng: &mut Rng, r: &Bounds| {
            Vec2::new(rng.range(r.min.x, r.max.x), rng.range(r.min.y, r.max.y))
        };
        let mut rays = Vec::new();
        while rays.len() < QUERIES {
            let o = point(&mut rng, &area);
            let a = rng.range(0.0, std::f64::consts::TAU);
            let d = Vec2::new(libm::cos(a), libm::sin(a));
            if area.contains(o + d * 20.0) && sim.overlap_point(o, &all).is_empty() {
                rays.push((o, d));
            }
        }
        let boxes: Vec<Bounds> = (0..QUERIES)
            .map(|_| {
                let h = Vec2::new(half * rng.range(0.5, 1.5), half * rng.range(0.5, 1.5));
                let inner = Bounds {
                    min: area.min + h,
                    max: area.max - h,
                };
                Bounds::around(point(&mut rng, &inner), h)
            })
            .collect();
        let (mut ray_times, mut box_times, mut sum) = (Vec::new(), Vec::new(), 0.0);
        for _ in 0..passes {
            let t = Instant::now();
            for &(o, d) in &rays {
                if let Some(h) = sim.cast_ray(o, d, 20.0, &all) {
                    sum += h.distance;
                }
            }
            ray_times.push(t.elapsed().as_secs_f64());
            let t = Instant::now();
            for b in &boxes {
                sum += sim.overlap_aabb(*b, &all).len() as f64;
            }
            box_times.push(t.elapsed().as_secs_f64());
        }
        let rate = |mut t: Vec<f64>| {
            t.sort_by(f64::total_cmp);
            t.get(t.len() / 2).map_or(0.0, |m| QUERIES as f64 / m)
        };
        println!(
            "{name}: rays/s {:.0}, overlaps/s {:.0} (answer sum {sum})",
            rate(ray_times),
            rate(box_times)
        );
        // What a game pays once a frame: the first query after a step builds the moving
        // bodies' tree and grid (after the passes, so the sums above stay as they were).
        let (mut first, mut next) = (Vec::new(), Vec::new());
        for _ in 0..frames {
            sim.step();
            let t = Instant::now();
            sum += sim.overlap_aabb(boxes[0], &all).len() as f64;
            first.push(t.elapsed().as_secs_f64());
            let t = Instant::now();
            sum += sim.overlap_aabb(boxes[1], &all).len() as f64;
            next.push(t.elapsed().as_secs_f64());
        }
        let median = |t: &[f64]| {
            let mut t = t.to_vec();
            t.sort_by(f64::total_cmp);
            t.get(t.len() / 2).copied().unwrap_or(0.0) * 1e6
        };
        let m = median(&first);
        // The frames that rebuilt the tree (a fresh build costs several refits).
        let slow = first.iter().filter(|&&t| t * 1e6 > 2.0 * m).count();
        let mean = first.iter().sum::<f64>() / first.len().max(1) as f64 * 1e6;
        println!(
            "{name}: a frame's first box query {m:.1} µs (mean {mean:.1}, {slow} frames over twice the median), the next {:.1} µs (medians of {frames} frames; {sum})",
            median(&next)
        );
    }
}

/// Frames stepped to time the first query after a step (`QUERY_FRAMES` overrides).
const FIRST_QUERY_FRAMES: usize = 21;
