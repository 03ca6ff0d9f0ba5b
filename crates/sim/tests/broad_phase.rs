//! The broad phases: every kind gives exactly the pairs of a naive all-pairs loop (bounds
//! overlap, touching counts, a dynamic body in the pair, interacting layers), on random
//! scenes and across frames with bodies moving, spawning and despawning; static bodies are
//! indexed once.

mod common;

use proptest::prelude::*;
use ricochet_geom::{Bounds, Vec2};
use ricochet_scenes::Rng;
use ricochet_sim::BodyKind;
use ricochet_sim::broad_phase::{
    BodyEntry, BroadPhase, BroadPhaseKind, BroadPhaseStats, Interactions,
};

const KINDS: [BroadPhaseKind; 7] = [
    BroadPhaseKind::BruteForce,
    BroadPhaseKind::SortAndSweep,
    BroadPhaseKind::Grid,
    BroadPhaseKind::Strips,
    BroadPhaseKind::Quadtree,
    BroadPhaseKind::Tree,
    BroadPhaseKind::Auto,
];

const LAYERS: usize = 4;

fn split(bodies: &[BodyEntry]) -> (Vec<BodyEntry>, Vec<BodyEntry>) {
    bodies.iter().partition(|b| b.kind == BodyKind::Static)
}

fn kind_of(k: u8) -> BodyKind {
    match k % 3 {
        0 => BodyKind::Dynamic,
        1 => BodyKind::Kinematic,
        _ => BodyKind::Static,
    }
}

/// Bounds of one of several families, from small integers: on a half-unit lattice (so
/// touching is common), degenerate (zero size), larger than any grid cell, near 1e6, tiny
/// near 1e6, and the odd inverted, infinite or NaN box.
fn make_bounds(family: u8, cx: i8, cy: i8, hx: u8, hy: u8) -> Bounds {
    let (cx, cy, hx, hy) = (
        f64::from(cx),
        f64::from(cy),
        f64::from(hx % 5),
        f64::from(hy % 5),
    );
    let lattice = |offset: f64, unit: f64, size: f64| {
        Bounds::around(
            Vec2::new(offset + cx * unit, offset + cy * unit),
            Vec2::new(hx * size, hy * size),
        )
    };
    match family {
        0..=9 => lattice(0.0, 0.5, 0.25),
        10 => lattice(0.0, 0.5, 0.0),
        11 | 12 => lattice(0.0, 0.5, 20.0),
        13 => lattice(1e6, 0.5, 0.25),
        14 => lattice(1e6, 1e-7, 0.5e-7),
        15 => lattice(-1e6, 3.0, 1e5),
        16 => {
            let b = lattice(0.0, 0.5, 0.25);
            Bounds {
                min: b.max,
                max: b.min,
            }
        }
        17 => Bounds {
            min: Vec2::new(f64::NEG_INFINITY, cy),
            max: Vec2::new(cx, cy + hy),
        },
        // A NaN in one coordinate or another: `min.x`, `max.x` or `max.y`.
        18 => {
            let mut b = Bounds {
                min: Vec2::new(cx, cy),
                max: Vec2::new(cx + hx, cy + hy),
            };
            if hy < 2.0 {
                b.min.x = f64::NAN;
            } else if hy < 4.0 {
                b.max.x = f64::NAN;
            } else {
                b.max.y = f64::NAN;
            }
            b
        }
        _ => lattice(0.25, 0.5, 0.5),
    }
}

prop_compose! {
    fn arb_body(families: u8)(
        family in 0..families,
        cx in -20i8..20,
        cy in -20i8..20,
        hx in any::<u8>(),
        hy in any::<u8>(),
        layer in 0..LAYERS as u8,
        kind in any::<u8>(),
        gap in 1u64..4,
    ) -> (u64, BodyEntry) {
        let bounds = make_bounds(family, cx, cy, hx, hy);
        (gap, BodyEntry { key: 0, bounds, layer, kind: kind_of(kind) })
    }
}

/// A scene: keys strictly increasing (with gaps, so spawns can land in between).
fn arb_scene(max: usize) -> impl Strategy<Value = Vec<BodyEntry>> {
    (prop_oneof![Just(10u8), Just(20u8)])
        .prop_flat_map(move |families| prop::collection::vec(arb_body(families), 0..max))
        .prop_map(|v| {
            let mut key = 0;
            v.into_iter()
                .map(|(gap, mut b)| {
                    key += gap * 4;
                    b.key = key;
                    b
                })
                .collect()
        })
}

/// A symmetric layer matrix from 10 bits (the upper triangle of 4 layers, diagonal
/// included), often with layers that ignore themselves.
fn interactions(bits: u16) -> Interactions {
    Interactions::from_fn(LAYERS, |a, b| {
        let (a, b) = (usize::from(a.min(b)), usize::from(a.max(b)));
        let bit = a * LAYERS - a * (a + 1) / 2 + b;
        bits >> bit & 1 == 1
    })
}

/// Runs every kind through both entry points and checks each against the reference.
struct Checker {
    whole: Vec<BroadPhase>,
    split: Vec<BroadPhase>,
    generation: u64,
    statics: Vec<BodyEntry>,
    out: Vec<(u32, u32)>,
}

impl Checker {
    fn new() -> Checker {
        Checker {
            whole: KINDS.iter().map(|&k| BroadPhase::new(k)).collect(),
            split: KINDS.iter().map(|&k| BroadPhase::new(k)).collect(),
            generation: 0,
            statics: Vec::new(),
            out: Vec::new(),
        }
    }

    /// Returns each kind's stats (whole-slice entry point).
    fn check(
        &mut self,
        bodies: &[BodyEntry],
        interactions: &Interactions,
    ) -> Result<Vec<BroadPhaseStats>, TestCaseError> {
        let expected = common::all_pairs(bodies, interactions);
        let (statics, movers) = split(bodies);
        if statics != self.statics {
            self.generation += 1;
            self.statics = statics;
        }
        let mut all = Vec::new();
        for (k, kind) in KINDS.iter().enumerate() {
            let stats = self.whole[k].pairs(bodies, interactions, &mut self.out);
            prop_assert_eq!(&self.out, &expected, "{:?} (pairs)", kind);
            prop_assert_eq!(stats.pairs, expected.len() as u64);
            all.push(stats);
            self.split[k].pairs_split(
                &self.statics,
                self.generation,
                &movers,
                interactions,
                &mut self.out,
            );
            prop_assert_eq!(&self.out, &expected, "{:?} (pairs_split)", kind);
        }
        Ok(all)
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn every_kind_finds_exactly_the_reference_pairs(
        bodies in arb_scene(80),
        bits in any::<u16>(),
    ) {
        Checker::new().check(&bodies, &interactions(bits))?;
    }

    #[test]
    fn every_layer_pair_interacting_also_matches(bodies in arb_scene(80)) {
        Checker::new().check(&bodies, &Interactions::all(LAYERS))?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(120))]

    /// Bodies move (a little, and sometimes far), spawn with keys landing anywhere in the
    /// order, despawn, change kind; static bodies change now and then. Every frame, every
    /// kind (kept from the previous frame) still matches.
    #[test]
    fn frames_with_motion_spawns_and_despawns_still_match(
        bodies in arb_scene(120),
        bits in any::<u16>(),
        seed in any::<u64>(),
        frames in 2usize..12,
    ) {
        let interactions = interactions(bits);
        let mut rng = Rng::new(seed);
        let mut bodies = bodies;
        let mut checker = Checker::new();
        for _ in 0..frames {
            checker.check(&bodies, &interactions)?;
            let statics_change = rng.below(4) == 0;
            for b in &mut bodies {
                if b.kind == BodyKind::Static && !statics_change {
                    continue;
                }
                let d = if rng.below(20) == 0 { 30.0 } else { 0.3 };
                let offset = Vec2::new((rng.unit() - 0.5) * d, (rng.unit() - 0.5) * d);
                // Half-unit steps now and then, to keep touching boxes in the mix.
                let offset = if rng.below(3) == 0 { (offset * 2.0).round() * 0.5 } else { offset };
                b.bounds = b.bounds.translated(offset);
                if b.kind != BodyKind::Static && rng.below(30) == 0 {
                    b.kind = match b.kind {
                        BodyKind::Dynamic => BodyKind::Kinematic,
                        _ => BodyKind::Dynamic,
                    };
                }
            }
            let removals = rng.below(4);
            for _ in 0..removals {
                if !bodies.is_empty() {
                    let i = rng.below(bodies.len());
                    if bodies[i].kind != BodyKind::Static || statics_change {
                        bodies.remove(i);
                    }
                }
            }
            let spawns = rng.below(5);
            for _ in 0..spawns {
                let key = rng.below(4 * bodies.len() + 16) as u64;
                if let Err(at) = bodies.binary_search_by_key(&key, |b| b.key) {
                    let family = [0, 0, 0, 10, 11, 13][rng.below(6)];
                    let (cx, cy) = (rng.below(40) as i8 - 20, rng.below(40) as i8 - 20);
                    let bounds = make_bounds(family, cx, cy, key as u8, (key >> 3) as u8);
                    let kind = if statics_change { kind_of(key as u8) } else { kind_of(key as u8 % 2) };
                    let layer = (key % LAYERS as u64) as u8;
                    bodies.insert(at, BodyEntry { key, bounds, layer, kind });
                }
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(120))]

    /// The same bodies over many frames, as in a game where nothing spawns: most move a
    /// little (up to 0.01 or 0.125 along x), some stay, some jump (up to 1), some grow or
    /// shrink by half.
    /// Every frame, every kind still matches (a structure that keeps anything per body
    /// from frame to frame, such as the kept tree's fat boxes, must not let it choose
    /// pairs).
    #[test]
    fn kept_ranges_with_the_same_bodies_still_match(
        bodies in arb_scene(120),
        bits in any::<u16>(),
        seed in any::<u64>(),
        frames in 2usize..40,
    ) {
        let interactions = interactions(bits);
        let mut rng = Rng::new(seed);
        let mut bodies = bodies;
        let mut checker = Checker::new();
        for _ in 0..frames {
            checker.check(&bodies, &interactions)?;
            for b in &mut bodies {
                if b.kind == BodyKind::Static {
                    continue;
                }
                let step = match rng.below(10) {
                    0 | 1 => 0.0,
                    2 => 2.0,
                    3 => 0.25,
                    _ => 0.02,
                };
                let dx = (rng.unit() - 0.5) * step;
                // Along y now and then only: a pair that meets in y alone.
                let dy = if rng.below(3) == 0 { (rng.unit() - 0.5) * step } else { 0.0 };
                b.bounds = b.bounds.translated(Vec2::new(dx, dy));
                if rng.below(15) == 0 {
                    let scale = if rng.below(2) == 0 { 1.5 } else { 0.5 };
                    let (c, h) = (b.bounds.center(), (b.bounds.max - b.bounds.min) * 0.5);
                    b.bounds = Bounds::around(c, h * scale);
                }
            }
        }
    }
}

fn body(key: u64, center: (f64, f64), half: f64, layer: u8, kind: BodyKind) -> BodyEntry {
    BodyEntry {
        key,
        bounds: Bounds::around(Vec2::new(center.0, center.1), Vec2::splat(half)),
        layer,
        kind,
    }
}

#[path = "broad_phase/scenes.rs"]
mod scenes;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(60))]

    /// Rain: many bodies sharing one narrow x range, spread and falling in y, some wrapping
    /// from the bottom back to the top (a body that crosses the whole sorted order), over a
    /// few static pegs, with sizes from specks to bodies taller than the rest. Every kind
    /// matches the reference on every frame.
    #[test]
    fn rain_like_columns_match_the_reference(
        seed in any::<u64>(),
        n in 50usize..400,
        frames in 2usize..10,
        column in prop_oneof![Just(2.0), Just(6.0), Just(40.0)],
        tall in prop_oneof![Just(1.0), Just(30.0)],
    ) {
        let mut rng = Rng::new(seed);
        let height = 400.0;
        let interactions = Interactions::from_fn(2, |_, _| true);
        let mut bodies: Vec<BodyEntry> = (0..n)
            .map(|k| {
                let statik = k % 10 == 0;
                let size = if rng.below(50) == 0 { tall } else { rng.range(0.05, 1.5) };
                let centre = Vec2::new(rng.range(0.0, column), rng.range(0.0, height));
                BodyEntry {
                    key: k as u64 * 3,
                    bounds: Bounds::around(centre, Vec2::new(rng.range(0.05, 1.0), size * 0.5)),
                    layer: u8::from(statik),
                    kind: if statik { BodyKind::Static } else { kind_of(rng.below(2) as u8) },
                }
            })
            .collect();
        let mut checker = Checker::new();
        for _ in 0..frames {
            checker.check(&bodies, &interactions)?;
            for b in bodies.iter_mut().filter(|b| b.kind != BodyKind::Static) {
                let mut dy = -rng.range(0.0, 3.0);
                if b.bounds.max.y + dy < 0.0 {
                    dy += height; // wrapped to the top
                }
                b.bounds = b.bounds.translated(Vec2::new(rng.range(-0.2, 0.2), dy));
            }
        }
    }
}

/// A million static unit tiles (a 1000 × 1000 map with holes) and a few hundred dynamic
/// boxes of several sizes over it, across frames: every kind but brute force gives exactly
/// the pairs of a direct loop over each moving body against every body.
#[test]
fn a_million_tile_map_matches_the_reference() {
    const SIDE: usize = 1000;
    let mut rng = Rng::new(0x00c0_ffee);
    let mut statics = Vec::with_capacity(SIDE * SIDE);
    for i in 0..SIDE * SIDE {
        if i % 97 != 13 {
            let (x, y) = ((i % SIDE) as f64, (i / SIDE) as f64);
            statics.push(body(i as u64, (x + 0.5, y + 0.5), 0.5, 0, BodyKind::Static));
        }
    }
    let base = (SIDE * SIDE) as u64;
    let mut movers: Vec<BodyEntry> = (0..300)
        .map(|k| {
            let half = [0.4, 0.5, 1.3, 7.0][k % 4];
            let c = (rng.range(0.0, SIDE as f64), rng.range(0.0, SIDE as f64));
            let kind = if k % 5 == 0 {
                BodyKind::Kinematic
            } else {
                BodyKind::Dynamic
            };
            body(base + k as u64, c, half, 1, kind)
        })
        .collect();
    let interactions = Interactions::from_fn(2, |a, b| a != b || a == 1);
    let kinds = [
        BroadPhaseKind::SortAndSweep,
        BroadPhaseKind::Grid,
        BroadPhaseKind::Strips,
        BroadPhaseKind::Quadtree,
        BroadPhaseKind::Tree,
        BroadPhaseKind::Auto,
    ];
    let mut phases: Vec<BroadPhase> = kinds.iter().map(|&k| BroadPhase::new(k)).collect();
    let mut out = Vec::new();
    for _ in 0..3 {
        // The reference: each moving body against every body after it in key order (static
        // keys all come first), and every static body against it.
        let mut expected = Vec::new();
        let n = statics.len() as u32;
        for (i, a) in movers.iter().enumerate() {
            let ia = n + i as u32;
            for (s, b) in statics.iter().enumerate() {
                if a.kind == BodyKind::Dynamic && a.bounds.overlaps(&b.bounds) {
                    expected.push((s as u32, ia));
                }
            }
            for (j, b) in movers.iter().enumerate().skip(i + 1) {
                let dynamic = a.kind == BodyKind::Dynamic || b.kind == BodyKind::Dynamic;
                if dynamic && a.bounds.overlaps(&b.bounds) {
                    expected.push((ia, n + j as u32));
                }
            }
        }
        expected.sort_unstable();
        assert!(expected.len() > 1000, "a scene with plenty of pairs");
        for (k, bp) in phases.iter_mut().enumerate() {
            bp.pairs_split(&statics, 1, &movers, &interactions, &mut out);
            assert_eq!(out, expected, "{:?}", kinds[k]);
        }
        for m in &mut movers {
            let d = Vec2::new(rng.range(-0.7, 0.7), rng.range(-0.7, 0.7));
            m.bounds = m.bounds.translated(d);
        }
    }
}
