//! Lag-compensated queries (issue #35): `Simulation::past(f)` answers every query exactly as
//! the same query on a fresh simulation of the scene restored from the snapshot taken right
//! after frame `f`'s step (the independent source), over random scenes with spawns,
//! despawns, reshapes and teleports between steps, in wrap worlds and not; and a frame
//! outside the kept window is a named error.

use proptest::prelude::*;
use ricochet_sim::prelude::*;
use ricochet_sim::{HistoryError, MAX_HISTORY};

mod random_scene;

use random_scene::{Rng, edit, probed_size, scenario};

/// Asks `past` and `then` (the scene restored at the same frame) the same random queries.
fn same_answers(
    past: &Past<'_>,
    then: &Simulation,
    rng: &mut Rng,
    size: Vec2,
) -> Result<usize, TestCaseError> {
    prop_assert_eq!(past.len(), then.world().len());
    random_scene::same_answers(past, then, rng, size, 12)
}

/// One case: a random scene stepped `steps` frames keeping `keep`, every kept frame asked
/// random queries; how many of them found something.
fn check(seed: u64, keep: usize, steps: u64) -> Result<usize, TestCaseError> {
    let mut rng = Rng(seed);
    let scene = scenario(&mut rng, "past", 20, 1.0);
    let size = probed_size(&scene);
    let mut sim = Simulation::new(&scene);
    sim.keep_history(keep).unwrap();
    // The snapshot right after each frame's step: what `past` must answer as.
    let mut snaps = Vec::new();
    for _ in 0..steps {
        sim.step();
        snaps.push(sim.snapshot());
        edit(&mut sim, &mut rng, size);
    }
    let newest = steps - 1;
    let oldest = steps.saturating_sub(keep as u64);
    prop_assert_eq!(sim.kept_frames(), Some(oldest..=newest));
    let mut then = Simulation::new(&scene);
    let mut hits = 0;
    for f in oldest..=newest {
        let past = sim.past(f).unwrap();
        prop_assert_eq!(past.frame(), f);
        then.restore(&snaps[f as usize]).unwrap();
        hits += same_answers(&past, &then, &mut rng, size)?;
    }
    // Older than the window, or not stepped yet: a named error, never an answer.
    let outside = HistoryError::NotKept {
        frame: newest + 1,
        oldest,
        newest,
    };
    prop_assert_eq!(sim.past(newest + 1).unwrap_err(), outside);
    if oldest > 0 {
        let old = matches!(
            sim.past(oldest - 1),
            Err(HistoryError::NotKept { frame, .. }) if frame == oldest - 1
        );
        prop_assert!(old, "frame {} is older than the window", oldest - 1);
    }
    Ok(hits)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn a_past_frame_answers_as_the_scene_restored_there(
        seed in 1..u64::MAX,
        keep in 1..12usize,
        steps in 1..40u64,
    ) {
        check(seed, keep, steps)?;
    }
}

/// The property is not vacuous: over a few fixed scenes most queries find something.
#[test]
fn the_property_s_queries_find_bodies() {
    let hits: usize = (1..=16u64)
        .map(|seed| check(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15), 8, 30).unwrap())
        .sum();
    // 16 scenes x 8 frames x 12 rounds x 6 queries = 9216 asked.
    eprintln!("{hits} hits");
    assert!(hits > 1000, "{hits} hits");
}

fn ball_scene() -> (Simulation, Entity) {
    let mut sim = Simulation::from_def(WorldDef {
        gravity: Vec2::ZERO,
        ..WorldDef::default()
    })
    .unwrap();
    let ball = sim.spawn(&BodyDef {
        shape: Shape::circle(0.5).unwrap(),
        velocity: Vec2::new(60.0, 0.0),
        ..BodyDef::default()
    });
    (sim, ball)
}

/// By hand: a ball at 60 units/s moves 1 unit a frame from x = 0 (frame 0 does not move
/// it), so at the end of frame `f` it is at `x = f`; a ray along y = 0 from x = -10 first
/// meets it at `x = f - 0.5`, distance `9.5 + f`.
#[test]
fn a_ray_at_a_past_frame_hits_the_ball_where_it_was() {
    let (mut sim, ball) = ball_scene();
    sim.keep_history(4).unwrap();
    for _ in 0..10 {
        sim.step();
    }
    assert_eq!(sim.kept_frames(), Some(6..=9));
    let ray = |q: &dyn Fn(Vec2, Vec2, f64, &QueryFilter) -> Option<RayHit>| {
        q(
            Vec2::new(-10.0, 0.0),
            Vec2::new(1.0, 0.0),
            100.0,
            &QueryFilter::all(),
        )
    };
    for f in 6..=9u64 {
        let past = sim.past(f).unwrap();
        let h = ray(&|o, d, m, fl| past.cast_ray(o, d, m, fl)).unwrap();
        assert_eq!(h.entity, ball);
        assert_eq!(h.distance, 9.5 + f as f64);
        assert_eq!(h.point, Vec2::new(f as f64 - 0.5, 0.0));
        assert_eq!(
            past.overlap_point(Vec2::new(f as f64 + 0.25, 0.0), &QueryFilter::all()),
            [ball]
        );
        assert!(
            past.overlap_point(Vec2::new(f as f64 + 1.0, 0.0), &QueryFilter::all())
                .is_empty()
        );
    }
    // The last step's end is now.
    assert_eq!(sim.position(ball), Some(Vec2::new(9.0, 0.0)));
    // A despawned ball is still in the frames it lived in, and not in later ones.
    sim.despawn(ball).unwrap();
    sim.step();
    let at = |f: u64| {
        sim.past(f)
            .unwrap()
            .overlap_point(Vec2::new(9.0, 0.0), &QueryFilter::all())
    };
    assert_eq!(at(9), [ball]);
    assert!(at(10).is_empty());
}

#[test]
fn a_frame_outside_the_window_is_a_named_error() {
    let (mut sim, _) = ball_scene();
    // Off by default.
    sim.step();
    let off = sim.past(0).unwrap_err();
    assert_eq!(off, HistoryError::Off { frame: 0 });
    assert!(off.to_string().contains("history is off"), "{off}");
    sim.keep_history(3).unwrap();
    // On, but nothing stepped since.
    assert_eq!(sim.past(0).unwrap_err(), HistoryError::NoneYet { frame: 0 });
    for _ in 0..5 {
        sim.step();
    }
    // Frames 1..=5 stepped since; 3 kept.
    assert_eq!(sim.kept_frames(), Some(3..=5));
    let old = sim.past(2).unwrap_err();
    assert_eq!(
        old,
        HistoryError::NotKept {
            frame: 2,
            oldest: 3,
            newest: 5
        }
    );
    assert_eq!(old.to_string(), "frame 2 is not kept: frames 3 to 5 are");
    assert_eq!(
        sim.past(6).unwrap_err(),
        HistoryError::NotKept {
            frame: 6,
            oldest: 3,
            newest: 5
        }
    );
    assert!(sim.past(5).is_ok());
    // Shorter: the oldest frames go.
    sim.keep_history(1).unwrap();
    assert_eq!(sim.kept_frames(), Some(5..=5));
    // Too long: refused, nothing changes.
    assert_eq!(
        sim.keep_history(MAX_HISTORY + 1).unwrap_err(),
        HistoryError::TooLong {
            asked: MAX_HISTORY + 1
        }
    );
    assert_eq!(sim.kept_frames(), Some(5..=5));
    // A restore clears it (the length stays).
    let snap = sim.snapshot();
    sim.step();
    sim.restore(&snap).unwrap();
    assert_eq!(sim.past(5).unwrap_err(), HistoryError::NoneYet { frame: 5 });
    sim.step();
    assert_eq!(sim.kept_frames(), Some(6..=6));
    // Off again: every frame is an error.
    sim.keep_history(0).unwrap();
    assert_eq!(sim.past(6).unwrap_err(), HistoryError::Off { frame: 6 });
    sim.step();
    assert_eq!(sim.kept_frames(), None);
}

/// Kept frames are not part of the state: a snapshot's bytes and the checksum are the same
/// with history on or off.
#[test]
fn history_is_not_in_a_snapshot_or_the_checksum() {
    let (mut a, _) = ball_scene();
    let (mut b, _) = ball_scene();
    b.keep_history(8).unwrap();
    for _ in 0..5 {
        a.step();
        b.step();
    }
    assert_eq!(a.snapshot().to_bytes(), b.snapshot().to_bytes());
    assert_eq!(a.checksum(), b.checksum());
}

/// A clone shares the frames kept so far; each then keeps its own, and stepping one never
/// changes what the other answers (the ball of `ball_scene` is at `x = f` at the end of
/// frame `f`).
#[test]
fn a_clone_keeps_its_own_frames() {
    let (mut sim, ball) = ball_scene();
    sim.keep_history(3).unwrap();
    for _ in 0..5 {
        sim.step();
    }
    let mut clone = sim.clone();
    for _ in 0..5 {
        sim.step();
    }
    clone.set_position(ball, Vec2::new(50.0, 0.0)).unwrap();
    clone.step();
    let inside = |s: &Simulation, f: u64, x: f64| {
        s.past(f)
            .unwrap()
            .overlap_point(Vec2::new(x, 0.0), &QueryFilter::all())
            == [ball]
    };
    assert_eq!(clone.kept_frames(), Some(3..=5));
    assert!(inside(&clone, 3, 3.0) && inside(&clone, 4, 4.0));
    // Frame 5 of the clone: moved to x = 50, then one unit.
    assert!(inside(&clone, 5, 51.0) && !inside(&clone, 5, 5.0));
    assert_eq!(sim.kept_frames(), Some(7..=9));
    assert!(inside(&sim, 7, 7.0) && inside(&sim, 9, 9.0));
}
