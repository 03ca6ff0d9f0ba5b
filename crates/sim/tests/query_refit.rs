//! The moving bodies' tree is kept from frame to frame and refit (issue #37): every query
//! answers, bit for bit, as the same query on a fresh simulation of the scene restored from
//! a snapshot of this frame (its trees built new: the independent source), over random
//! scenes of up to 150 bodies moving, turning, wrapping, leaving the world, spawned,
//! despawned, reshaped and teleported between steps, asked in some frames and not others.
//! And the answers after a run do not depend on which frames asked.

use proptest::prelude::*;
use ricochet_sim::prelude::*;

mod random_scene;

use random_scene::{Rng, edit, probed_size, scenario};

/// Some moving bodies never turn: a refit moves them with no sine or cosine.
const TURNING: f64 = 0.6;

/// Asks `now` (its moving tree kept and refit) and `fresh` (the scene restored at the same
/// frame: every tree built new) the same random queries; how many found something.
fn same_answers(
    now: &Simulation,
    fresh: &Simulation,
    rng: &mut Rng,
    size: Vec2,
) -> Result<usize, TestCaseError> {
    random_scene::same_answers(now, fresh, rng, size, 8)
}

/// One case: a random scene stepped `steps` frames, asked random queries in about half of
/// them (with edits between some steps), each answer checked against a fresh simulation
/// restored at that frame; how many queries found something.
fn check(seed: u64, count: usize, steps: u64) -> Result<usize, TestCaseError> {
    let mut rng = Rng(seed);
    let scene = scenario(&mut rng, "refit", count, TURNING);
    let size = probed_size(&scene);
    let mut sim = Simulation::new(&scene);
    let mut fresh = Simulation::new(&scene);
    let mut hits = 0;
    for _ in 0..steps {
        sim.step();
        if rng.chance(0.5) {
            fresh.restore(&sim.snapshot()).unwrap();
            hits += same_answers(&sim, &fresh, &mut rng, size)?;
        }
        // Mostly motion alone (the tree refit), sometimes the bodies change (rebuilt).
        if rng.chance(0.15) {
            edit(&mut sim, &mut rng, size);
        }
    }
    Ok(hits)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn a_refit_tree_answers_as_a_fresh_one(
        seed in 1..u64::MAX,
        count in 1..150usize,
        steps in 1..40u64,
    ) {
        check(seed, count, steps)?;
    }
}

/// The proptest's cases find things: a check that finds nothing checks nothing.
#[test]
fn the_cases_find_something() {
    let hits: usize = (1..=6)
        .map(|seed| check(seed * 7919, 120, 30).unwrap())
        .sum();
    assert!(hits > 200, "{hits}");
}

/// The answers after a run are the same whether the frames before asked queries (the
/// moving tree kept and refit in those frames) or not (built once, at the end): what a
/// query answers depends on the simulation's history, never on the queries asked.
#[test]
fn answers_do_not_depend_on_earlier_queries() {
    for seed in [3, 17, 2024] {
        let mut rng = Rng(seed);
        let scene = scenario(&mut rng, "refit", 140, TURNING);
        let size = probed_size(&scene);
        let (mut asked, mut quiet) = (Simulation::new(&scene), Simulation::new(&scene));
        let mut probe = Rng(seed ^ 0x5eed);
        let mut found = 0;
        for frame in 0..60 {
            asked.step();
            quiet.step();
            // A few queries a frame; every tenth frame past the grid's threshold, so that
            // the grid answers too.
            for _ in 0..if frame % 10 == 0 { 1100 } else { 3 } {
                let c = probe.vec(0.0, 1.0) * size;
                found += asked
                    .overlap_aabb(Bounds::around(c, Vec2::splat(2.0)), &QueryFilter::all())
                    .len();
            }
            let o = probe.vec(0.0, 1.0) * size;
            found += usize::from(
                asked
                    .cast_ray(o, Vec2::X, 50.0, &QueryFilter::all())
                    .is_some(),
            );
        }
        assert!(found > 100, "{found}");
        let mut a = Rng(seed);
        let mut b = Rng(seed);
        same_answers(&asked, &quiet, &mut a, size).unwrap();
        // And both against a fresh restore, from the same queries.
        let mut fresh = Simulation::new(&scene);
        fresh.restore(&quiet.snapshot()).unwrap();
        same_answers(&quiet, &fresh, &mut b, size).unwrap();
    }
}

/// A clone shares the trees until one of the two moves on: each then answers as its own
/// fresh restore (neither refits a tree the other still holds).
#[test]
fn a_clone_and_its_original_answer_each_for_itself() {
    for seed in [5, 41, 977] {
        let mut rng = Rng(seed);
        let scene = scenario(&mut rng, "refit", 120, TURNING);
        let size = probed_size(&scene);
        let mut sim = Simulation::new(&scene);
        let mut fresh = Simulation::new(&scene);
        sim.step();
        let _ = sim.overlap_aabb(Bounds::around(size * 0.5, size), &QueryFilter::all());
        let mut twin = sim.clone();
        for frame in 0..6 {
            sim.step();
            if frame % 2 == 0 {
                edit(&mut twin, &mut rng, size);
            }
            twin.step();
            for s in [&sim, &twin] {
                fresh.restore(&s.snapshot()).unwrap();
                same_answers(s, &fresh, &mut rng, size).unwrap();
            }
        }
    }
}
