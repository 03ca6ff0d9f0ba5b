//! The per-axis stages' static boxes as a tile map: a dense array of tile ids by cell, for
//! the tiles on a regular lattice, and a [`FixedGrid`] for the rest.

use ricochet_geom::{Bounds, Vec2};

use super::FixedGrid;

/// One static box handed to [`TileMap::new`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct StaticBox {
    /// Its bounds, exactly as the caller computes them.
    pub bounds: Bounds,
    /// Its centre and half extents when `bounds` is `Bounds::around(centre, half)` bit for
    /// bit (an axis-aligned box on its body's origin): only such a box can be a tile.
    pub centre: Option<(Vec2, Vec2)>,
    /// What [`TileMap::query`] reports for it (the per-axis stages: its rank among the
    /// static bodies).
    pub handle: u32,
    /// Reported with it (its layer).
    pub tag: u8,
}

/// Which static boxes overlap a query box. Most of a level is tiles of one size on a
/// regular lattice (centre `origin + (i, j) * step`, as a scenario's tile rows are spawned),
/// and a tile's bounds follow from its cell: those are kept as one `u32` a cell (the tile's
/// handle plus one, 0 for an empty cell), row by row, so a lookup reads one word per cell it
/// covers and never an entry it has to filter (4 bytes a cell, against the grid's 40 bytes
/// a tile). Every other box, and a tile the lattice cannot place bit for bit, is in a
/// [`FixedGrid`].
///
/// The lattice is found from the boxes alone: the most common size and layer, the smallest
/// coordinates as the origin, and as the step along each axis the smallest non-zero gap
/// between two boxes handed in one after the other (tile rows are handed in order). A box
/// whose centre is not `origin + k * step` bit for bit, or whose cell is taken, goes to the
/// grid; so does every box when the lattice would have more than twice as many cells as
/// tiles (8 bytes a tile at most).
#[derive(Debug, Default, Clone)]
pub(crate) struct TileMap {
    lattice: Lattice,
    rest: FixedGrid,
}

/// Tiles of one size and layer whose centres are `origin + (i, j) * step`.
#[derive(Debug, Default, Clone)]
struct Lattice {
    /// The centre of cell `(0, 0)`.
    origin: Vec2,
    /// The distance between neighbouring cells' centres (positive).
    step: Vec2,
    /// Every tile's half extents.
    half: Vec2,
    /// Every tile's tag.
    tag: u8,
    /// Cells along x.
    cols: usize,
    /// Cells along y.
    rows: usize,
    /// Each cell's tile handle plus one, 0 when empty; `cols` a row, row by row.
    cells: Vec<u32>,
}

/// The key of a box's size and tag, bit for bit.
fn kind_of(half: Vec2, tag: u8) -> (u64, u64, u8) {
    (half.x.to_bits(), half.y.to_bits(), tag)
}

impl Lattice {
    /// The centre of cell `(i, j)`: the formula the cells are checked against.
    #[inline]
    fn centre(&self, i: usize, j: usize) -> Vec2 {
        Vec2::new(
            self.origin.x + i as f64 * self.step.x,
            self.origin.y + j as f64 * self.step.y,
        )
    }

    /// The cell whose centre is `c` bit for bit, if any, within `cols` by `rows` cells.
    fn cell_of(&self, c: Vec2, cols: usize, rows: usize) -> Option<(usize, usize)> {
        let index = |v: f64, o: f64, s: f64, n: usize| {
            let k = (v - o) / s + 0.5;
            // Irregular or outside: no cell. `k` is at most `n`, so the cast is exact.
            if !(k >= 0.0 && k < n as f64) {
                return None;
            }
            Some(k as usize)
        };
        let i = index(c.x, self.origin.x, self.step.x, cols)?;
        let j = index(c.y, self.origin.y, self.step.y, rows)?;
        let at = self.centre(i, j);
        (at.x.to_bits() == c.x.to_bits() && at.y.to_bits() == c.y.to_bits()).then_some((i, j))
    }

    /// The cells along one axis whose tiles may overlap `lo..=hi`, or `None`: cell `k`'s tile
    /// reaches `lo` when `k >= (lo - half - origin) / step` and `hi` when `k <= (hi + half -
    /// origin) / step`. The arithmetic rounds (a tile's bounds too, by a few units in the
    /// last place of the coordinates), so each end is widened by `slack` cells, a billionth
    /// of the coordinates' size in cells: millions of times the rounding, far below a cell
    /// (the caller tests the bounds exactly).
    #[inline]
    fn span(
        lo: f64,
        hi: f64,
        origin: f64,
        step: f64,
        half: f64,
        n: usize,
    ) -> Option<(usize, usize)> {
        let slack = 1e-9 * (1.0 + (lo.abs() + hi.abs() + origin.abs() + half + step) / step);
        let a = (lo - half - origin) / step - slack;
        let b = (hi + half - origin) / step + slack;
        // Rounded by casts (`f64::ceil` and `floor` are calls on the baseline x86-64), which
        // saturate: an infinite query reaches the ends. NaN (an infinite query minus an
        // infinite slack) casts to 0, the first cell: never a narrower span.
        let (ta, tb) = (a as i64, b as i64);
        let first = if (ta as f64) < a {
            ta.saturating_add(1)
        } else {
            ta
        }
        .max(0);
        let last = if b.is_nan() {
            n as i64 - 1
        } else if (tb as f64) > b {
            tb.saturating_sub(1)
        } else {
            tb
        }
        .min(n as i64 - 1);
        (first <= last).then_some((first as usize, last as usize))
    }
}

impl TileMap {
    /// Indexes the static boxes `boxes()` yields (called a few times, the same boxes each
    /// time: no copy of a million tiles is made to find the lattice).
    pub(crate) fn new<I: Iterator<Item = StaticBox>>(boxes: impl Fn() -> I) -> TileMap {
        let lattice = Lattice::find(&boxes).unwrap_or_default();
        let (mut cells, mut rest) = (lattice.cells.clone(), Vec::new());
        let key = kind_of(lattice.half, lattice.tag);
        for b in boxes() {
            let placed = b
                .centre
                .filter(|(_, h)| kind_of(*h, b.tag) == key)
                .and_then(|(c, _)| {
                    let (i, j) = lattice.cell_of(c, lattice.cols, lattice.rows)?;
                    let cell = &mut cells[j * lattice.cols + i];
                    let id = b.handle.checked_add(1)?;
                    (*cell == 0).then(|| *cell = id)
                });
            if placed.is_none() {
                rest.push((b.bounds, b.handle, b.tag));
            }
        }
        TileMap {
            lattice: Lattice { cells, ..lattice },
            rest: FixedGrid::new(&rest),
        }
    }

    /// Calls `f` once with the handle, bounds and tag of every box overlapping `q` (touching
    /// counts), tiles last. Returns the box tests made.
    pub(crate) fn query(&self, q: &Bounds, mut f: impl FnMut(u32, &Bounds, u8)) -> u64 {
        // A tile map alone leaves the grid empty: not even its cell arithmetic then.
        let mut tested = if self.rest.is_empty() {
            0
        } else {
            self.rest.query(q, &mut f)
        };
        let l = &self.lattice;
        if l.cells.is_empty() || !(q.min.x <= q.max.x && q.min.y <= q.max.y) {
            return tested;
        }
        let Some((i0, i1)) =
            Lattice::span(q.min.x, q.max.x, l.origin.x, l.step.x, l.half.x, l.cols)
        else {
            return tested;
        };
        let Some((j0, j1)) =
            Lattice::span(q.min.y, q.max.y, l.origin.y, l.step.y, l.half.y, l.rows)
        else {
            return tested;
        };
        for j in j0..=j1 {
            let row = &l.cells[j * l.cols..][..l.cols];
            for (&id, i) in row[i0..=i1].iter().zip(i0..) {
                if id == 0 {
                    continue;
                }
                tested += 1;
                let b = Bounds::around(l.centre(i, j), l.half);
                if b.overlaps(q) {
                    f(id - 1, &b, l.tag);
                }
            }
        }
        tested
    }

    /// The bytes the lattice's cells take, and how many tiles they hold.
    #[cfg(test)]
    fn lattice_size(&self) -> (usize, usize) {
        let l = &self.lattice.cells;
        (
            std::mem::size_of_val(l.as_slice()),
            l.iter().filter(|&&c| c != 0).count(),
        )
    }
}

impl Lattice {
    /// The lattice of the most common tile among `boxes()`, its cells empty, or `None` when
    /// there is no tile or it would be more than half empty.
    fn find<I: Iterator<Item = StaticBox>>(boxes: &impl Fn() -> I) -> Option<Lattice> {
        // The most common size and tag (the first of equals), among the first few kinds.
        let mut kinds: Vec<((u64, u64, u8), usize, Vec2)> = Vec::new();
        for (h, tag) in boxes().filter_map(|b| Some((b.centre?.1, b.tag))) {
            let k = kind_of(h, tag);
            if let Some(seen) = kinds.iter_mut().find(|(x, ..)| *x == k) {
                seen.1 += 1;
            } else if kinds.len() < 16 {
                kinds.push((k, 1, h));
            }
        }
        let mut best = kinds.first()?;
        for k in &kinds {
            if k.1 > best.1 {
                best = k;
            }
        }
        let (key, count, half) = *best;
        // The origin, and the smallest gap between consecutive tiles along each axis.
        let mut origin = Vec2::splat(f64::INFINITY);
        let mut step = Vec2::splat(f64::INFINITY);
        let mut last: Option<Vec2> = None;
        for b in boxes() {
            let Some((c, h)) = b.centre.filter(|(_, h)| kind_of(*h, b.tag) == key) else {
                continue;
            };
            debug_assert_eq!(h.x.to_bits(), half.x.to_bits());
            origin = origin.min(c);
            if let Some(p) = last {
                let d = (c - p).abs();
                for a in 0..2 {
                    // A gap under a quarter of the tile is no step (a tile off the lattice
                    // by an ulp, say): it would leave every other tile off the lattice.
                    if d[a] >= 0.25 * half[a] && d[a] < step[a] {
                        step[a] = d[a];
                    }
                }
            }
            last = Some(c);
        }
        for a in 0..2 {
            // One column or one row: any step will do.
            if !step[a].is_finite() {
                step[a] = 1.0;
            }
        }
        if !(origin.is_finite() && step.is_finite()) {
            return None;
        }
        let mut lattice = Lattice {
            origin,
            step,
            half,
            tag: key.2,
            cols: 0,
            rows: 0,
            cells: Vec::new(),
        };
        // The cells the tiles reach, capped at twice the tiles.
        let cap = 2 * count + 64;
        let (mut cols, mut rows) = (0usize, 0usize);
        for b in boxes() {
            let Some((c, _)) = b.centre.filter(|(_, h)| kind_of(*h, b.tag) == key) else {
                continue;
            };
            if let Some((i, j)) = lattice.cell_of(c, cap, cap) {
                cols = cols.max(i + 1);
                rows = rows.max(j + 1);
            }
        }
        if cols == 0 || cols.saturating_mul(rows) > cap {
            return None;
        }
        (lattice.cols, lattice.rows) = (cols, rows);
        lattice.cells = vec![0; cols * rows];
        Some(lattice)
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::super::grid::test_boxes;
    use super::*;

    /// The boxes as [`StaticBox`]es, handles in order, tags 1 and 0 in turn.
    fn static_boxes(boxes: &[(Bounds, Option<(Vec2, Vec2)>)]) -> Vec<StaticBox> {
        boxes
            .iter()
            .enumerate()
            .map(|(k, &(bounds, centre))| StaticBox {
                bounds,
                centre,
                handle: k as u32,
                tag: (k % 3 == 0) as u8,
            })
            .collect()
    }

    /// Brute force: the handles of every box overlapping `q`, ascending.
    fn expected(boxes: &[StaticBox], q: &Bounds) -> Vec<u32> {
        boxes
            .iter()
            .filter(|b| b.bounds.overlaps(q))
            .map(|b| b.handle)
            .collect()
    }

    fn found(map: &TileMap, boxes: &[StaticBox], q: &Bounds) -> Vec<u32> {
        let mut found = Vec::new();
        map.query(q, |h, b, tag| {
            let src = &boxes[h as usize];
            assert_eq!(*b, src.bounds);
            assert_eq!(tag, src.tag);
            found.push(h);
        });
        found.sort_unstable();
        found
    }

    /// A tile map's rows: half extents `half`, step `step`, at `origin`, some cells left out,
    /// some tiles nudged off the lattice by an ulp, and odd boxes among them.
    fn level() -> impl Strategy<Value = Vec<(Bounds, Option<(Vec2, Vec2)>)>> {
        (
            prop_oneof![Just(0.5), Just(0.25), Just(0.7), 0.1..1.0f64],
            prop_oneof![Just(1.0), Just(0.5), 0.3..2.0f64],
            prop_oneof![Just(5.0), Just(1.0), 0.5..7.0f64],
            prop_oneof![Just(0.5), Just(1e6 + 0.5), -30.0..30.0f64],
            proptest::collection::vec((0..24usize, 0..6usize, 0..20u8), 0..120),
            test_boxes(),
        )
            .prop_map(|(h, sx, sy, o, cells, odd)| {
                let half = Vec2::new(h, 0.5 * h + 0.1);
                let mut out = Vec::new();
                for (i, j, what) in cells {
                    let mut c = Vec2::new(o + i as f64 * sx, -3.0 + j as f64 * sy);
                    if what == 0 {
                        c.x = f64::from_bits(c.x.to_bits() + 1);
                    }
                    let half = if what == 1 { half * 2.0 } else { half };
                    out.push((Bounds::around(c, half), Some((c, half))));
                }
                out.extend(odd.iter().map(|b| (*b, None)));
                out
            })
    }

    proptest! {
        #[test]
        fn tile_map_finds_exactly_the_overlapping_boxes_once(
            boxes in level(),
            queries in test_boxes(),
        ) {
            let boxes = static_boxes(&boxes);
            let map = TileMap::new(|| boxes.iter().copied());
            for q in &queries {
                prop_assert_eq!(found(&map, &boxes, q), expected(&boxes, q));
            }
            // Around every box too, where its neighbours are.
            for b in &boxes {
                prop_assert_eq!(found(&map, &boxes, &b.bounds), expected(&boxes, &b.bounds));
            }
        }
    }

    #[test]
    fn a_platformer_level_is_all_lattice_at_under_eight_bytes_a_tile() {
        // Floors 5 apart of 1×1 tiles, a gap every 8: as the platformer bench scene.
        let half = Vec2::splat(0.5);
        let mut boxes = Vec::new();
        for floor in 0..40 {
            for col in 0..64 {
                if floor > 0 && (col + 3 * floor) % 8 == 4 {
                    continue;
                }
                let c = Vec2::new(col as f64 + 0.5, 5.0 * floor as f64);
                boxes.push((Bounds::around(c, half), Some((c, half))));
            }
        }
        let boxes: Vec<_> = static_boxes(&boxes)
            .into_iter()
            .map(|b| StaticBox { tag: 0, ..b })
            .collect();
        let map = TileMap::new(|| boxes.iter().copied());
        let (bytes, tiles) = map.lattice_size();
        assert_eq!(tiles, boxes.len());
        assert!(bytes <= 8 * tiles, "{bytes} bytes for {tiles} tiles");
        let q = Bounds::around(Vec2::new(10.0, 0.9), Vec2::splat(0.4));
        assert_eq!(found(&map, &boxes, &q), expected(&boxes, &q));
        assert_eq!(found(&map, &boxes, &q).len(), 2);
        let nan = Bounds::around(Vec2::splat(f64::NAN), Vec2::ONE);
        assert!(found(&map, &boxes, &nan).is_empty());
        let all = Bounds::around(Vec2::ZERO, Vec2::splat(f64::INFINITY));
        assert_eq!(found(&map, &boxes, &all).len(), boxes.len());
    }

    /// The handles `q` finds among `at`, tiles of half extents 0.5 and tag 0, and the
    /// lattice's size.
    fn tiles_at(at: &[Vec2], q: &Bounds) -> (Vec<u32>, (usize, usize)) {
        let half = Vec2::splat(0.5);
        let boxes: Vec<_> = at
            .iter()
            .map(|&c| (Bounds::around(c, half), Some((c, half))))
            .collect();
        let boxes: Vec<_> = static_boxes(&boxes)
            .into_iter()
            .map(|b| StaticBox { tag: 0, ..b })
            .collect();
        let map = TileMap::new(|| boxes.iter().copied());
        (found(&map, &boxes, q), map.lattice_size())
    }

    #[test]
    fn a_tile_far_off_the_lattice_or_a_scattered_level_goes_to_the_grid() {
        let far = Vec2::new(1e6, 1e6);
        let q = Bounds::around(far, Vec2::splat(0.5));
        let row = [Vec2::ZERO, Vec2::X, Vec2::new(2.0, 0.0), far];
        assert_eq!(tiles_at(&row, &q), (vec![3], (12, 3)));
        // A diagonal: 100 tiles would take 100 × 100 cells.
        let diagonal: Vec<Vec2> = (0..100).map(|k| Vec2::splat(f64::from(k))).collect();
        let q = Bounds::around(Vec2::splat(50.0), Vec2::splat(0.5));
        assert_eq!(tiles_at(&diagonal, &q), (vec![49, 50, 51], (0, 0)));
        let empty = TileMap::new(std::iter::empty);
        let mut n = 0;
        empty.query(&q, |_, _, _| n += 1);
        assert_eq!(n, 0);
    }
}
