//! The queries' grid: a uniform grid over one set of bodies (`index.rs`), built beside its
//! tree once the set has answered 1,024 queries by the tree (`index.rs`), so that a small
//! box is a few cell lookups and a short ray a few rows of cells, instead of a walk down
//! the tree's levels (seven on 10,000 members).
//!
//! A member is listed in every cell its box covers, but for a cell its box only touches
//! from below: a box whose top (or right) side lies exactly on a cell's lower (or left)
//! edge is not listed above (or right of) it. On a level of tiles the cells line up with
//! the tiles, and each tile is listed once instead of up to four times. A box query visits
//! the cells its box covers and reports a member only from the cell holding the lower
//! corner of the two boxes' intersection, `(max(q.min.x, m.min.x), max(q.min.y, m.min.y))`.
//! Where the two boxes share more than a side (the intersection's lower corner is below
//! the member's top and left of its right side), that point is in a cell the member is
//! listed in and in one the query visits, since the cell of a point is a monotone function
//! of it on each axis: every such member is reported exactly once, with no list to dedup.
//! A member whose box only touches the query's may be reported or not, at most once: every
//! caller's exact test (a shape overlapping a box, a point strictly inside a shape) fails
//! for it anyway, as a shape lies within its box. A ray: [`Grid::ray`].
//!
//! **Bounds** (memory linear in the members whatever their boxes): the cell is
//! [`MEDIANS`] times the median member's size, grown when needed to at most about
//! [`CELLS_PER_MEMBER`] cells a member (at most three times that, plus four, with the
//! rounding); a member covering more than [`SPAN`] cells is kept apart and tested by every
//! query; when more than [`BIG`] members are so, or any box is infinite, there is no grid
//! and the tree answers ([`Grid::new`] gives `None`).

use ricochet_geom::{Bounds, Vec2};

use super::slab::{Slab, smaller};

/// The cell's side, in median member sizes (1.5, 1 and 0.75 measured within noise of 2 on
/// the bench's scenes; 2 was 5–8% faster on the platformer's box queries).
const MEDIANS: f64 = 2.0;

/// Cells per member at most.
const CELLS_PER_MEMBER: f64 = 2.0;

/// Cells a member covers at most to be listed in them (else it is tested by every query).
const SPAN: u64 = 16;

/// Members covering more than [`SPAN`] cells at most: beyond, the tree answers.
const BIG: usize = 16;

/// A member's box and handle, as a cell lists it.
#[derive(Clone, Copy, Debug)]
struct Entry {
    min: Vec2,
    max: Vec2,
    handle: u32,
    /// Whether this cell is the member's first column ([`FIRST_COLUMN`]) and first row
    /// ([`FIRST_ROW`]): in the padding, so the entry stays 40 bytes.
    first: u8,
}

/// [`Entry::first`]'s bit: the cell is in the member's first column.
const FIRST_COLUMN: u8 = 1;
/// [`Entry::first`]'s bit: the cell is in the member's first row.
const FIRST_ROW: u8 = 2;

impl Entry {
    /// Whether the entry's box overlaps `q` (touching counts), as [`Bounds::overlaps`]:
    /// the smallest of the four gaps is not negative. Written as arithmetic, not as four
    /// comparisons, which the compiler turns into four branches, each a coin toss for the
    /// predictor on a scan of a cell. Exact for finite boxes: a difference of two finite
    /// doubles is negative exactly when the first is smaller (it rounds, but never to zero
    /// or across it), and the grid holds finite boxes only.
    #[inline(always)]
    fn meets(&self, q: &Bounds) -> bool {
        let gap = smaller(
            smaller(q.max.x - self.min.x, self.max.x - q.min.x),
            smaller(q.max.y - self.min.y, self.max.y - q.min.y),
        );
        gap >= 0.0
    }
}

impl Entry {
    /// `f(handle, max)` if the segment crosses the entry's box within `max` (as the tree's
    /// walk tests it), else `max`.
    #[inline(always)]
    fn cross(&self, slab: &Slab, max: f64, f: &mut impl FnMut(usize, f64) -> f64) -> f64 {
        let b = Bounds {
            min: self.min,
            max: self.max,
        };
        match slab.enter(&b, max) {
            Some(t) if t <= max => f(self.handle as usize, max),
            _ => max,
        }
    }
}

/// A uniform grid over a set's member boxes, cells in rows (see the module docs).
#[derive(Debug)]
pub(crate) struct Grid {
    /// The lower corner of cell `(0, 0)`.
    origin: Vec2,
    /// Cells per length unit (one over the cell's side).
    inv: f64,
    /// The cell's side.
    side: f64,
    /// The box around every member listed or kept apart.
    hull: Bounds,
    /// Cells along x (a row's length).
    nx: u32,
    /// The last column and row (cells along x and y, less one), as floats: the clamp of
    /// [`Grid::column`].
    last: Vec2,
    /// Cell `c`'s entries are `entries[start[c] .. start[c + 1]]`.
    start: Vec<u32>,
    entries: Vec<Entry>,
    /// The members covering more than [`SPAN`] cells, tested by every query.
    big: Vec<Entry>,
}

impl Grid {
    /// The grid over `boxes` (by handle), or `None` when a box is infinite or too many
    /// are too large for the cell (the tree answers then). A box with a NaN coordinate
    /// meets nothing and is left out (the tree stores it empty).
    pub(crate) fn new(boxes: &[Bounds]) -> Option<Grid> {
        if boxes.len() >= u32::MAX as usize {
            return None;
        }
        // Neither NaN nor empty (`min > max`, as the tree stores a NaN box): it meets
        // nothing.
        let some = |b: &Bounds| b.min.x <= b.max.x && b.min.y <= b.max.y;
        let members: Vec<(u32, &Bounds)> = (0..).zip(boxes).filter(|(_, b)| some(b)).collect();
        if members
            .iter()
            .any(|(_, b)| !(b.min.is_finite() && b.max.is_finite()))
        {
            return None;
        }
        let hull = members.iter().map(|(_, b)| **b).reduce(Bounds::union)?;
        let mut sizes: Vec<f64> = members
            .iter()
            .map(|(_, b)| (b.max.x - b.min.x).max(b.max.y - b.min.y))
            .collect();
        // The median's value, whatever the selection's order (linear, not a sort).
        let mid = sizes.len() / 2;
        sizes.select_nth_unstable_by(mid, f64::total_cmp);
        let (w, h) = (hull.max.x - hull.min.x, hull.max.y - hull.min.y);
        // At least twice the median member, and big enough for the cell count's bound.
        let most = CELLS_PER_MEMBER * members.len() as f64;
        let side = (MEDIANS * sizes[mid])
            .max((w * h / most).sqrt())
            .max(w.max(h) / most)
            .max(f64::MIN_POSITIVE);
        let inv = 1.0 / side;
        if !(inv.is_finite() && inv > 0.0) {
            return None;
        }
        let count = |len: f64| {
            ((len * inv) as u64)
                .saturating_add(1)
                .min(u64::from(u32::MAX))
        };
        let (nx, ny) = (count(w), count(h));
        // `side` bounds the cells by `3 * most + 1` (`(w / side + 1) * (h / side + 1)`).
        let cells = nx
            .checked_mul(ny)
            .filter(|&c| c as f64 <= 3.0 * most + 4.0)?;
        let mut grid = Grid {
            origin: hull.min,
            inv,
            side,
            hull,
            nx: nx as u32,
            last: Vec2::new((nx - 1) as f64, (ny - 1) as f64),
            start: vec![0; cells as usize + 1],
            entries: Vec::new(),
            big: Vec::new(),
        };
        let entry = |k: u32, b: &Bounds, first: u8| Entry {
            min: b.min,
            max: b.max,
            handle: k,
            first,
        };
        let mut listed = Vec::with_capacity(members.len());
        for &(k, b) in &members {
            let span = grid.listed(b);
            let (x0, y0, x1, y1) = span;
            if u64::from(x1 - x0 + 1) * u64::from(y1 - y0 + 1) > SPAN {
                grid.big.push(entry(k, b, 0));
                if grid.big.len() > BIG {
                    return None;
                }
                continue;
            }
            for y in y0..=y1 {
                for x in x0..=x1 {
                    let c = grid.cell(x, y);
                    grid.start[c + 1] += 1;
                }
            }
            listed.push((k, b, span));
        }
        for c in 1..grid.start.len() {
            grid.start[c] += grid.start[c - 1];
        }
        let total = grid.start[cells as usize] as usize;
        let mut next = grid.start.clone();
        let mut entries = vec![entry(0, &hull, 0); total];
        for &(k, b, (x0, y0, x1, y1)) in &listed {
            for y in y0..=y1 {
                for x in x0..=x1 {
                    let c = grid.cell(x, y);
                    let first =
                        (u8::from(x == x0) * FIRST_COLUMN) | (u8::from(y == y0) * FIRST_ROW);
                    entries[next[c] as usize] = entry(k, b, first);
                    next[c] += 1;
                }
            }
        }
        grid.entries = entries;
        Some(grid)
    }

    /// The column (or row) of coordinate `v` on the axis starting at `o` whose last cell
    /// is `last`: monotone in `v`, clamped into the grid (a coordinate outside it counts as
    /// the edge cell, which keeps the module's argument: both boxes' cells are clamped
    /// alike).
    #[inline(always)]
    fn column(&self, v: f64, o: f64, last: f64) -> u32 {
        // Clamped to `[0, last]` first (`max` takes NaN to 0), so the conversion is in
        // range: truncating the clamped `t` is its floor.
        ((v - o) * self.inv).max(0.0).min(last) as u32
    }

    /// [`Grid::column`] on the x axis.
    #[inline(always)]
    fn column_x(&self, x: f64) -> u32 {
        self.column(x, self.origin.x, self.last.x)
    }

    /// [`Grid::column`] on the y axis: the row.
    #[inline(always)]
    fn row_y(&self, y: f64) -> u32 {
        self.column(y, self.origin.y, self.last.y)
    }

    /// The last column (or row) a member's box ending at `v` is listed in, its first being
    /// `first`: [`Grid::column`]'s, less one when `v` lies exactly on that cell's lower
    /// edge (the box only touches the cell).
    #[inline(always)]
    fn last_listed(&self, first: u32, v: f64, o: f64, last: f64) -> u32 {
        let c = self.column(v, o, last);
        if c > first && (v - o) * self.inv == f64::from(c) {
            c - 1
        } else {
            c
        }
    }

    /// The cells member box `b` is listed in (see the module docs): columns `x0..=x1`,
    /// rows `y0..=y1`.
    fn listed(&self, b: &Bounds) -> (u32, u32, u32, u32) {
        let (x0, y0) = (self.column_x(b.min.x), self.row_y(b.min.y));
        (
            x0,
            y0,
            self.last_listed(x0, b.max.x, self.origin.x, self.last.x),
            self.last_listed(y0, b.max.y, self.origin.y, self.last.y),
        )
    }

    /// The cells `b` covers: columns `x0..=x1`, rows `y0..=y1`.
    #[inline(always)]
    fn span(&self, b: &Bounds) -> (u32, u32, u32, u32) {
        (
            self.column_x(b.min.x),
            self.row_y(b.min.y),
            self.column_x(b.max.x),
            self.row_y(b.max.y),
        )
    }

    #[inline(always)]
    fn cell(&self, x: u32, y: u32) -> usize {
        y as usize * self.nx as usize + x as usize
    }

    /// Calls `f` with every member whose box overlaps the finite box `q` (touching counts),
    /// once each.
    #[inline]
    pub(crate) fn query(&self, q: &Bounds, f: &mut impl FnMut(usize)) {
        for e in &self.big {
            if e.meets(q) {
                f(e.handle as usize);
            }
        }
        let (x0, y0, x1, y1) = self.span(q);
        for y in y0..=y1 {
            let row = y as usize * self.nx as usize;
            // Reported from the cell of the intersection's lower corner only: its column
            // is `max(x0, the member's first)` (`column` is monotone), so it is this cell's
            // when this is the query's first column or the member's (both are at most
            // `x`), and likewise its row.
            let at_y0 = if y == y0 { FIRST_ROW } else { 0 };
            for x in x0..=x1 {
                let c = row + x as usize;
                let (from, to) = (self.start[c] as usize, self.start[c + 1] as usize);
                let here = at_y0 | if x == x0 { FIRST_COLUMN } else { 0 };
                for e in &self.entries[from..to] {
                    if ((e.first | here) == (FIRST_COLUMN | FIRST_ROW)) & e.meets(q) {
                        f(e.handle as usize);
                    }
                }
            }
        }
    }
}

impl Grid {
    /// Calls `f` on every member whose box the segment `origin + t * dir`, `t` in
    /// `[0, max]`, may cross ([`Slab::enter`], as the tree's walk tests it), possibly more
    /// than once; `f` returns the new `max`. Rows of cells are visited in the order the
    /// segment crosses them, and the walk stops at the first row it enters beyond `max`.
    /// `false` (nothing called) when the segment is not finite or lies so far from the
    /// grid that its rounding nears [`Grid::ray`]'s margin: the tree answers then.
    ///
    /// The cells visited are those within a margin of the segment (a millionth of a cell,
    /// ten times the slab test's rounding pad, a `1e-12` of the coordinates, at the farthest
    /// the grid is walked: `1e5` cells from the origin), so every
    /// member whose padded box the segment enters is in a cell visited.
    pub(crate) fn ray(
        &self,
        origin: Vec2,
        dir: Vec2,
        max: f64,
        f: &mut impl FnMut(usize, f64) -> f64,
    ) -> bool {
        let far = origin
            .abs()
            .max(self.hull.min.abs())
            .max(self.hull.max.abs());
        let end = origin + dir * max;
        let usable = origin.is_finite()
            && end.is_finite()
            && max.is_finite()
            && far.x.max(far.y) < self.side * 1e5;
        if !usable {
            return false;
        }
        let slab = Slab::new(origin, dir, &self.hull);
        let mut max = max;
        for e in &self.big {
            max = e.cross(&slab, max, f);
        }
        let m = self.side * 1e-6;
        // The rows the segment's box covers, widened by the margin, in the order it
        // crosses them.
        let (lo, hi) = (origin.min(end), origin.max(end));
        let r0 = self.row_y(lo.y - m);
        let r1 = self.row_y(hi.y + m);
        let up = dir.y >= 0.0;
        let inv_y = 1.0 / dir.y;
        // Handles tested last, newest first (a member listed in the cells a segment
        // crosses next to each other is tested once, not once a cell; a repeat is
        // harmless, only slower). Shifted along rather than written at a rotating slot:
        // a 4-byte store into the array the next check loads whole stalls the load.
        let mut recent = [u32::MAX; 4];
        for n in 0..=(r1 - r0) {
            let r = if up { r0 + n } else { r1 - n };
            // Where the segment is within the row (widened): its `t` range, then its x.
            let y_lo = self.origin.y + f64::from(r) * self.side - m;
            let y_hi = self.origin.y + f64::from(r + 1) * self.side + m;
            let (t0, t1) = if inv_y.is_finite() {
                let (a, b) = ((y_lo - origin.y) * inv_y, (y_hi - origin.y) * inv_y);
                (a.min(b).max(0.0), a.max(b).min(max))
            } else {
                (0.0, max)
            };
            if t0 > max {
                // This row, and every row after it, lies beyond the nearest hit.
                break;
            }
            if t0 > t1 {
                continue;
            }
            let (xa, xb) = (origin.x + dir.x * t0, origin.x + dir.x * t1);
            let c0 = self.column_x(xa.min(xb) - m);
            let c1 = self.column_x(xa.max(xb) + m);
            let row = r as usize * self.nx as usize;
            for k in 0..=(c1 - c0) {
                let c = row + if dir.x >= 0.0 { c0 + k } else { c1 - k } as usize;
                let (from, to) = (self.start[c] as usize, self.start[c + 1] as usize);
                for e in &self.entries[from..to] {
                    let h = e.handle;
                    if (recent[0] == h) | (recent[1] == h) | (recent[2] == h) | (recent[3] == h) {
                        continue;
                    }
                    max = e.cross(&slab, max, f);
                    recent = [h, recent[0], recent[1], recent[2]];
                }
            }
        }
        true
    }
}

#[cfg(test)]
mod tests;
