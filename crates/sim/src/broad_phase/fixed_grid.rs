//! A grid over boxes that never move, built once, for the per-axis stages' static boxes.

use ricochet_geom::{Bounds, Vec2};

use super::grid::{CellRange, Cells, MAX_CELLS};

/// A grid over boxes that never move, built once (the per-axis stages' static boxes): which
/// of them overlap a query box. Laid out as the broad phase's grids ([`Cells`]: cells twice
/// the median box), each entry holding its box's bounds, so a lookup in a million tiles
/// reads a few cache lines (a cell's bucket start and its entries) and never the bodies.
///
/// A box at most two cells wide and two high (every tile of a tile map) is entered once, in
/// the cell of its lower-left corner: a box overlapping a query has its corner in the
/// query's cells or one cell below or left of them, so a lookup reaches one cell further
/// down and left and meets each such box once (40 bytes a tile). A larger box (up to
/// [`MAX_CELLS`] cells) is entered in every cell it covers and
/// reported from the cell holding the lower-left corner of the overlap; a box covering more,
/// or with irregular bounds, is kept in a list every lookup scans.
#[derive(Debug, Default, Clone)]
pub(crate) struct FixedGrid {
    /// Boxes at most two cells wide and high, each once, in its lower-left corner's cell.
    corner: Table<Entry>,
    /// Larger boxes, in every cell they cover, with the cell.
    spread: Table<(Entry, (i32, i32))>,
    /// The boxes in no cell.
    big: Vec<Entry>,
}

/// One table of entries, counting-sorted by cell: bucket `b` is
/// `entries[starts[b]..starts[b + 1]]`.
#[derive(Debug, Clone)]
struct Table<E> {
    /// The cell size and table layout.
    cells: Cells,
    starts: Vec<u32>,
    entries: Vec<E>,
}

/// A box, its handle and its tag (in what would be padding).
#[derive(Clone, Copy, Debug)]
struct Entry {
    bounds: Bounds,
    handle: u32,
    tag: u8,
}

impl<E> Default for Table<E> {
    fn default() -> Self {
        Table {
            cells: Cells::default(),
            starts: Vec::new(),
            entries: Vec::new(),
        }
    }
}

impl<E: Copy> Table<E> {
    /// Counting-sorts `entry(cell, k)` for each of `items` (an index `k` with the cells it is
    /// entered in).
    fn fill(
        &mut self,
        cells: Cells,
        items: &[(CellRange, u32)],
        blank: E,
        entry: impl Fn((i32, i32), u32) -> E,
    ) {
        self.cells = cells;
        self.cells
            .fill(items, blank, entry, &mut self.starts, &mut self.entries);
    }

    /// The entries of cell `c`'s bucket (hashed: other cells' too).
    fn bucket(&self, c: (i32, i32)) -> &[E] {
        self.cells.bucket(c).map_or(&[], |k| {
            &self.entries[self.starts[k] as usize..self.starts[k + 1] as usize]
        })
    }
}

impl FixedGrid {
    /// Indexes `boxes`, each with a handle and a tag (the per-axis stages: the body's rank
    /// among the static bodies, and its layer) reported by [`FixedGrid::query`].
    pub(crate) fn new(boxes: &[(Bounds, u32, u8)]) -> FixedGrid {
        let cells = Cells::sized_for(boxes.iter().map(|(b, _, _)| b), &mut Vec::new());
        let mut g = FixedGrid::default();
        let (mut corner, mut spread) = (Vec::new(), Vec::new());
        let at = |k: usize| {
            let (bounds, handle, tag) = boxes[k];
            Entry {
                bounds,
                handle,
                tag,
            }
        };
        for (k, (bounds, _, _)) in boxes.iter().enumerate() {
            match cells.range(bounds) {
                Some(r) if r.within_two() => corner.push((r.corner(), k as u32)),
                Some(r) if r.count() <= MAX_CELLS => spread.push((r, k as u32)),
                _ => g.big.push(at(k)),
            }
        }
        let blank = Entry {
            bounds: Bounds::around(Vec2::ZERO, Vec2::ZERO),
            handle: 0,
            tag: 0,
        };
        g.corner.fill(cells, &corner, blank, |_, k| at(k as usize));
        drop(corner);
        g.spread
            .fill(cells, &spread, (blank, (0, 0)), |c, k| (at(k as usize), c));
        g
    }

    /// Whether it holds no box.
    pub(crate) fn is_empty(&self) -> bool {
        self.big.is_empty() && self.corner.entries.is_empty() && self.spread.entries.is_empty()
    }

    /// Calls `f` once with the handle, bounds and tag of every box overlapping `q` (touching
    /// counts). Returns the box tests made.
    pub(crate) fn query(&self, q: &Bounds, mut f: impl FnMut(u32, &Bounds, u8)) -> u64 {
        let mut tested = 0;
        let mut test = |e: &Entry| {
            tested += 1;
            if e.bounds.overlaps(q) {
                f(e.handle, &e.bounds, e.tag);
            }
        };
        self.big.iter().for_each(&mut test);
        // An irregular query overlaps nothing.
        let Some(r) = self.corner.cells.range(q) else {
            return tested;
        };
        // Boxes filed by their corner: one cell further down and left, each met once.
        let t = &self.corner;
        let reach = t.cells.clip(r.reach_back());
        if reach.count() > t.entries.len() as u64 {
            t.entries.iter().for_each(&mut test);
        } else {
            for c in reach.cells() {
                for e in t.bucket(c) {
                    // Hashed, a bucket holds other cells' boxes too.
                    if (t.cells.coord(e.bounds.min.x), t.cells.coord(e.bounds.min.y)) == c {
                        test(e);
                    }
                }
            }
        }
        // Boxes in every cell they cover: reported once, from the cell holding the lower
        // left corner of the overlap (or, looking at everything, from their first cell).
        let t = &self.spread;
        if t.entries.is_empty() {
            return tested;
        }
        let r = t.cells.clip(r);
        if r.count() > t.entries.len() as u64 {
            for (e, cell) in &t.entries {
                let first = (t.cells.coord(e.bounds.min.x), t.cells.coord(e.bounds.min.y));
                if *cell == first {
                    test(e);
                }
            }
            return tested;
        }
        for c in r.cells() {
            for (e, cell) in t.bucket(c) {
                if *cell == c && t.cells.owns(&e.bounds, q, c) {
                    test(e);
                }
            }
        }
        tested
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::super::grid::test_boxes as boxes;
    use super::*;

    proptest! {
        #[test]
        fn fixed_grid_finds_exactly_the_overlapping_boxes_once(
            fixed in boxes(),
            queries in boxes(),
        ) {
            let boxes: Vec<(Bounds, u32, u8)> =
                fixed.iter().enumerate().map(|(i, b)| (*b, i as u32, i as u8)).collect();
            let grid = FixedGrid::new(&boxes);
            for q in &queries {
                let mut found = Vec::new();
                grid.query(q, |h, b, tag| {
                    assert_eq!(*b, fixed[h as usize]);
                    assert_eq!(tag, h as u8);
                    found.push(h);
                });
                found.sort_unstable();
                let expected: Vec<u32> = (0..fixed.len() as u32)
                    .filter(|&i| fixed[i as usize].overlaps(q))
                    .collect();
                prop_assert_eq!(found, expected);
            }
        }
    }

    #[test]
    fn fixed_grid_handles_empty_nan_and_everything_queries() {
        let tiles: Vec<(Bounds, u32, u8)> = (0..100)
            .map(|i| {
                let p = Vec2::new(f64::from(i % 10), f64::from(i / 10));
                (Bounds::around(p, Vec2::splat(0.5)), i, 0)
            })
            .collect();
        let grid = FixedGrid::new(&tiles);
        let count = |q: Bounds| {
            let mut n = 0;
            grid.query(&q, |_, _, _| n += 1);
            n
        };
        assert_eq!(
            count(Bounds::around(Vec2::splat(4.5), Vec2::splat(1e9))),
            100
        );
        assert_eq!(count(Bounds::around(Vec2::splat(f64::NAN), Vec2::ONE)), 0);
        assert_eq!(
            count(Bounds::around(Vec2::new(0.0, 0.0), Vec2::splat(0.1))),
            1
        );
        let empty = FixedGrid::new(&[]);
        let mut n = 0;
        empty.query(&Bounds::around(Vec2::ZERO, Vec2::ONE), |_, _, _| n += 1);
        assert_eq!(n, 0);
    }
}
