//! Keeping a [`QueryTree`] across frames (issue #37): its members' boxes set anew and its
//! nodes recomputed bottom up, the members' order and the tree's shape kept; and the cost a
//! refit tree is compared by against a fresh build (`index.rs` decides when to rebuild).

use ricochet_geom::Bounds;

use super::{LEAF, MAX_X, MAX_Y, MIN_X, MIN_Y, Quad, QueryTree, stored};

impl QueryTree {
    /// Sets member `k`'s box (by handle) to `b` for [`QueryTree::refit`]: until then the
    /// nodes above it are stale.
    #[inline]
    pub(crate) fn set_member(&mut self, k: usize, b: Bounds) {
        self.quads[k / LEAF].set_lane(k % LEAF, &stored(b));
    }

    /// Recomputes every node above the members from the members' boxes as they are now
    /// ([`QueryTree::set_member`]), keeping the members' order and the tree's shape: the
    /// same nodes [`QueryTree::new`] builds over the members in this order, bit for bit.
    /// Returns the tree's [`QueryTree::cost`].
    pub(crate) fn refit(&mut self) -> f64 {
        if self.quads.is_empty() {
            return 0.0;
        }
        for level in 1..=self.top {
            let (below, this) = (self.start[level - 1], self.start[level]);
            let end = if level < self.top {
                self.start[level + 1]
            } else {
                self.quads.len()
            };
            for n in 0..end - this {
                let first = below + n * LEAF;
                let last = (first + LEAF).min(this);
                let mut q = Quad::EMPTY;
                for (j, c) in (first..last).enumerate() {
                    q.set_lane(j, &self.quads[c].hull());
                }
                self.quads[this + n] = q;
            }
        }
        self.all = Some(self.quads[self.start[self.top]].hull());
        self.cost()
    }

    /// The summed half perimeter of every node's box above the members: how much a walk
    /// pays, the measure a refit tree is compared by against a fresh build (`index.rs`).
    /// Empty lanes count nothing.
    pub(crate) fn cost(&self) -> f64 {
        if self.top == 0 {
            return 0.0;
        }
        let mut sum = 0.0;
        for q in &self.quads[self.start[1]..] {
            for j in 0..LEAF {
                let w = q.c[MAX_X][j] - q.c[MIN_X][j];
                let h = q.c[MAX_Y][j] - q.c[MIN_Y][j];
                // Also false for an empty lane (`-inf`) and a NaN.
                if w >= 0.0 && h >= 0.0 {
                    sum += w + h;
                }
            }
        }
        sum
    }
}
