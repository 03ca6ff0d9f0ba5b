//! `Grid`'s structure: a uniform grid of one layer's bodies, laid out by [`Cells`]. A query
//! covering more cells than the grid has bodies tests them all. A pair seen in several cells
//! is reported only in the cell holding the lower-left corner of the two boxes' intersection,
//! so nothing needs deduplicating. The static grids are built once, their members ordered by
//! cell so that a cell's bodies are neighbours in memory; the moving ones every call.

use ricochet_geom::Bounds;

use super::Member;
use super::grid::{CellRange, Cells, MAX_CELLS};

/// A uniform grid: `(cell, member)` entries counting-sorted by cell, into a dense table over
/// the occupied cells or a table indexed by a fixed hash of the cell.
#[derive(Debug, Default, Clone)]
pub(super) struct HashGrid {
    /// The call the grid was last built for (moving bodies).
    pub(super) frame: u64,
    /// The cell size and table layout.
    cells: Cells,
    /// Bucket `b` is `entries[starts[b]..starts[b + 1]]`.
    starts: Vec<u32>,
    /// `(cell x, cell y, member)`.
    entries: Vec<(i32, i32, u32)>,
    /// The bodies indexed.
    pub(super) members: Vec<Member>,
    /// Members in no cell (covering too many, or with inverted or NaN bounds): tested
    /// against everything.
    big: Vec<u32>,
    /// Whether each member is in `big`.
    is_big: Vec<bool>,
    /// Build buffer: each member in cells, with the cells it covers.
    ranges: Vec<(CellRange, u32)>,
}

impl HashGrid {
    /// Heap bytes held.
    pub(super) fn heap_bytes(&self) -> usize {
        self.starts.capacity() * 4
            + self.entries.capacity() * size_of::<(i32, i32, u32)>()
            + self.members.capacity() * size_of::<Member>()
            + self.big.capacity() * 4
            + self.is_big.capacity()
            + self.ranges.capacity() * size_of::<(CellRange, u32)>()
    }

    /// The entries of bucket `b`.
    fn bucket_entries(&self, b: usize) -> &[(i32, i32, u32)] {
        &self.entries[self.starts[b] as usize..self.starts[b + 1] as usize]
    }

    /// The entries of cell `c` (and, hashed, of the cells sharing its bucket).
    #[inline]
    fn cell_entries(&self, c: (i32, i32)) -> &[(i32, i32, u32)] {
        self.cells.bucket(c).map_or(&[], |b| self.bucket_entries(b))
    }

    /// Chooses the cell from `members` and indexes them.
    /// With `reorder` (static grids, built once), the members are first sorted by the row
    /// and column of their lower-left cell, so a cell's members sit together in memory.
    pub(super) fn build(&mut self, extents: &mut Vec<f64>, reorder: bool) {
        self.cells = Cells::sized_for(self.members.iter().map(|m| &m.bounds), extents);
        if reorder {
            let cells = self.cells;
            self.members.sort_by_cached_key(|m| {
                let b = &m.bounds;
                (cells.coord(b.min.y), cells.coord(b.min.x), m.handle)
            });
        }
        self.big.clear();
        self.is_big.clear();
        self.is_big.resize(self.members.len(), false);
        let mut ranges = std::mem::take(&mut self.ranges);
        ranges.clear();
        for (i, m) in self.members.iter().enumerate() {
            match self.cells.placed(&m.bounds) {
                Some(r) => ranges.push((r, i as u32)),
                None => {
                    self.is_big[i] = true;
                    self.big.push(i as u32);
                }
            }
        }
        let entry = |(cx, cy), i| (cx, cy, i);
        self.cells.fill(
            &ranges,
            (0, 0, 0),
            entry,
            &mut self.starts,
            &mut self.entries,
        );
        self.ranges = ranges;
    }

    /// Calls `f` once on every member overlapping `q`. Returns the body tests.
    pub(super) fn query(&self, q: &Bounds, mut f: impl FnMut(&Member)) -> u64 {
        let mut tested = 0;
        let range = self
            .cells
            .range(q)
            .map(|r| self.cells.clip(r))
            .filter(|r| r.count() <= (self.members.len() as u64).max(MAX_CELLS));
        let Some(range) = range else {
            // Too big (or irregular) to look up cell by cell: test everything.
            for m in &self.members {
                tested += 1;
                if m.bounds.overlaps(q) {
                    f(m);
                }
            }
            return tested;
        };
        if self.members.len() > self.big.len() {
            for c in range.cells() {
                for &(cx, cy, i) in self.cell_entries(c) {
                    if (cx, cy) != c {
                        continue;
                    }
                    let m = &self.members[i as usize];
                    tested += 1;
                    if m.bounds.overlaps(q) && self.cells.owns(q, &m.bounds, c) {
                        f(m);
                    }
                }
            }
        }
        for &i in &self.big {
            let m = &self.members[i as usize];
            tested += 1;
            if m.bounds.overlaps(q) {
                f(m);
            }
        }
        tested
    }

    /// Every overlapping pair of members with a dynamic body. Returns the body tests.
    pub(super) fn self_pairs(&self, out: &mut Vec<(u32, u32)>) -> u64 {
        let mut tested = 0;
        for b in 0..self.starts.len() - 1 {
            let es = self.bucket_entries(b);
            for (k, &(cx, cy, i)) in es.iter().enumerate() {
                let p = &self.members[i as usize];
                for &(dx, dy, j) in &es[k + 1..] {
                    let q = &self.members[j as usize];
                    if (dx, dy) != (cx, cy) || !(p.dynamic || q.dynamic) {
                        continue;
                    }
                    tested += 1;
                    if p.bounds.overlaps(&q.bounds)
                        && self.cells.owns(&p.bounds, &q.bounds, (cx, cy))
                    {
                        out.push((p.handle, q.handle));
                    }
                }
            }
        }
        for &o in &self.big {
            let p = &self.members[o as usize];
            for (i, q) in self.members.iter().enumerate() {
                if i as u32 == o || (self.is_big[i] && (i as u32) < o) {
                    continue;
                }
                if p.dynamic || q.dynamic {
                    tested += 1;
                    if p.bounds.overlaps(&q.bounds) {
                        out.push((p.handle, q.handle));
                    }
                }
            }
        }
        tested
    }
}
