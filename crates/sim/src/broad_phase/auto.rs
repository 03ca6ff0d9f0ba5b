//! `Auto`'s rule: which algorithm a call runs, from this call's counts, layer table and
//! moving bodies' widths alone (deterministic, no timing, no memory of earlier calls: a
//! simulation restored from a snapshot, whose broad phase is built anew, picks what the
//! original picked). The rule and the study's figures behind it are in the module docs of
//! `broad_phase`.

use super::{BodyEntry, BroadPhase, BroadPhaseKind, CROWD, Interactions, STRIPS_ENTER, of_layer};

/// At most this many bodies given to the broad phase: `BruteForce` (at most 496 tests).
const BRUTE_FORCE_MAX: usize = 32;

impl BroadPhase {
    /// The algorithm `Auto` runs for this call's bodies (grouped by layer already). Sets
    /// `self.overlaps` to the estimate it used (0 when none was needed).
    pub(super) fn auto_kind(
        &mut self,
        bodies: &[BodyEntry],
        interactions: &Interactions,
    ) -> BroadPhaseKind {
        self.overlaps = 0.0;
        // Inert static bodies (`set_inert_statics`) are never indexed, so they cost no
        // algorithm anything: only the indexed ones count here.
        let (movers, indexed) = (self.movers.len(), self.statics.keys.len());
        if movers + indexed <= BRUTE_FORCE_MAX {
            return BroadPhaseKind::BruteForce;
        }
        if indexed >= movers {
            // A band around the world's edge (the wrap seam's bodies and their images)
            // spans every row of the world while holding few bodies: its own grid of
            // them, hashed anew each call, cost more than filing them in strips, where
            // each finds its static candidates by binary search in its strip's run
            // (rain-10000's seam: 145,000 instructions a frame fewer of 7,560,000; the
            // platformer's 10,000 tiles: 5,000 more of 4,075,000).
            return if self.band {
                BroadPhaseKind::Strips
            } else {
                BroadPhaseKind::Grid
            };
        }
        for &l in &self.mover_layers {
            let handles = of_layer(&self.movers, &self.layer_start, l);
            if handles.len() >= CROWD && interactions.interacts(l, l) {
                self.overlaps = self.overlaps.max(x_overlaps(handles, bodies));
            }
        }
        if self.overlaps >= STRIPS_ENTER {
            BroadPhaseKind::Strips
        } else {
            BroadPhaseKind::SortAndSweep
        }
    }
}

/// Bodies of a layer [`x_overlaps`] looks at, at most: the estimate needs a digit, not a
/// pass over every body (that pass cost a tenth of sort and sweep's own instructions).
const SAMPLE: usize = 64;

/// Sort and sweep's tests per body of one layer, estimated: a body is tested against the
/// bodies whose `min.x` falls within its own x extent, which, for `n` bodies of mean width
/// `w` spread evenly over an x span `X`, is `n w / X`. `w` and `X` are taken from at most
/// [`SAMPLE`] bodies evenly spaced in key order (deterministic; all of them in a smaller
/// layer). A NaN box makes the sum NaN, which compares as no crowd; an infinite width gives
/// NaN too, an infinite span 0.
fn x_overlaps(handles: &[u32], bodies: &[BodyEntry]) -> f64 {
    let step = handles.len().div_ceil(SAMPLE).max(1);
    let (mut widths, mut lo, mut hi, mut seen) = (0.0, f64::INFINITY, f64::NEG_INFINITY, 0);
    for &h in handles.iter().step_by(step) {
        let b = &bodies[h as usize].bounds;
        widths += b.max.x - b.min.x;
        lo = lo.min(b.min.x);
        hi = hi.max(b.max.x);
        seen += 1;
    }
    let span = hi - lo;
    if span > 0.0 {
        widths * (handles.len() as f64 / f64::from(seen)) / span
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use ricochet_geom::{Bounds, Vec2};

    use super::*;
    use crate::def::BodyKind;

    /// A crowd whose sample (every 16th body from the first) holds the last body too, so
    /// that the estimate is exact: 64 samples.
    const N: usize = 1009;

    /// `n` dynamic boxes of `layer`, `width` wide and 1 tall, spread evenly along x with
    /// their `min.x` from 0 to `span - width` (so their x span is `span`), on rows 2 apart.
    fn row(n: usize, width: f64, span: f64, layer: u8, first_key: u64) -> Vec<BodyEntry> {
        (0..n)
            .map(|i| {
                let x = (span - width) * i as f64 / (n - 1) as f64;
                let y = 2.0 * (i % 50) as f64;
                BodyEntry {
                    key: first_key + i as u64,
                    bounds: Bounds {
                        min: Vec2::new(x, y),
                        max: Vec2::new(x + width, y + 1.0),
                    },
                    layer,
                    kind: BodyKind::Dynamic,
                }
            })
            .collect()
    }

    /// `n` static unit tiles of layer 1, keys from 0.
    fn tiles(n: usize) -> Vec<BodyEntry> {
        (0..n)
            .map(|i| BodyEntry {
                key: i as u64,
                bounds: Bounds::around(Vec2::new(i as f64, -5.0), Vec2::splat(0.5)),
                layer: 1,
                kind: BodyKind::Static,
            })
            .collect()
    }

    fn pick(bp: &mut BroadPhase, statics: &[BodyEntry], movers: &[BodyEntry]) -> BroadPhaseKind {
        let all = Interactions::all(2);
        let stats = bp.pairs_split(statics, statics.len() as u64, movers, &all, &mut Vec::new());
        assert_eq!(stats.kind, bp.chosen());
        stats.kind
    }

    #[test]
    fn the_estimate_is_the_sum_of_widths_over_the_x_span() {
        // Exact: 4 boxes 2 wide starting at 0, 10, 20 and 30 span [0, 32]: 8 / 32.
        let bodies: Vec<BodyEntry> = (0..4)
            .map(|i| BodyEntry {
                key: i,
                bounds: Bounds {
                    min: Vec2::new(10.0 * i as f64, 0.0),
                    max: Vec2::new(10.0 * i as f64 + 2.0, 1.0),
                },
                layer: 0,
                kind: BodyKind::Dynamic,
            })
            .collect();
        assert_eq!(x_overlaps(&[0, 1, 2, 3], &bodies), 0.25);
        assert_eq!(x_overlaps(&[3], &bodies), 1.0);
        assert_eq!(x_overlaps(&[], &bodies), 0.0);
        // A NaN box makes no crowd of the layer, and never panics.
        let mut nan = bodies.clone();
        nan[1].bounds.max.x = f64::NAN;
        assert!(x_overlaps(&[0, 1, 2, 3], &nan).is_nan());
    }

    #[test]
    fn few_bodies_are_brute_force_and_inert_statics_do_not_count() {
        let mut bp = BroadPhase::new(BroadPhaseKind::Auto);
        assert_eq!(
            pick(&mut bp, &tiles(12), &row(20, 1.0, 100.0, 0, 100)),
            BroadPhaseKind::BruteForce
        );
        let mut bp = BroadPhase::new(BroadPhaseKind::Auto);
        assert_eq!(
            pick(&mut bp, &tiles(13), &row(20, 1.0, 100.0, 0, 100)),
            BroadPhaseKind::SortAndSweep
        );
        // A million tiles the caller keeps out: still brute force, and still counted.
        let mut bp = BroadPhase::new(BroadPhaseKind::Auto);
        bp.set_inert_statics(1_000_000, &[1]);
        let stats = bp.pairs_split(
            &[],
            1,
            &row(20, 1.0, 100.0, 0, 100),
            &Interactions::all(2),
            &mut Vec::new(),
        );
        assert_eq!(stats.kind, BroadPhaseKind::BruteForce);
        assert_eq!((stats.statics, stats.movers), (1_000_000, 20));
    }

    #[test]
    fn grid_only_when_the_indexed_statics_outnumber_the_movers() {
        let movers = row(N, 0.8, 3000.0, 0, 10_000);
        let mut bp = BroadPhase::new(BroadPhaseKind::Auto);
        assert_eq!(pick(&mut bp, &tiles(N), &movers), BroadPhaseKind::Grid);
        let mut bp = BroadPhase::new(BroadPhaseKind::Auto);
        assert_eq!(
            pick(&mut bp, &tiles(N - 1), &movers),
            BroadPhaseKind::SortAndSweep
        );
        // The platformer: a million inert tiles, 1,000 actors along a long level.
        let mut bp = BroadPhase::new(BroadPhaseKind::Auto);
        bp.set_inert_statics(1_000_000, &[1]);
        assert_eq!(pick(&mut bp, &[], &movers), BroadPhaseKind::SortAndSweep);
        assert!((bp.sweep_overlaps() - 0.8 * N as f64 / 3000.0).abs() < 1e-12);
    }

    #[test]
    fn a_band_takes_strips_where_others_take_the_grid() {
        let movers = row(N, 0.8, 3000.0, 0, 10_000);
        // A static box on each mover, a little to its right, and the unit tiles below.
        let mut statics: Vec<BodyEntry> = movers
            .iter()
            .enumerate()
            .map(|(i, m)| BodyEntry {
                key: i as u64,
                bounds: m.bounds.translated(Vec2::new(0.5, 0.25)),
                layer: 1,
                kind: BodyKind::Static,
            })
            .collect();
        statics.extend(tiles(N).into_iter().map(|t| BodyEntry {
            key: t.key + N as u64,
            ..t
        }));
        let all = Interactions::all(2);
        let mut band = BroadPhase::for_band(BroadPhaseKind::Auto);
        let mut found = Vec::new();
        let stats = band.pairs_split(&statics, 1, &movers, &all, &mut found);
        assert_eq!(stats.kind, BroadPhaseKind::Strips);
        // The same pairs as the grid's: one for each mover.
        let mut grid = BroadPhase::new(BroadPhaseKind::Auto);
        let mut want = Vec::new();
        let stats = grid.pairs_split(&statics, 1, &movers, &all, &mut want);
        assert_eq!(stats.kind, BroadPhaseKind::Grid);
        assert_eq!(want.len(), N);
        assert_eq!(found, want);
        // Otherwise the band's rule is everybody's.
        let mut band = BroadPhase::for_band(BroadPhaseKind::Auto);
        assert_eq!(
            pick(&mut band, &tiles(N - 1), &movers),
            BroadPhaseKind::SortAndSweep
        );
        let mut band = BroadPhase::for_band(BroadPhaseKind::Auto);
        assert_eq!(
            pick(&mut band, &tiles(12), &row(20, 1.0, 100.0, 0, 100)),
            BroadPhaseKind::BruteForce
        );
    }

    #[test]
    fn a_crowd_crowded_along_x_takes_strips() {
        // N bodies 1 wide: over N units, one x-overlap each; over N / 10, ten.
        let n = N as f64;
        let mut bp = BroadPhase::new(BroadPhaseKind::Auto);
        let spread = row(N, 1.0, n, 0, 0);
        assert_eq!(pick(&mut bp, &[], &spread), BroadPhaseKind::SortAndSweep);
        assert!((bp.sweep_overlaps() - 1.0).abs() < 1e-12);
        let packed = row(N, 1.0, n / 10.0, 0, 0);
        assert_eq!(pick(&mut bp, &[], &packed), BroadPhaseKind::Strips);
        assert!((bp.sweep_overlaps() - 10.0).abs() < 1e-12);
        // Just below and just above the threshold, from a fresh broad phase.
        let mut bp = BroadPhase::new(BroadPhaseKind::Auto);
        let below = row(N, 1.0, n / (STRIPS_ENTER - 0.01), 0, 0);
        assert_eq!(pick(&mut bp, &[], &below), BroadPhaseKind::SortAndSweep);
        let mut bp = BroadPhase::new(BroadPhaseKind::Auto);
        let above = row(N, 1.0, n / (STRIPS_ENTER + 0.01), 0, 0);
        assert_eq!(pick(&mut bp, &[], &above), BroadPhaseKind::Strips);
        // A sample: the 64 bodies every 16th of a crowd of 1,009 (the rest could be
        // anything), its widths scaled up to the whole layer.
        let mut sampled = row(N, 1.0, n / 10.0, 0, 0);
        for (i, b) in sampled.iter_mut().enumerate() {
            if i % 16 != 0 {
                b.bounds.max.x = b.bounds.min.x + 100.0;
            }
        }
        let mut bp = BroadPhase::new(BroadPhaseKind::Auto);
        pick(&mut bp, &[], &sampled);
        assert!((bp.sweep_overlaps() - 10.0).abs() < 1e-12);
    }

    #[test]
    fn only_a_large_layer_that_meets_itself_is_a_crowd() {
        let crowd = row(N, 1.0, 100.0, 0, 0);
        // The layer meets only the other one (asteroids and bullets).
        let apart = Interactions::from_fn(2, |a, b| a != b);
        let mut bp = BroadPhase::new(BroadPhaseKind::Auto);
        bp.pairs_split(&[], 0, &crowd, &apart, &mut Vec::new());
        assert_eq!(bp.chosen(), BroadPhaseKind::SortAndSweep);
        assert_eq!(bp.sweep_overlaps(), 0.0);
        // Fewer than CROWD bodies, however packed.
        let mut bp = BroadPhase::new(BroadPhaseKind::Auto);
        let small = row(CROWD - 1, 1.0, 10.0, 0, 0);
        assert_eq!(pick(&mut bp, &[], &small), BroadPhaseKind::SortAndSweep);
        let mut bp = BroadPhase::new(BroadPhaseKind::Auto);
        let small = row(CROWD, 1.0, 10.0, 0, 0);
        assert_eq!(pick(&mut bp, &[], &small), BroadPhaseKind::Strips);
        // Two layers: the crowded one decides.
        let mut two = row(N, 1.0, 1000.0, 0, 0);
        two.extend(row(N, 1.0, 100.0, 1, 5000));
        let mut bp = BroadPhase::new(BroadPhaseKind::Auto);
        assert_eq!(pick(&mut bp, &[], &two), BroadPhaseKind::Strips);
    }

    #[test]
    fn the_pick_depends_on_this_call_alone() {
        // A broad phase that just ran strips picks, for an input below the threshold, what
        // a fresh one picks (a restored simulation builds its broad phase anew).
        let at = |overlaps: f64| row(N, 1.0, N as f64 / overlaps, 0, 0);
        let mut warm = BroadPhase::new(BroadPhaseKind::Auto);
        assert_eq!(pick(&mut warm, &[], &at(10.0)), BroadPhaseKind::Strips);
        let below = at(STRIPS_ENTER - 0.01);
        let fresh = pick(&mut BroadPhase::new(BroadPhaseKind::Auto), &[], &below);
        assert_eq!(fresh, BroadPhaseKind::SortAndSweep);
        assert_eq!(pick(&mut warm, &[], &below), fresh);
    }
}
