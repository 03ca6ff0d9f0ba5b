//! `SortAndSweep`'s static structure: a packed tree per layer (sort-tile-recursive: sorted
//! once by x into slices, each slice by y, leaves of 8, a binary tree of boxes above), which
//! each dynamic body queries in `O(log n + k)`. (The scene queries keep their own tree of
//! the same build, `query/tree.rs`.)

use ricochet_geom::{Bounds, Vec2};

use super::Member;

/// `SortAndSweep`'s static structure: a packed tree (sort-tile-recursive), built once.
#[derive(Debug, Default, Clone)]
pub(crate) struct StaticTree {
    /// Leaves of [`LEAF`] consecutive members.
    items: Vec<Member>,
    /// `levels[0][i]` bounds leaf `i`; `levels[k + 1][i]` bounds `levels[k][2i..2i + 2]`.
    levels: Vec<Vec<Bounds>>,
}

/// Members per leaf.
const LEAF: usize = 8;

impl StaticTree {
    /// The tree over `items`.
    pub(crate) fn new(mut items: Vec<Member>) -> StaticTree {
        if items.is_empty() {
            return StaticTree::default();
        }
        let center = |m: &Member| m.bounds.center();
        items.sort_unstable_by(|a, b| {
            center(a)
                .x
                .total_cmp(&center(b).x)
                .then(a.handle.cmp(&b.handle))
        });
        let leaves = items.len().div_ceil(LEAF);
        let slices = (leaves as f64).sqrt().ceil().max(1.0) as usize;
        let per_slice = leaves.div_ceil(slices) * LEAF;
        for slice in items.chunks_mut(per_slice) {
            slice.sort_unstable_by(|a, b| {
                center(a)
                    .y
                    .total_cmp(&center(b).y)
                    .then(a.handle.cmp(&b.handle))
            });
        }
        let leaves: Vec<Bounds> = items
            .chunks(LEAF)
            .map(|c| c[1..].iter().fold(c[0].bounds, |u, m| hull(u, m.bounds)))
            .collect();
        let mut levels = vec![leaves];
        while levels[levels.len() - 1].len() > 1 {
            let next = levels[levels.len() - 1]
                .chunks(2)
                .map(|c| c[1..].iter().fold(c[0], |u, b| hull(u, *b)))
                .collect();
            levels.push(next);
        }
        StaticTree { items, levels }
    }

    /// Calls `f` on every member overlapping `q`. Returns the body tests.
    pub(crate) fn query(
        &self,
        q: &Bounds,
        stack: &mut Vec<(u32, u32)>,
        f: &mut impl FnMut(&Member),
    ) -> u64 {
        if self.items.is_empty() {
            return 0;
        }
        let mut tested = 0;
        stack.clear();
        stack.push(((self.levels.len() - 1) as u32, 0));
        while let Some((level, i)) = stack.pop() {
            let (level, i) = (level as usize, i as usize);
            if !self.levels[level][i].overlaps(q) {
                continue;
            }
            if level == 0 {
                let end = (i * LEAF + LEAF).min(self.items.len());
                for m in &self.items[i * LEAF..end] {
                    tested += 1;
                    if m.bounds.overlaps(q) {
                        f(m);
                    }
                }
            } else {
                let below = self.levels[level - 1].len();
                for c in [2 * i + 1, 2 * i] {
                    if c < below {
                        stack.push(((level - 1) as u32, c as u32));
                    }
                }
            }
        }
        tested
    }

    /// The heap bytes the tree holds (capacities), for the broad-phase study.
    pub(crate) fn heap_bytes(&self) -> usize {
        self.items.capacity() * size_of::<Member>()
            + self.levels.capacity() * size_of::<Vec<Bounds>>()
            + self.levels.iter().map(|l| l.capacity()).sum::<usize>() * size_of::<Bounds>()
    }
}

/// The smallest box holding both, ignoring NaN coordinates (`f64::min` and `max` do; a NaN
/// box overlaps nothing, so nothing is lost). Inverted boxes are fine: a member overlapping
/// `q` makes every box holding its `min` and `max` overlap `q` too.
fn hull(a: Bounds, b: Bounds) -> Bounds {
    Bounds {
        min: Vec2::new(a.min.x.min(b.min.x), a.min.y.min(b.min.y)),
        max: Vec2::new(a.max.x.max(b.max.x), a.max.y.max(b.max.y)),
    }
}
