//! Sort and sweep's case of a big layer that meets only far smaller layers (10,000
//! asteroids that never meet each other, met by 101 bullets and a ship): keeping the big
//! layer sorted costs a slot rewrite and an insertion-sort step per body per call, and the
//! binary searches of the small layers into it miss the cache. Instead the small layers'
//! bounds mark the cells of a coarse bitmap over their union box; each body of the big layer
//! reads the bits its own bounds cover (one pass in the caller's order, a few instructions a
//! body), and only a body on a marked cell is tested exactly against the small layers' sorted
//! lists. The union box maps onto the inner cells only: what lies outside it is clamped onto
//! the border cells, which no small body marks, so a big layer far from a cluster of small
//! bodies (bullets near their ship) is passed over, not tested body by body. The filter is
//! conservative (cells from one monotone map of both bounds), so the
//! pairs found are exactly those whose bounds overlap, as the sweep finds them; only the
//! order in which they are found differs, and every caller sorts them.

use ricochet_geom::{Bounds, Vec2};

use super::sort_and_sweep::{SweepList, SweepView};
use super::{BodyEntry, BroadPhase, BroadPhaseKind, Interactions, member, of_layer};

/// A layer is filtered when it holds at least this many moving bodies...
const BIG: usize = 1024;
/// ...and at least this many times as many as every other moving layer it meets together.
const RATIO: usize = 16;
/// Cells along each axis of the bitmap: 4 words a row, 8 KB in all, in the L1 cache.
pub(super) const CELLS: usize = 256;
pub(super) const WORDS: usize = CELLS / 64;

/// The bitmap of one call, kept to reuse its allocation.
#[derive(Debug, Clone, Default)]
pub(super) struct CellFilter {
    /// Per layer, whether it is filtered this call.
    filtered: Vec<bool>,
    /// `CELLS` rows of `WORDS` words, bit `x` of row `y` set when a small body covers it.
    pub(super) bits: Vec<u64>,
    /// The small layers met by the layer being filtered.
    pub(super) partners: Vec<u8>,
    /// Per layer, the widest and tallest body of its last filtered call.
    pub(super) reach: Vec<Vec2>,
    /// When the big layer was left out of the entries (`left_out.rs`): its bodies on a
    /// marked cell, found as their bounds were made, and the reach to keep.
    pub(super) marked: Vec<u32>,
    pub(super) left_out: Option<Vec2>,
}

/// The monotone map from a coordinate to a cell along one axis (clamped to the grid): two
/// closed intervals that overlap map to cell ranges that overlap, whatever their values
/// (NaN maps to cell 0, and a NaN bound overlaps nothing anyway). `min..=max` maps onto
/// cells `1..=CELLS - 2`; cell 0 and cell `CELLS - 1` hold only values outside it.
#[derive(Clone, Copy)]
pub(super) struct Axis {
    min: f64,
    scale: f64,
}

/// Where `min` maps to: the first inner cell.
const INNER: f64 = 1.0;

impl Axis {
    fn new(min: f64, max: f64) -> Axis {
        // `max` maps to `INNER + CELLS - 3`, the last inner cell (within roundings far below
        // half a cell).
        let scale = (CELLS - 3) as f64 / (max - min);
        // A zero or infinite span (or NaN) leaves one cell: still conservative.
        let scale = if scale.is_finite() { scale } else { 0.0 };
        Axis { min, scale }
    }

    #[inline]
    fn cell(self, v: f64) -> usize {
        // Clamped to the grid in floating point (`max` takes 0 for NaN), then rounded to the
        // nearest integer by adding 2^52, whose low mantissa bits are then that integer: a
        // monotone map in a few instructions, where a saturating cast to an integer costs
        // a dozen (it is computed four times a body).
        let t = (v - self.min) * self.scale + INNER;
        // Written as comparisons (one `maxsd`/`minsd` each); NaN fails the first and is 0.
        let t = if t > 0.0 { t } else { 0.0 };
        let t = if t < (CELLS - 1) as f64 {
            t
        } else {
            (CELLS - 1) as f64
        };
        ((t + 4_503_599_627_370_496.0).to_bits() & 0xffff) as usize
    }
}

/// The cell of a point on both axes at once, as a bit of the bitmap (`y * CELLS + x`): the
/// arithmetic of [`Axis::cell`] on each axis, written on both lanes of one vector (half the
/// instructions of two calls; it is asked once for every big body).
#[derive(Clone, Copy)]
pub(super) struct Corner {
    min: Vec2,
    scale: Vec2,
}

impl Corner {
    pub(super) fn new(ax: Axis, ay: Axis) -> Corner {
        Corner {
            min: Vec2::new(ax.min, ay.min),
            scale: Vec2::new(ax.scale, ay.scale),
        }
    }

    #[inline]
    pub(super) fn bit(self, p: Vec2) -> usize {
        let t = (p - self.min) * self.scale + Vec2::splat(INNER);
        let top = (CELLS - 1) as f64;
        let t = Vec2::new(
            if t.x > 0.0 { t.x } else { 0.0 },
            if t.y > 0.0 { t.y } else { 0.0 },
        );
        let t = Vec2::new(
            if t.x < top { t.x } else { top },
            if t.y < top { t.y } else { top },
        );
        let t = t + Vec2::splat(4_503_599_627_370_496.0);
        let (x, y) = (t.x.to_bits() & 0xff, t.y.to_bits() & 0xff);
        (y as usize) * CELLS + x as usize
    }
}

/// `b` reaching `reach` further down and left, by a relative margin far above the rounding
/// of `reach` (a difference of two bounds) and of the subtraction.
#[inline]
fn widened(b: &Bounds, reach: Vec2) -> Bounds {
    let reach = reach * (1.0 + 1e-12);
    let min = b.min - reach;
    Bounds {
        min: min - (min.abs() + reach) * 1e-12 - Vec2::splat(f64::MIN_POSITIVE),
        max: b.max,
    }
}

/// Whether any bit `x0..=x1` (`x0 <= x1`) of `row` (`WORDS` words) is set.
#[cfg(test)]
fn any_in(row: &[u64], x0: usize, x1: usize) -> bool {
    let (w0, w1) = (x0 / 64, x1 / 64);
    let (head, tail) = (u64::MAX << (x0 % 64), u64::MAX >> (63 - x1 % 64));
    if w0 == w1 {
        return row[w0] & head & tail != 0;
    }
    row[w0] & head != 0 || row[w0 + 1..w1].iter().any(|&w| w != 0) || row[w1] & tail != 0
}

/// Sets bits `x0..=x1` (`x0 <= x1`) of `row` (`WORDS` words).
fn set(row: &mut [u64], x0: usize, x1: usize) {
    let (w0, w1) = (x0 / 64, x1 / 64);
    let (head, tail) = (u64::MAX << (x0 % 64), u64::MAX >> (63 - x1 % 64));
    if w0 == w1 {
        row[w0] |= head & tail;
        return;
    }
    row[w0] |= head;
    for w in &mut row[w0 + 1..w1] {
        *w = u64::MAX;
    }
    row[w1] |= tail;
}

impl CellFilter {
    /// Whether layer `l` is filtered this call.
    #[inline]
    pub(super) fn filtered(&self, l: u8) -> bool {
        self.filtered.get(usize::from(l)).copied().unwrap_or(false)
    }
}

impl BroadPhase {
    /// Decides, for this call, which moving layers sort and sweep filters (see the module
    /// docs): `layers` are the moving layers, in order.
    pub(super) fn plan_filters(
        &mut self,
        kind: BroadPhaseKind,
        layers: &[u8],
        interactions: &Interactions,
    ) {
        let f = &mut self.filter;
        f.filtered.clear();
        if kind != BroadPhaseKind::SortAndSweep {
            return;
        }
        let count = |l: u8| of_layer(&self.movers, &self.layer_start, l).len();
        for &l in layers {
            if worth_filtering(l, layers, count, interactions) {
                if f.filtered.is_empty() {
                    f.filtered.resize(256, false);
                }
                f.filtered[usize::from(l)] = true;
            }
        }
    }

    /// Every pair of a dynamic body with one body of `big` (a filtered layer) and one of a
    /// moving layer it meets (`layers`, the moving layers), whose bounds overlap, into `out`
    /// as `(small, big)` handles. Returns the exact tests. When the big layer was left out
    /// of the entries (`left_out.rs`), its bodies on a marked cell are listed already.
    pub(super) fn filtered_pairs(
        &mut self,
        big: u8,
        layers: &[u8],
        interactions: &Interactions,
        bodies: &[BodyEntry],
        out: &mut Vec<(u32, u32)>,
    ) -> (u64, u64) {
        let mut partners = std::mem::take(&mut self.filter.partners);
        partners.clear();
        partners.extend(
            layers
                .iter()
                .copied()
                .filter(|&m| m != big && interactions.interacts(big, m)),
        );
        // The small layers' lists, sorted, for the exact tests.
        let mut resorted = 0;
        for &m in &partners {
            resorted += self.ensure_sweep(m, bodies);
        }
        let f = &mut self.filter;
        if f.reach.is_empty() {
            f.reach.resize(256, Vec2::ZERO);
        }
        // The big layer's widest and tallest body, as of the last call: a big body that
        // overlaps a small one has its lower-left corner within the small one's bounds
        // widened down and left by these, so one cell a big body is enough. The pass measures
        // them again; if a body outgrew them, it is done again with this call's
        // ([`kept_reach`]).
        let mut reach = f.reach[usize::from(big)];
        let (start, mut tested) = (out.len(), 0);
        let smalls = |m: u8| of_layer(&self.movers, &self.layer_start, m);
        let sweeps = &self.sweeps;
        let pair = |h: u32, tested: &mut u64, out: &mut Vec<(u32, u32)>| {
            pair_with_smalls(h, &partners, (sweeps, smalls), bodies, tested, out);
        };
        if let Some(kept) = f.left_out.take() {
            for &h in &f.marked {
                pair(h, &mut tested, out);
            }
            f.reach[usize::from(big)] = kept;
            f.partners = partners;
            return (tested, resorted);
        }
        let big_handles = smalls(big);
        while let Some((ax, ay)) = mark(&mut f.bits, &partners, smalls, bodies, reach) {
            let bits: &[u64; CELLS * WORDS] = f.bits[..].try_into().expect("marked as many");
            let corner = Corner::new(ax, ay);
            let mut seen = Vec2::ZERO;
            tested = 0;
            for &h in big_handles {
                let e = &bodies[h as usize];
                let b = &e.bounds;
                let size = b.max - b.min;
                // Branches, not `f64::max`: rarely taken, no dependency chain, NaN ignored
                // (a NaN box overlaps nothing).
                if size.x > seen.x {
                    seen.x = size.x;
                }
                if size.y > seen.y {
                    seen.y = size.y;
                }
                let c = corner.bit(b.min);
                if bits[c / 64] & (1 << (c % 64)) == 0 {
                    continue;
                }
                pair(h, &mut tested, out);
            }
            let enough = seen.x <= reach.x && seen.y <= reach.y;
            reach = kept_reach(seen);
            if enough {
                break;
            }
            out.truncate(start);
        }
        f.reach[usize::from(big)] = reach;
        f.partners = partners;
        (tested, resorted)
    }
}

/// The reach kept for the next call from the widest and tallest body measured (`seen`): a
/// sixteenth more, so that bounds a rounding larger (placed at another position) or a body
/// growing slowly (widened over a motion that speeds up) do not mark the cells again. The
/// cells marked are only a little wider: the filter stays conservative with any reach at
/// least the bodies' sizes.
pub(super) fn kept_reach(seen: Vec2) -> Vec2 {
    seen + seen / 16.0
}

/// Whether sort and sweep filters moving layer `l`, of the moving `layers` whose bodies
/// `count` gives: 1,024 bodies or more, not meeting itself, and 16 times as many as every
/// moving layer it meets together (one at least).
pub(super) fn worth_filtering(
    l: u8,
    layers: &[u8],
    count: impl Fn(u8) -> usize,
    interactions: &Interactions,
) -> bool {
    let n = count(l);
    if n < BIG || interactions.interacts(l, l) {
        return false;
    }
    let mut others = 0;
    let mut any = false;
    for &m in layers {
        if m != l && interactions.interacts(l, m) {
            others += count(m);
            any = true;
        }
    }
    any && others.saturating_mul(RATIO) <= n
}

/// Tests big body `h` against the small layers (`partners`, each with its sorted list in
/// `sweeps` and its handles from `smalls`), pushing each pair with a dynamic body whose
/// bounds overlap as `(small, big)`, and counting the tests in `tested`.
fn pair_with_smalls<'a>(
    h: u32,
    partners: &[u8],
    (sweeps, smalls): (&[SweepList], impl Fn(u8) -> &'a [u32]),
    bodies: &[BodyEntry],
    tested: &mut u64,
    out: &mut Vec<(u32, u32)>,
) {
    let e = &bodies[h as usize];
    let q = member(e, h);
    for &m in partners {
        let view = SweepView {
            list: &sweeps[usize::from(m)],
            handles: smalls(m),
            bodies,
        };
        view.each_along_x(e, |s| {
            if q.dynamic || s.dynamic {
                *tested += 1;
                if q.bounds.overlaps(&s.bounds) {
                    out.push((s.handle, q.handle));
                }
            }
        });
    }
}

/// Marks in `bits` the cells of the small layers' bodies (`partners`, each layer's handles
/// from `of`) widened by `reach`; returns the map of each axis, or `None` when no small body
/// has bounds without NaN (nothing to pair).
pub(super) fn mark<'a>(
    bits: &mut Vec<u64>,
    partners: &[u8],
    of: impl Fn(u8) -> &'a [u32],
    bodies: &[BodyEntry],
    reach: Vec2,
) -> Option<(Axis, Axis)> {
    // The union of the small bodies' widened bounds (NaN bounds, which overlap nothing, left
    // out).
    let mut union: Option<Bounds> = None;
    for &m in partners {
        for &h in of(m) {
            let b = widened(&bodies[h as usize].bounds, reach);
            if [b.min.x, b.min.y, b.max.x, b.max.y]
                .iter()
                .any(|v| v.is_nan())
            {
                continue;
            }
            union = Some(union.map_or(b, |u| u.union(b)));
        }
    }
    let u = union?;
    let (ax, ay) = (Axis::new(u.min.x, u.max.x), Axis::new(u.min.y, u.max.y));
    bits.clear();
    // Past finite values (which the world's limits keep out) every body is tested.
    let finite = reach.is_finite() && u.min.is_finite() && u.max.is_finite();
    bits.resize(CELLS * WORDS, if finite { 0 } else { u64::MAX });
    for &m in partners {
        for &h in of(m) {
            let b = widened(&bodies[h as usize].bounds, reach);
            let (x0, x1) = (ax.cell(b.min.x), ax.cell(b.max.x));
            if x0 > x1 {
                // Inverted past the reach (the map is monotone, so `min > max`): a big body
                // overlapping it would span `[.. <= max, min <= ..]`, wider than the reach.
                // None does; and an empty row range on y is no loop.
                continue;
            }
            for y in ay.cell(b.min.y)..=ay.cell(b.max.y) {
                set(&mut bits[y * WORDS..(y + 1) * WORDS], x0, x1);
            }
        }
    }
    Some((ax, ay))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_set_and_read_exactly_the_cells_asked() {
        for (x0, x1) in [
            (0, 0),
            (3, 5),
            (0, 63),
            (60, 66),
            (63, 64),
            (10, 200),
            (255, 255),
        ] {
            let mut row = [0u64; WORDS];
            set(&mut row, x0, x1);
            for x in 0..CELLS {
                let bit = row[x / 64] >> (x % 64) & 1 == 1;
                assert_eq!(bit, (x0..=x1).contains(&x), "{x0}..={x1}: bit {x}");
                assert_eq!(any_in(&row, x, x), bit);
            }
            assert!(any_in(&row, 0, CELLS - 1));
            if x0 > 0 {
                assert!(!any_in(&row, 0, x0 - 1));
            }
            if x1 < CELLS - 1 {
                assert!(!any_in(&row, x1 + 1, CELLS - 1));
            }
        }
    }

    #[test]
    fn a_corners_bit_is_the_cell_of_each_axis() {
        let (ax, ay) = (Axis::new(-3.0, 1e3), Axis::new(0.5, 0.75));
        let corner = Corner::new(ax, ay);
        let values = [
            f64::NEG_INFINITY,
            -1e300,
            -3.0,
            -2.999,
            0.0,
            0.5,
            0.6,
            0.749,
            0.75,
            1.0,
            499.0,
            999.99,
            1e3,
            1e300,
            f64::INFINITY,
            f64::NAN,
        ];
        for x in values {
            for y in values {
                let want = ay.cell(y) * CELLS + ax.cell(x);
                assert_eq!(corner.bit(Vec2::new(x, y)), want, "({x}, {y})");
            }
        }
    }

    #[test]
    fn the_cell_map_is_monotone_and_clamped() {
        // 253 units over the 253 steps between the first inner cell (1) and the last (254):
        // a unit a cell, `v` in cell `round(v) + 1`, clamped to 0..=255.
        let a = Axis::new(0.0, 253.0);
        assert_eq!(a.cell(-1e300), 0);
        assert_eq!(a.cell(f64::NEG_INFINITY), 0);
        assert_eq!(a.cell(f64::NAN), 0);
        assert_eq!(a.cell(-0.51), 0);
        assert_eq!(a.cell(-0.49), 1);
        assert_eq!(a.cell(0.0), 1);
        assert_eq!(a.cell(1.0), 2);
        assert_eq!(a.cell(253.0), 254);
        assert_eq!(a.cell(253.49), 254);
        assert_eq!(a.cell(253.51), 255);
        assert_eq!(a.cell(1e300), 255);
        assert_eq!(a.cell(f64::INFINITY), 255);
        // No span: every value in the one inner cell.
        let flat = Axis::new(3.0, 3.0);
        assert_eq!(flat.cell(-5.0), 1);
        assert_eq!(flat.cell(7.0), 1);
    }

    #[test]
    fn the_union_box_fills_the_inner_cells_only() {
        for (min, max) in [(-3.0, 1e3), (0.5, 0.75), (1e6, 1e6 + 1e-7), (-1e150, 1e150)] {
            let a = Axis::new(min, max);
            assert_eq!(a.cell(min), 1, "{min}..{max}");
            assert_eq!(a.cell(max), CELLS - 2, "{min}..{max}");
        }
    }
}
