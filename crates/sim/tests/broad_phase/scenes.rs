//! The broad phases on small scenes built by hand: empty and single bodies, touching and
//! apart boxes, static bodies indexed once, layers that ignore each other, static and
//! kinematic bodies, `Auto`'s pick, repeatable stats, a NaN static box.

use ricochet_geom::{Bounds, Vec2};
use ricochet_sim::BodyKind;
use ricochet_sim::broad_phase::{BodyEntry, BroadPhase, BroadPhaseKind, Interactions};

use super::{Checker, KINDS, body, common};

#[test]
fn empty_and_single_body_scenes_have_no_pairs() {
    let mut checker = Checker::new();
    let all = Interactions::all(1);
    checker.check(&[], &all).unwrap();
    checker
        .check(&[body(7, (0.0, 0.0), 1.0, 0, BodyKind::Dynamic)], &all)
        .unwrap();
    checker.check(&[], &all).unwrap();
}

#[test]
fn touching_boxes_pair_and_apart_ones_do_not() {
    let bodies = [
        body(1, (0.0, 0.0), 1.0, 0, BodyKind::Dynamic),
        body(2, (2.0, 0.0), 1.0, 0, BodyKind::Dynamic),
        body(3, (2.0, 2.0), 1.0, 0, BodyKind::Dynamic),
        body(4, (4.0 + 1e-12, 4.0), 1.0, 0, BodyKind::Dynamic),
    ];
    let mut out = Vec::new();
    for kind in KINDS {
        BroadPhase::new(kind).pairs(&bodies, &Interactions::all(1), &mut out);
        assert_eq!(out, [(0, 1), (0, 2), (1, 2)], "{kind:?}");
    }
}

/// A scene of `n` static unit tiles in a square and `movers` dynamic boxes over them.
fn tiles(n: usize, movers: usize, t: f64) -> (Vec<BodyEntry>, Vec<BodyEntry>) {
    let side = (n as f64).sqrt().ceil() as usize;
    let statics = (0..n)
        .map(|i| {
            let (x, y) = ((i % side) as f64, (i / side) as f64);
            body(i as u64, (x + 0.5, y + 0.5), 0.5, 1, BodyKind::Static)
        })
        .collect();
    let movers = (0..movers)
        .map(|i| {
            let f = i as f64;
            let x = (f * 7.3 + t * 0.1) % side as f64;
            let y = (f * 3.1) % side as f64;
            body((n + i) as u64, (x, y), 0.4, 0, BodyKind::Dynamic)
        })
        .collect();
    (statics, movers)
}

#[test]
fn static_bodies_are_indexed_once_while_they_do_not_change() {
    let interactions = Interactions::from_fn(2, |a, b| a != b || a == 0);
    for kind in [
        BroadPhaseKind::SortAndSweep,
        BroadPhaseKind::Grid,
        BroadPhaseKind::Strips,
        BroadPhaseKind::Quadtree,
        BroadPhaseKind::Tree,
    ] {
        let (mut whole, mut apart) = (BroadPhase::new(kind), BroadPhase::new(kind));
        let mut out = Vec::new();
        let (statics, _) = tiles(400, 30, 0.0);
        for frame in 0..10 {
            let (_, movers) = tiles(400, 30, f64::from(frame));
            let mut bodies = statics.clone();
            bodies.extend_from_slice(&movers);
            let s = whole.pairs(&bodies, &interactions, &mut out);
            assert_eq!(out, common::all_pairs(&bodies, &interactions), "{kind:?}");
            assert_eq!(s.static_rebuilds, 1, "{kind:?} frame {frame}");
            assert_eq!((s.statics, s.movers), (400, 30));
            // Past the first call, the static bodies are not even read while the generation
            // stays the same.
            let given: &[BodyEntry] = if frame == 0 { &statics } else { &[] };
            let s = apart.pairs_split(given, 0, &movers, &interactions, &mut out);
            assert_eq!(out, common::all_pairs(&bodies, &interactions), "{kind:?}");
            assert_eq!(s.static_rebuilds, 1, "{kind:?} frame {frame}");
        }
        // A tile goes: rebuilt once, then left alone again.
        let statics = &statics[1..];
        for frame in 0..3 {
            let (_, movers) = tiles(400, 30, f64::from(frame));
            let mut bodies = statics.to_vec();
            bodies.extend_from_slice(&movers);
            let s = whole.pairs(&bodies, &interactions, &mut out);
            assert_eq!(out, common::all_pairs(&bodies, &interactions), "{kind:?}");
            assert_eq!(s.static_rebuilds, 2, "{kind:?}");
            let s = apart.pairs_split(statics, 1, &movers, &interactions, &mut out);
            assert_eq!(out, common::all_pairs(&bodies, &interactions), "{kind:?}");
            assert_eq!(s.static_rebuilds, 2, "{kind:?}");
        }
    }
}

/// Asteroids that ignore each other, heaped on top of each other: the structures never
/// test one asteroid against another, so the tests stay near the ship's and bullets' share.
#[test]
fn a_layer_that_ignores_itself_is_never_tested_against_itself() {
    // Layer 0: asteroids; 1: bullets; 2: ship. Asteroids meet bullets and the ship.
    let interactions = Interactions::from_fn(3, |a, b| a != b && (a == 0 || b == 0));
    let mut bodies: Vec<BodyEntry> = (0..3000u32)
        .map(|i| {
            let f = f64::from(i);
            body(
                i.into(),
                (f * 0.013 % 20.0, f * 0.029 % 20.0),
                1.0,
                0,
                BodyKind::Dynamic,
            )
        })
        .collect();
    bodies.extend((0..20u32).map(|i| {
        let f = f64::from(i);
        body(3000 + u64::from(i), (f, 10.0), 0.05, 1, BodyKind::Dynamic)
    }));
    bodies.push(body(4000, (10.0, 10.0), 1.0, 2, BodyKind::Dynamic));
    let expected = common::all_pairs(&bodies, &interactions);
    let mut out = Vec::new();
    // Brute force counts the skipped layer combinations too (its tests are all pairs).
    let s = BroadPhase::new(BroadPhaseKind::BruteForce).pairs(&bodies, &interactions, &mut out);
    assert_eq!(out, expected);
    assert_eq!(s.layer_pairs_skipped, 4);
    for kind in [
        BroadPhaseKind::SortAndSweep,
        BroadPhaseKind::Grid,
        BroadPhaseKind::Strips,
        BroadPhaseKind::Quadtree,
        BroadPhaseKind::Tree,
    ] {
        let mut bp = BroadPhase::new(kind);
        for _ in 0..3 {
            let s = bp.pairs(&bodies, &interactions, &mut out);
            assert_eq!(out, expected, "{kind:?}");
            // 3000 asteroids in a 20x20 heap overlap each other about a million times;
            // the bullets and the ship test each asteroid at most once.
            assert!(s.tested <= 21 * 3000, "{kind:?}: {s:?}");
            // Asteroid–asteroid, bullet–bullet, ship–ship, bullet–ship.
            assert_eq!(s.layer_pairs_skipped, 4, "{kind:?}");
        }
    }
}

#[test]
fn static_and_kinematic_bodies_never_pair_with_each_other() {
    let bodies = [
        body(1, (0.0, 0.0), 1.0, 0, BodyKind::Static),
        body(2, (0.5, 0.0), 1.0, 0, BodyKind::Kinematic),
        body(3, (1.0, 0.0), 1.0, 0, BodyKind::Static),
        body(4, (1.5, 0.0), 1.0, 0, BodyKind::Kinematic),
    ];
    let mut out = Vec::new();
    for kind in KINDS {
        BroadPhase::new(kind).pairs(&bodies, &Interactions::all(1), &mut out);
        assert!(out.is_empty(), "{kind:?}");
    }
}

#[test]
fn auto_picks_by_the_counts() {
    let all = Interactions::all(2);
    let mut out = Vec::new();
    let mut bp = BroadPhase::new(BroadPhaseKind::Auto);
    let (statics, movers) = tiles(10, 10, 0.0);
    bp.pairs_split(&statics, 0, &movers, &all, &mut out);
    assert_eq!(bp.chosen(), BroadPhaseKind::BruteForce);
    let (statics, movers) = tiles(100, 30, 0.0);
    bp.pairs_split(&statics, 1, &movers, &all, &mut out);
    assert_eq!(bp.chosen(), BroadPhaseKind::Grid);
    let (statics, movers) = tiles(10, 100, 0.0);
    bp.pairs_split(&statics, 2, &movers, &all, &mut out);
    assert_eq!(bp.chosen(), BroadPhaseKind::SortAndSweep);
}

#[test]
fn the_same_calls_give_the_same_stats() {
    let interactions = Interactions::from_fn(2, |a, b| a != b || a == 0);
    for kind in KINDS {
        let run = || {
            let mut bp = BroadPhase::new(kind);
            let mut out = Vec::new();
            (0..5)
                .map(|t| {
                    let (statics, movers) = tiles(300, 50, f64::from(t) * 3.0);
                    bp.pairs_split(&statics, 0, &movers, &interactions, &mut out)
                })
                .collect::<Vec<_>>()
        };
        assert_eq!(run(), run(), "{kind:?}");
    }
}

/// Found by the property test: a NaN box in a leaf of the static tree once made the leaf's
/// box NaN, hiding its neighbour.
#[test]
fn a_nan_static_box_does_not_hide_its_neighbours() {
    let nan = Bounds {
        min: Vec2::new(f64::NAN, 0.0),
        max: Vec2::new(0.0, 0.0),
    };
    let bodies = [
        BodyEntry {
            key: 4,
            bounds: Bounds {
                min: Vec2::new(0.5, 0.0),
                max: Vec2::new(2.5, 0.0),
            },
            layer: 0,
            kind: BodyKind::Static,
        },
        BodyEntry {
            key: 8,
            bounds: Bounds::around(Vec2::new(0.5, 0.0), Vec2::ZERO),
            layer: 0,
            kind: BodyKind::Dynamic,
        },
        BodyEntry {
            key: 12,
            bounds: nan,
            layer: 0,
            kind: BodyKind::Static,
        },
    ];
    Checker::new()
        .check(&bodies, &Interactions::all(1))
        .unwrap();
}
