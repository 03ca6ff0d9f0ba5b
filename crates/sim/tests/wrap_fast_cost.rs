//! The cost of a frame with bodies far faster than a wrapping world (issue #34): bounded by
//! what the scene holds, not by the speed. Counted, not timed: `narrow_tests` counts every
//! exact test and time-of-impact cast `detect` runs.

use ricochet_geom::Shape;
use ricochet_sim::{Simulation, load_scenario};

/// The casts a frame may make through the images of long paths, for all pairs together
/// (`MAX_FRAME_PATH_CASTS`, the documented per-frame budget).
const FRAME_PATH_CASTS: u64 = 4096;

fn asteroids(edit: impl Fn(&str) -> String) -> Simulation {
    let path = format!(
        "{}/../../scenarios/asteroids.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).expect("scenario file");
    let text = edit(&text);
    Simulation::new(&load_scenario(&text, "asteroids.toml").expect("scenario loads"))
}

/// The most exact tests a frame of `n` bodies may run without long paths: each pair
/// directly and at its 8 images through the seam, plus a `separate` pair's time of impact
/// (at most as many again); the long paths' casts come on top.
fn bound(n: usize) -> u64 {
    let pairs = (n * n.saturating_sub(1) / 2) as u64;
    2 * 9 * pairs + FRAME_PATH_CASTS
}

#[test]
fn twenty_bullets_at_1e15_units_a_second_cost_a_bounded_frame_and_each_hits_a_rock() {
    // 20 bullets spawned by the script at frame 0, each moving [1e15, 3.7e14] units/s:
    // about 2e11 widths of the 80 x 50 world a frame, along a slope that sweeps it densely,
    // so each meets a rock in its first frame of motion.
    let spawns: String = (0..20)
        .map(|k| {
            format!(
                "  {{ frame = 0, action = \"spawn\", template = \"bullet\", name = \"shot{k}\", \
                 position = [{}, 24], velocity = [1e15, 3.7e14] }},\n",
                -38 + 3 * k
            )
        })
        .collect();
    let mut sim = asteroids(|t| t.replacen("script = [\n", &format!("script = [\n{spawns}"), 1));
    let mut removed = Vec::new();
    for _ in 0..3 {
        let n = sim.world().len() + 20;
        let out = sim.step();
        let tests = out.stats.narrow_tests;
        assert!(
            tests <= bound(n),
            "frame {}: {tests} tests, {n} bodies",
            out.frame
        );
        removed.extend(out.removed.iter().map(|r| r.name.clone()));
    }
    for k in 0..20 {
        assert!(
            removed.contains(&format!("shot{k}")),
            "shot{k} never hit: {removed:?}"
        );
    }
}

#[test]
fn the_stock_asteroids_run_with_bullet_speed_1e15_costs_bounded_frames() {
    let mut sim = asteroids(|t| t.replacen("bullet_speed = 30", "bullet_speed = 1e15", 1));
    let mut hits = 0;
    for _ in 0..=300 {
        let n = sim.world().len() + 1;
        let out = sim.step();
        let tests = out.stats.narrow_tests;
        assert!(
            tests <= bound(n),
            "frame {}: {tests} tests, {n} bodies",
            out.frame
        );
        let bullet = Shape::circle(0.2).unwrap();
        hits += out.removed.iter().filter(|r| r.shape == bullet).count();
    }
    // Every shot at 1e15 units/s sweeps the world densely and hits a rock within a frame
    // of being fired: the script fires 16 times by frame 300 (frames 19 to 296).
    assert_eq!(hits, 16, "bullets removed");
}

#[test]
fn near_misses_at_every_image_spend_at_most_the_frames_cast_budget() {
    use ricochet_geom::Vec2;
    use ricochet_scenes::{layers, moving_body, scenario};
    use ricochet_sim::{Response, WorldBounds, WorldDef};
    // In a 100 x 100 wrapping world, bullets moving along the diagonal at 1e15 units/s pass
    // every image of two thin rocks lying along the same diagonal, 1 unit to their side:
    // each image's bounds and bounding circles meet, the shapes never do (0.3 + 0.1 < 1).
    // Without a frame's budget each of the 8 pairs casts its 4,096 images.
    let mut l = layers(&["bullet", "rock"], &[(0, 1, Response::Report)]);
    l.set_fast(0);
    let w = WorldDef {
        layers: l,
        bounds: Some(WorldBounds {
            min: Vec2::ZERO,
            max: Vec2::splat(100.0),
            wrap: true,
        }),
        ..WorldDef::default()
    };
    // Along (1, 1) 3.5 each way, 0.2 each way across: corners (±3.5 ± 0.2, ±3.5 ∓ 0.2).
    let thin = Shape::polygon(&[
        Vec2::new(3.7, 3.3),
        Vec2::new(3.3, 3.7),
        Vec2::new(-3.7, -3.3),
        Vec2::new(-3.3, -3.7),
    ])
    .unwrap();
    let side = 2f64.sqrt();
    let mut bodies: Vec<_> = (0..4)
        .map(|k| {
            let x = 10.0 + 20.0 * f64::from(k);
            let shape = Shape::circle(0.1).unwrap();
            let v = Vec2::splat(1e15);
            moving_body(&format!("b{k}"), 0, shape, Vec2::new(x, x + side), v)
        })
        .collect();
    for (k, at) in [30.0, 70.0].into_iter().enumerate() {
        let at = Vec2::splat(at);
        bodies.push(moving_body(
            &format!("r{k}"),
            1,
            thin.clone(),
            at,
            Vec2::ZERO,
        ));
    }
    let mut sim = Simulation::new(&scenario("near-misses", w, bodies, 2));
    for _ in 0..=2 {
        let out = sim.step();
        let tests = out.stats.narrow_tests;
        assert!(tests <= bound(6), "frame {}: {tests} tests", out.frame);
        // Past the budget a pair is taken at its first image whose bounding circles meet:
        // logged with the shapes' exact contact there, apart (below zero), never missed.
        assert!(
            out.contacts.iter().all(|c| c.depth < 0.0),
            "{:?}",
            out.contacts
        );
    }
}
