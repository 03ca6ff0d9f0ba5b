//! A grid over the per-axis stages' moving boxes, rebuilt every pass and filled box by box.

use ricochet_geom::Bounds;

use super::grid::Cells;

/// The moving boxes that are solid to the box being settled: a uniform grid rebuilt every
/// pass, filled as boxes settle. A lookup may return a box twice, or one that does not
/// overlap: the caller sorts, dedups and tests.
#[derive(Debug, Default, Clone)]
pub(crate) struct MoverGrid {
    /// The cell size, and the hash of a cell to one of `buckets`.
    cells: Cells,
    /// The boxes entered in each bucket; the length is a power of two.
    buckets: Vec<Vec<u32>>,
    /// Buckets filled this pass, to empty next pass.
    used: Vec<usize>,
    /// Boxes kept aside by [`Cells::placed`] (covering too many cells, or irregular): met by
    /// every lookup.
    big: Vec<u32>,
}

impl MoverGrid {
    /// Empties the grid and sizes its cells at twice the median of `extents` (the dynamic
    /// boxes' larger side), for about `count` boxes.
    pub(crate) fn reset(&mut self, extents: &mut [f64], count: usize) {
        for &b in &self.used {
            self.buckets[b].clear();
        }
        self.used.clear();
        self.big.clear();
        let size = (2 * count).max(16).next_power_of_two();
        if self.buckets.len() < size {
            self.buckets.resize_with(size, Vec::new);
        }
        self.cells = Cells::hashed(extents, self.buckets.len());
    }

    /// Whether no box was entered since the last reset.
    pub(crate) fn is_empty(&self) -> bool {
        self.used.is_empty() && self.big.is_empty()
    }

    /// Enters box `b` as `handle`.
    pub(crate) fn insert(&mut self, b: &Bounds, handle: u32) {
        let Some(r) = self.cells.placed(b) else {
            self.big.push(handle);
            return;
        };
        for c in r.cells() {
            let k = self.cells.hashed_bucket(c);
            if self.buckets[k].is_empty() {
                self.used.push(k);
            }
            self.buckets[k].push(handle);
        }
    }

    /// Calls `f` with the handle of every box that may overlap `q` (at least every box that
    /// does), in no useful order and possibly more than once.
    pub(crate) fn query(&self, q: &Bounds, mut f: impl FnMut(u32)) {
        for &h in &self.big {
            f(h);
        }
        match self.cells.placed(q) {
            Some(r) => {
                for c in r.cells() {
                    for &h in &self.buckets[self.cells.hashed_bucket(c)] {
                        f(h);
                    }
                }
            }
            None => {
                for &b in &self.used {
                    for &h in &self.buckets[b] {
                        f(h);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;
    use ricochet_geom::Vec2;

    use super::super::grid::test_boxes as boxes;
    use super::*;

    /// What a lookup returns, sorted and without repeats, as the per-axis stages take it.
    fn found(grid: &MoverGrid, q: &Bounds) -> Vec<u32> {
        let mut found = Vec::new();
        grid.query(q, |h| found.push(h));
        found.sort_unstable();
        found.dedup();
        found
    }

    proptest! {
        #[test]
        fn mover_grid_finds_every_overlapping_box(
            sized in boxes(),
            inserted in boxes(),
            queries in boxes(),
        ) {
            let mut grid = MoverGrid::default();
            // Twice: a reset empties what the last pass filled.
            for _ in 0..2 {
                let mut extents: Vec<f64> =
                    sized.iter().map(|b| (b.max - b.min).max_element()).collect();
                grid.reset(&mut extents, sized.len());
                for (i, b) in inserted.iter().enumerate() {
                    grid.insert(b, i as u32);
                }
                for q in &queries {
                    let found = found(&grid, q);
                    for (i, b) in inserted.iter().enumerate() {
                        if b.overlaps(q) {
                            prop_assert!(found.binary_search(&(i as u32)).is_ok());
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn mover_grid_keeps_irregular_and_huge_boxes_aside() {
        let mut grid = MoverGrid::default();
        grid.reset(&mut [1.0], 4);
        let tile = |x: f64| Bounds::around(Vec2::new(x, 0.0), Vec2::splat(0.5));
        grid.insert(&tile(0.0), 0);
        grid.insert(&tile(100.0), 1);
        grid.insert(&Bounds::around(Vec2::splat(f64::NAN), Vec2::ONE), 2);
        grid.insert(&Bounds::around(Vec2::ZERO, Vec2::splat(1e6)), 3);
        // The tile, and the boxes kept aside (the other tile only if its cells share a bucket).
        let near = found(&grid, &tile(0.0));
        assert!([0, 2, 3].iter().all(|h| near.contains(h)), "{near:?}");
        let everything = Bounds::around(Vec2::ZERO, Vec2::splat(1e9));
        assert_eq!(found(&grid, &everything), [0, 1, 2, 3]);
        assert_eq!(
            found(&grid, &Bounds::around(Vec2::splat(f64::NAN), Vec2::ONE)),
            [0, 1, 2, 3]
        );
        grid.reset(&mut [], 0);
        assert_eq!(found(&grid, &everything), [] as [u32; 0]);
    }
}
