//! A grid over boxes that never move, built once, for the per-axis stages' static boxes.

use ricochet_geom::{Bounds, Vec2};

use super::grid::{CellRange, Cells};

/// A grid over boxes that never move, built once (the per-axis stages' static boxes): which
/// of them overlap a query box. Laid out as the broad phase's grids ([`Cells`]), but each
/// cell's entries hold the boxes' bounds themselves, so a lookup in a million tiles reads a
/// few cache lines (the cell's bucket start and its entries) and never the bodies. A box
/// covering more than [`MAX_CELLS`](super::grid::MAX_CELLS) cells (or with irregular bounds) is kept in a list every
/// lookup scans.
#[derive(Debug, Default, Clone)]
pub(crate) struct FixedGrid {
    /// The cell size and table layout.
    cells: Cells,
    /// Bucket `b` is `entries[starts[b]..starts[b + 1]]`.
    starts: Vec<u32>,
    /// Each box once in every cell it covers.
    entries: Vec<FixedEntry>,
    /// The boxes in no cell, with their handles.
    big: Vec<(Bounds, u32)>,
}

/// A box in one of its cells.
#[derive(Clone, Copy, Debug)]
struct FixedEntry {
    /// The cell.
    cell: (i32, i32),
    /// The box's handle.
    handle: u32,
    /// The box.
    bounds: Bounds,
}

impl FixedGrid {
    /// Indexes `boxes`, each with a handle reported by [`FixedGrid::query`].
    pub(crate) fn new(boxes: impl Iterator<Item = (Bounds, u32)>) -> FixedGrid {
        let boxes: Vec<(Bounds, u32)> = boxes.collect();
        let mut g = FixedGrid {
            cells: Cells::sized_for(boxes.iter().map(|(b, _)| b), &mut Vec::new()),
            ..FixedGrid::default()
        };
        let mut placed: Vec<(CellRange, (Bounds, u32))> = Vec::with_capacity(boxes.len());
        for &(b, h) in &boxes {
            match g.cells.placed(&b) {
                Some(r) => placed.push((r, (b, h))),
                None => g.big.push((b, h)),
            }
        }
        let blank = FixedEntry {
            cell: (0, 0),
            handle: 0,
            bounds: Bounds::around(Vec2::ZERO, Vec2::ZERO),
        };
        let entry = |cell, (bounds, handle)| FixedEntry {
            cell,
            handle,
            bounds,
        };
        g.cells
            .fill(&placed, blank, entry, &mut g.starts, &mut g.entries);
        g
    }

    /// Calls `f` once with the handle and bounds of every box overlapping `q` (touching
    /// counts). Returns the box tests made.
    pub(crate) fn query(&self, q: &Bounds, mut f: impl FnMut(u32, &Bounds)) -> u64 {
        let mut tested = 0;
        for (b, h) in &self.big {
            tested += 1;
            if b.overlaps(q) {
                f(*h, b);
            }
        }
        let Some(r) = self.cells.range(q).map(|r| self.cells.clip(r)) else {
            return tested;
        };
        if r.count() > self.entries.len() as u64 {
            // Larger than everything: each box once, from its entry in its own first cell
            // (the lower-left one it covers).
            for e in &self.entries {
                let first = (
                    self.cells.coord(e.bounds.min.x),
                    self.cells.coord(e.bounds.min.y),
                );
                if e.cell == first {
                    tested += 1;
                    if e.bounds.overlaps(q) {
                        f(e.handle, &e.bounds);
                    }
                }
            }
            return tested;
        }
        for c in r.cells() {
            let Some(k) = self.cells.bucket(c) else {
                continue;
            };
            for e in &self.entries[self.starts[k] as usize..self.starts[k + 1] as usize] {
                if e.cell != c {
                    continue;
                }
                tested += 1;
                // Reported once: in the cell holding the lower-left corner of the overlap.
                if e.bounds.overlaps(q) && self.cells.owns(&e.bounds, q, c) {
                    f(e.handle, &e.bounds);
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
            let grid = FixedGrid::new(fixed.iter().enumerate().map(|(i, b)| (*b, i as u32)));
            for q in &queries {
                let mut found = Vec::new();
                grid.query(q, |h, b| {
                    assert_eq!(*b, fixed[h as usize]);
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
        let tiles: Vec<(Bounds, u32)> = (0..100)
            .map(|i| {
                let p = Vec2::new(f64::from(i % 10), f64::from(i / 10));
                (Bounds::around(p, Vec2::splat(0.5)), i)
            })
            .collect();
        let grid = FixedGrid::new(tiles.iter().copied());
        let count = |q: Bounds| {
            let mut n = 0;
            grid.query(&q, |_, _| n += 1);
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
        let empty = FixedGrid::new(std::iter::empty());
        let mut n = 0;
        empty.query(&Bounds::around(Vec2::ZERO, Vec2::ONE), |_, _| n += 1);
        assert_eq!(n, 0);
    }
}
