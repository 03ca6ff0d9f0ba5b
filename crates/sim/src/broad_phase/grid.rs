//! What every grid shares: cell coordinates, the cell size, the table a grid's entries are
//! counting-sorted into, and the limit on the cells a box may cover.
//!
//! The table is dense (one bucket per cell of the occupied rectangle, row by row) when that
//! rectangle has at most four cells per entry, as in a tile map, and otherwise hashed by a
//! fixed multiplicative hash of the cell (no `HashMap`: the layout depends only on the input,
//! and every lookup checks the cell itself). The cell is twice the median of the boxes'
//! extents (`max(width, height)`), widened if needed so cell coordinates stay within `±2^30`
//! (bodies at 1e6 with 1e-7 extents), and clamped to `i32` besides, which is monotone and so
//! still correct. A box covering more than [`MAX_CELLS`] cells, or with inverted or NaN
//! bounds, is kept aside in a list tested against everything instead.
//!
//! Used by the broad phase's [`HashGrid`](super::hash_grid::HashGrid) and by the per-axis
//! stages' [`FixedGrid`](super::FixedGrid) (both counting-sorted into a table by
//! [`Cells::fill`]) and [`MoverGrid`](super::MoverGrid) (filled box by box, hashed).

use ricochet_geom::Bounds;

/// A box covering more cells is kept aside (in its grid's `big` list), not entered in cells.
pub(super) const MAX_CELLS: u64 = 16;

/// How a grid maps space to buckets: the cell size, and either a dense table over the
/// occupied rectangle of cells (row by row: neighbours are neighbours in memory, as in a tile
/// map) or a table indexed by a fixed multiplicative hash of the cell.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Cells {
    /// One over the cell size.
    inv_cell: f64,
    /// Hashed: the table has `1 << bits` buckets.
    bits: u32,
    /// Dense: one bucket per cell of the `span` cells from `origin`, row by row.
    dense: bool,
    /// Dense: the lowest cell.
    origin: (i32, i32),
    /// Dense: the cells along x and y.
    span: (u32, u32),
}

impl Cells {
    /// Cells twice the median extent of `boxes` (`max(width, height)`), widened if needed so
    /// that cell coordinates stay within `±2^30`. `extents` is a buffer.
    pub(super) fn sized_for<'a>(
        boxes: impl Iterator<Item = &'a Bounds>,
        extents: &mut Vec<f64>,
    ) -> Cells {
        extents.clear();
        let mut max_abs: f64 = 0.0;
        for b in boxes {
            if b.min.x <= b.max.x && b.min.y <= b.max.y {
                let e = (b.max.x - b.min.x).max(b.max.y - b.min.y);
                if e.is_finite() {
                    extents.push(e);
                }
                for v in [b.min.x, b.min.y, b.max.x, b.max.y] {
                    if v.is_finite() {
                        max_abs = max_abs.max(v.abs());
                    }
                }
            }
        }
        Cells {
            inv_cell: inv_cell_size(extents, max_abs),
            ..Cells::default()
        }
    }

    /// A hashed table of `buckets` buckets (a power of two), for a grid filled box by box:
    /// cells twice the median of `extents` (the boxes' `max(width, height)`, in any order),
    /// not widened (the bounds are not known yet; coordinates clamp to `i32`, still correct).
    pub(super) fn hashed(extents: &mut [f64], buckets: usize) -> Cells {
        debug_assert!(buckets.is_power_of_two() && buckets > 1, "a hashed table");
        Cells {
            inv_cell: inv_cell_size(extents, 0.0),
            bits: buckets.trailing_zeros(),
            ..Cells::default()
        }
    }

    /// Chooses the table for `items` (each with the cells it covers; an empty range for one
    /// kept out of the cells) and counting-sorts `entry(cell, item)` into `entries`, bucket
    /// `b` being `entries[starts[b]..starts[b + 1]]`, each bucket in input order. Dense
    /// unless the occupied rectangle has more than four cells per entry.
    pub(super) fn fill<T: Copy, E: Copy>(
        &mut self,
        items: &[(CellRange, T)],
        blank: E,
        entry: impl Fn((i32, i32), T) -> E,
        starts: &mut Vec<u32>,
        entries: &mut Vec<E>,
    ) {
        let (mut lo, mut hi) = ((i32::MAX, i32::MAX), (i32::MIN, i32::MIN));
        let mut total = 0u64;
        for (r, _) in items {
            if r.count() > 0 {
                lo = (lo.0.min(r.x.0), lo.1.min(r.y.0));
                hi = (hi.0.max(r.x.1), hi.1.max(r.y.1));
                total += r.count();
            }
        }
        let span = |a: i32, b: i32| (i64::from(b) - i64::from(a) + 1).max(0) as u64;
        let cells = span(lo.0, hi.0).saturating_mul(span(lo.1, hi.1));
        self.dense = total > 0 && cells <= 4 * total + 64;
        let size = if self.dense {
            self.origin = lo;
            self.span = (span(lo.0, hi.0) as u32, span(lo.1, hi.1) as u32);
            cells as usize
        } else {
            (total as usize).max(16).next_power_of_two()
        };
        self.bits = size.trailing_zeros();
        starts.clear();
        starts.resize(size + 1, 0);
        for (r, _) in items {
            for c in r.cells() {
                if let Some(k) = self.bucket(c) {
                    starts[k] += 1;
                }
            }
        }
        // Each bucket's end, then fill backwards: `starts[b]` ends at the bucket's start.
        let mut sum = 0;
        for st in starts.iter_mut() {
            sum += *st;
            *st = sum;
        }
        entries.clear();
        entries.resize(total as usize, blank);
        for &(r, item) in items.iter().rev() {
            for c in r.cells() {
                if let Some(k) = self.bucket(c) {
                    starts[k] -= 1;
                    entries[starts[k] as usize] = entry(c, item);
                }
            }
        }
    }

    /// The cell coordinate of `v`: monotone in `v`, so overlapping boxes share a cell.
    #[inline]
    pub(super) fn coord(&self, v: f64) -> i32 {
        cell_coord(v, self.inv_cell)
    }

    /// The cells `b` covers, or `None` for inverted or NaN bounds.
    #[inline]
    pub(super) fn range(&self, b: &Bounds) -> Option<CellRange> {
        if !(b.min.x <= b.max.x && b.min.y <= b.max.y) {
            return None;
        }
        Some(CellRange {
            x: (self.coord(b.min.x), self.coord(b.max.x)),
            y: (self.coord(b.min.y), self.coord(b.max.y)),
        })
    }

    /// The cells `b` is entered in, or `None` when it is kept aside: covering more than
    /// [`MAX_CELLS`] cells, or with inverted or NaN bounds.
    #[inline]
    pub(super) fn placed(&self, b: &Bounds) -> Option<CellRange> {
        self.range(b).filter(|r| r.count() <= MAX_CELLS)
    }

    /// Whether cell `c` is where the pair `(a, b)` is reported: the one holding the lower
    /// left corner of their intersection, a cell both cover.
    #[inline]
    pub(super) fn owns(&self, a: &Bounds, b: &Bounds, c: (i32, i32)) -> bool {
        self.coord(a.min.x.max(b.min.x)) == c.0 && self.coord(a.min.y.max(b.min.y)) == c.1
    }

    /// The bucket of cell `c`: `None` for a cell outside a dense table.
    #[inline]
    pub(super) fn bucket(&self, (cx, cy): (i32, i32)) -> Option<usize> {
        if self.dense {
            let x = i64::from(cx) - i64::from(self.origin.0);
            let y = i64::from(cy) - i64::from(self.origin.1);
            let (w, h) = (i64::from(self.span.0), i64::from(self.span.1));
            return (0 <= x && x < w && 0 <= y && y < h).then_some((x + y * w) as usize);
        }
        Some(self.hashed_bucket((cx, cy)))
    }

    /// The bucket of cell `c` in a hashed table: the top `bits` bits of a fixed
    /// multiplicative (Fibonacci) hash of the cell.
    #[inline]
    pub(super) fn hashed_bucket(&self, (cx, cy): (i32, i32)) -> usize {
        let packed = u64::from(cx as u32) | (u64::from(cy as u32) << 32);
        (packed.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> (64 - self.bits)) as usize
    }

    /// `r` cut to the occupied cells when the table is dense.
    pub(super) fn clip(&self, r: CellRange) -> CellRange {
        if !self.dense {
            return r;
        }
        let last = |o: i32, n: u32| (i64::from(o) + i64::from(n) - 1) as i32;
        CellRange {
            x: (
                r.x.0.max(self.origin.0),
                r.x.1.min(last(self.origin.0, self.span.0)),
            ),
            y: (
                r.y.0.max(self.origin.1),
                r.y.1.min(last(self.origin.1, self.span.1)),
            ),
        }
    }
}

/// One over the cell size for boxes of these extents (`max(width, height)` each; reordered):
/// twice their median, widened if needed so that coordinates up to `max_abs` give cells
/// within `±2^30`, and 1 when there is nothing sensible to go by.
fn inv_cell_size(extents: &mut [f64], max_abs: f64) -> f64 {
    let mut cell = if extents.is_empty() {
        1.0
    } else {
        let mid = extents.len() / 2;
        let (_, median, _) = extents.select_nth_unstable_by(mid, f64::total_cmp);
        2.0 * *median
    };
    if !(cell.is_finite() && cell > 0.0) {
        cell = 1.0;
    }
    cell = cell.max(max_abs / CELL_RANGE);
    if !(1.0 / cell).is_normal() {
        cell = 1.0f64.max(max_abs / CELL_RANGE);
    }
    1.0 / cell
}

/// Cell coordinates stay within `±2^30` of the origin for finite bounds.
const CELL_RANGE: f64 = (1u64 << 30) as f64;

/// A rectangle of cells: `x.0..=x.1` by `y.0..=y.1`.
#[derive(Clone, Copy, Debug)]
pub(super) struct CellRange {
    /// The first and last column.
    x: (i32, i32),
    /// The first and last row.
    y: (i32, i32),
}

impl CellRange {
    /// How many cells (saturating).
    pub(super) fn count(self) -> u64 {
        let span = |(lo, hi): (i32, i32)| (i64::from(hi) - i64::from(lo) + 1).max(0) as u64;
        span(self.x).saturating_mul(span(self.y))
    }

    /// Whether the range is at most two cells wide and two high.
    pub(super) fn within_two(self) -> bool {
        i64::from(self.x.1) - i64::from(self.x.0) <= 1
            && i64::from(self.y.1) - i64::from(self.y.0) <= 1
    }

    /// The range's lower-left cell alone.
    pub(super) fn corner(self) -> CellRange {
        CellRange {
            x: (self.x.0, self.x.0),
            y: (self.y.0, self.y.0),
        }
    }

    /// The range reaching one cell further down and to the left (saturating).
    pub(super) fn reach_back(self) -> CellRange {
        CellRange {
            x: (self.x.0.saturating_sub(1), self.x.1),
            y: (self.y.0.saturating_sub(1), self.y.1),
        }
    }

    /// The cells, row by row.
    pub(super) fn cells(self) -> impl Iterator<Item = (i32, i32)> {
        (self.y.0..=self.y.1).flat_map(move |cy| (self.x.0..=self.x.1).map(move |cx| (cx, cy)))
    }
}

/// `floor(v * inv_cell)`, clamped to `i32`: monotone in `v`.
#[inline]
pub(super) fn cell_coord(v: f64, inv_cell: f64) -> i32 {
    // Clamped, then floored by hand (`f64::floor` is a call on baseline x86-64): the cast
    // truncates toward zero, a negative fraction steps down. NaN becomes 0; only regular
    // bounds get here.
    let x = (v * inv_cell).clamp(f64::from(i32::MIN), f64::from(i32::MAX));
    let t = x as i32;
    t - i32::from(f64::from(t) > x)
}

/// Random boxes for the grids' tests: tiles and odd sizes, around the origin and at 1e6, a
/// few huge.
#[cfg(test)]
pub(super) fn test_boxes() -> impl proptest::strategy::Strategy<Value = Vec<Bounds>> {
    use proptest::prelude::*;
    use ricochet_geom::Vec2;
    let b = (
        prop_oneof![Just(0.0), Just(1e6)],
        -20.0..20.0f64,
        -20.0..20.0f64,
        prop_oneof![3 => 0.5..1.5f64, 1 => 1e-3..0.1f64, 1 => 5.0..60.0f64],
        0.1..2.0f64,
    )
        .prop_map(|(o, x, y, w, h)| Bounds {
            min: Vec2::new(o + x, y),
            max: Vec2::new(o + x + w, y + h),
        });
    proptest::collection::vec(b, 0..200)
}
