//! Sort and sweep's filter of a big moving layer that meets only far smaller ones
//! (`broad_phase/cell_filter.rs`: 1,024 bodies or more, not meeting itself, 16 times the
//! bodies of the layers it meets): the pairs are exactly a plain all-pairs loop's, on scenes
//! with touching boxes on a lattice, bodies of very different sizes (the filter tests one
//! corner cell of each big body), tiny boxes near 1e6 (rounding), and the odd NaN or
//! infinite box, across frames of motion in which bodies grow past the sizes of the last.

mod common;

use proptest::prelude::*;
use ricochet_geom::{Bounds, Vec2};
use ricochet_scenes::Rng;
use ricochet_sim::BodyKind;
use ricochet_sim::broad_phase::{BodyEntry, BroadPhase, BroadPhaseKind, Interactions};

/// The big layer; layers 0 and 2 are the small ones.
const BIG: u8 = 1;

/// A box of family `family` at lattice point `(cx, cy)` with half extents from `hx`, `hy`;
/// `spread` scales the lattice (1: crowded, touching common; 16: as sparse as asteroids).
fn make_bounds(family: u8, (cx, cy): (i32, i32), hx: u8, hy: u8, spread: f64) -> Bounds {
    let (cx, cy) = (f64::from(cx), f64::from(cy));
    let (hx, hy) = (f64::from(hx % 9), f64::from(hy % 9));
    let lattice = |offset: f64, unit: f64, size: f64| {
        Bounds::around(
            Vec2::new(offset + cx * unit, offset + cy * unit),
            Vec2::new(hx * size, hy * size),
        )
    };
    match family {
        // Small boxes on a half-unit lattice: touching is common.
        0..=5 => lattice(0.0, 0.5 * spread, 0.25),
        // Degenerate.
        6 => lattice(0.0, 0.5 * spread, 0.0),
        // Long: a body whose lower-left corner is far from where it meets a small one.
        7 => lattice(0.0, 0.5 * spread, 3.0),
        // Tiny near 1e6.
        8 => lattice(1e6, 1e-7, 0.5e-7),
        // Inverted, infinite, NaN.
        9 => {
            let b = lattice(0.0, 0.5, 0.25);
            Bounds {
                min: b.max,
                max: b.min,
            }
        }
        10 => Bounds {
            min: Vec2::new(f64::NEG_INFINITY, cy),
            max: Vec2::new(cx, cy + hy),
        },
        _ => Bounds {
            min: Vec2::new(f64::NAN, cy),
            max: Vec2::new(cx, cy + hy),
        },
    }
}

fn kind_of(k: u64) -> BodyKind {
    if k.is_multiple_of(4) {
        BodyKind::Kinematic
    } else {
        BodyKind::Dynamic
    }
}

/// A scene: `big` bodies of the big layer and `small` of layers 0 and 2, interleaved in key
/// order, with families drawn from `families` (`odd`: the NaN and infinite ones too).
fn scene(
    seed: u64,
    (big, small): (usize, usize),
    near_1e6: bool,
    odd: bool,
    spread: f64,
) -> Vec<BodyEntry> {
    let mut rng = Rng::new(seed);
    let n = big + small;
    let mut smalls_left = small;
    (0..n)
        .map(|k| {
            let layer = if smalls_left > 0 && rng.below(n) < small {
                smalls_left -= 1;
                if rng.below(3) == 0 { 0 } else { 2 }
            } else {
                BIG
            };
            let family = match rng.below(20) {
                0 if odd => 9 + rng.below(3) as u8,
                1..=3 => 7,
                4 | 5 => 6,
                6 if near_1e6 => 8,
                _ => rng.below(6) as u8,
            };
            // The small layers' bodies span the whole lattice too (bullets all over).
            let (cx, cy) = (rng.below(160) as i32 - 80, rng.below(160) as i32 - 80);
            let (hx, hy) = (rng.below(256) as u8, rng.below(256) as u8);
            let bounds = make_bounds(family, (cx, cy), hx, hy, spread);
            BodyEntry {
                key: (k as u64 + 1) * 4,
                bounds,
                layer,
                kind: kind_of(rng.below(1 << 20) as u64),
            }
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Every frame, sort and sweep and `Auto` (kept from frame to frame, both entry points)
    /// find exactly the reference pairs.
    #[test]
    fn a_big_layer_met_by_small_ones_pairs_exactly(
        seed in any::<u64>(),
        big in 1024usize..1100,
        small in 1usize..=64,
        near_1e6 in any::<bool>(),
        odd in any::<bool>(),
        bits in 0u8..8,
        frames in 1usize..5,
        sparse in any::<bool>(),
    ) {
        // Layers 0 and 2 meet the big layer; among themselves, as `bits` says; the big layer
        // never meets itself.
        let interactions = Interactions::from_fn(3, |a, b| match (a.min(b), a.max(b)) {
            (0, 1) | (1, 2) => true,
            (0, 0) => bits & 1 != 0,
            (2, 2) => bits & 2 != 0,
            (0, 2) => bits & 4 != 0,
            _ => false,
        });
        let spread = if sparse { 16.0 } else { 1.0 };
        let mut bodies = scene(seed, (big, small), near_1e6, odd, spread);
        let kinds = [BroadPhaseKind::SortAndSweep, BroadPhaseKind::Auto];
        let mut whole: Vec<BroadPhase> = kinds.iter().map(|&k| BroadPhase::new(k)).collect();
        let mut split: Vec<BroadPhase> = kinds.iter().map(|&k| BroadPhase::new(k)).collect();
        let mut rng = Rng::new(seed ^ 0x5eed);
        let mut out = Vec::new();
        for frame in 0..frames {
            let expected = common::all_pairs(&bodies, &interactions);
            for (k, kind) in kinds.iter().enumerate() {
                whole[k].pairs(&bodies, &interactions, &mut out);
                prop_assert_eq!(&out, &expected, "{:?} (pairs), frame {}", kind, frame);
                split[k].pairs_split(&[], 0, &bodies, &interactions, &mut out);
                prop_assert_eq!(&out, &expected, "{:?} (pairs_split), frame {}", kind, frame);
            }
            for b in &mut bodies {
                let d = if rng.below(20) == 0 { 30.0 } else { 0.3 };
                let offset = Vec2::new((rng.unit() - 0.5) * d, (rng.unit() - 0.5) * d);
                // Half-unit steps now and then, to keep touching boxes in the mix.
                let offset = if rng.below(3) == 0 { (offset * 2.0).round() * 0.5 } else { offset };
                b.bounds = b.bounds.translated(offset);
            }
            // A body grows down and left, wider and taller than any before it: its
            // lower-left corner moves far from the small bodies it now reaches.
            let grows = rng.below(bodies.len());
            let by = Vec2::new(20.0 + rng.unit() * 60.0, 20.0 + rng.unit() * 60.0) * spread;
            bodies[grows].bounds.min -= by;
        }
    }
}

/// A dynamic body of `layer` with bounds `min` to `max`.
fn body(key: u64, min: (f64, f64), max: (f64, f64), layer: u8) -> BodyEntry {
    BodyEntry {
        key,
        bounds: Bounds {
            min: Vec2::new(min.0, min.1),
            max: Vec2::new(max.0, max.1),
        },
        layer,
        kind: BodyKind::Dynamic,
    }
}

/// Two boxes that only touch, the big one long and reaching the small one with its far end:
/// its lower-left corner is far outside the small one's cell, and the pair is still found.
#[test]
fn a_long_big_body_touching_a_small_one_at_its_far_end_pairs() {
    // 1,100 small bodies of the big layer in a row far from the small one, then one long
    // body whose right end touches it, and the small one (a bullet) at x = 500.
    let mut bodies: Vec<BodyEntry> = (0..1100)
        .map(|k| {
            let x = -1000.0 + k as f64 * 0.9;
            body(k + 1, (x, -5.0), (x + 0.5, -4.5), BIG)
        })
        .collect();
    bodies.push(body(2000, (100.0, 3.0), (500.0, 3.5), BIG));
    bodies.push(body(2001, (500.0, 3.5), (500.2, 3.7), 0));
    bodies.push(body(2002, (-2000.0, 900.0), (-1999.0, 901.0), 0));
    let interactions = Interactions::from_fn(3, |a, b| a != b && (a == BIG || b == BIG));
    let expected = common::all_pairs(&bodies, &interactions);
    assert_eq!(expected, vec![(1100, 1101)]);
    let mut out = Vec::new();
    BroadPhase::new(BroadPhaseKind::SortAndSweep).pairs(&bodies, &interactions, &mut out);
    assert_eq!(out, expected);
}

/// A small body whose bounds are inverted (min above max) by more than the big layer's
/// widest body: no big body can overlap it, and the filter's bitmap, which marks the cells
/// of each small body widened by that width, marked a reversed range and panicked (found by
/// the proptest above, seed 14380036766739847613).
#[test]
fn a_small_body_inverted_past_the_big_layers_reach_pairs_nothing_and_does_not_panic() {
    // 1,100 unit boxes of the big layer on a line, two small bodies among them, and one
    // between those inverted by 60 units on x (and by 0.5 on y).
    let mut bodies: Vec<BodyEntry> = (0..1100)
        .map(|k| {
            let x = k as f64 * 0.5;
            body(k + 1, (x, 0.0), (x + 1.0, 1.0), BIG)
        })
        .collect();
    bodies.push(body(2000, (200.0, 0.2), (200.3, 0.4), 0));
    bodies.push(body(2001, (300.0, 0.5), (240.0, 0.0), 2));
    bodies.push(body(2002, (400.0, 0.2), (400.3, 0.4), 0));
    let interactions = Interactions::from_fn(3, |a, b| a != b && (a == BIG || b == BIG));
    let expected = common::all_pairs(&bodies, &interactions);
    assert!(!expected.is_empty());
    for kind in [BroadPhaseKind::SortAndSweep, BroadPhaseKind::Auto] {
        let mut out = Vec::new();
        BroadPhase::new(kind).pairs(&bodies, &interactions, &mut out);
        assert_eq!(out, expected, "{kind:?}");
    }
}

/// A big layer far from a cluster of small bodies (bullets near their ship) is passed over,
/// not tested body by body: everything outside the small bodies' union box falls on the
/// bitmap's border cells, which no small body marks. Before that border, the union box
/// spanned the whole bitmap, every far body was clamped onto a marked edge cell, and each was
/// tested against the cluster (an asteroids field 30% slower a frame once its bullets
/// expired and only the ship was left).
#[test]
fn big_bodies_far_from_every_small_one_are_not_tested() {
    // 1,100 unit boxes of the big layer in a column from y = 100 up, at the small bodies' x,
    // one box of it touching the cluster, and the cluster: three small boxes near the origin.
    let mut bodies: Vec<BodyEntry> = (0..1100)
        .map(|k| {
            let y = 100.0 + k as f64 * 2.0;
            body(k + 1, (0.0, y), (1.0, y + 1.0), BIG)
        })
        .collect();
    bodies.push(body(2000, (0.5, 0.5), (1.5, 1.5), BIG));
    bodies.push(body(2001, (0.0, 0.0), (0.6, 0.6), 0));
    bodies.push(body(2002, (0.2, -0.5), (0.4, -0.3), 0));
    bodies.push(body(2003, (-0.5, 0.1), (-0.2, 0.3), 2));
    let interactions = Interactions::from_fn(3, |a, b| a != b && (a == BIG || b == BIG));
    let expected = common::all_pairs(&bodies, &interactions);
    assert_eq!(expected, vec![(1100, 1101)]);
    let mut out = Vec::new();
    let stats =
        BroadPhase::new(BroadPhaseKind::SortAndSweep).pairs(&bodies, &interactions, &mut out);
    assert_eq!(out, expected);
    // The one big box near the cluster, tested against the bodies its x range reaches in
    // layer 0's sorted list (2001 and 2002, that list's widest being 0.6 wide; 2003, of layer
    // 2, ends left of it): two tests. The other 1,100 add none.
    assert_eq!(stats.tested, 2, "{stats:?}");
}
