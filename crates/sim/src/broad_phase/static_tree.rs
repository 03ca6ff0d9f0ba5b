//! `SortAndSweep`'s static structure: a packed tree per layer (sort-tile-recursive: sorted
//! once by x into slices, each slice by y, leaves of 8, a binary tree of boxes above), which
//! each dynamic body queries in `O(log n + k)`. The scene queries (`query/`) build the same
//! trees over every layer's bodies and walk them along a ray ([`StaticTree::ray`]).

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

impl StaticTree {
    /// Calls `f` on every member whose bounds the segment `origin + t * dir`, `t` in
    /// `[0, max]`, may cross (a slab test, touching counts). `f` returns the new `max`: a
    /// first-hit search shrinks it, so boxes beyond the best hit so far are skipped. Nearer
    /// boxes are walked first (of two children, the one the segment enters first), so the
    /// first hit is found early and prunes the rest.
    pub(crate) fn ray(
        &self,
        origin: Vec2,
        dir: Vec2,
        mut max: f64,
        f: &mut impl FnMut(&Member, f64) -> f64,
    ) {
        if self.items.is_empty() {
            return;
        }
        let inv = Vec2::new(1.0 / dir.x, 1.0 / dir.y);
        let top = self.levels.len() - 1;
        // One rounding margin for the whole walk: the root's, which is at least any box's.
        let root = &self.levels[top][0];
        let pad = root.max.abs().max(root.min.abs()).max(origin.abs()) * 1e-12;
        // (level, index, entry distance). A walk that pushes two children per node holds at
        // most one pending sibling per level, and a tree over 2^32 members has < 32 levels.
        let mut stack = [(0u32, 0u32, 0.0f64); 64];
        let Some(t) = enter(root, origin, inv, max, pad) else {
            return;
        };
        stack[0] = (top as u32, 0, t);
        let mut len = 1;
        while len > 0 {
            len -= 1;
            let (level, i, t) = stack[len];
            if t > max {
                continue;
            }
            let (level, i) = (level as usize, i as usize);
            if level == 0 {
                let end = (i * LEAF + LEAF).min(self.items.len());
                for m in &self.items[i * LEAF..end] {
                    if enter(&m.bounds, origin, inv, max, pad).is_some() {
                        max = f(m, max);
                    }
                }
                continue;
            }
            let below = &self.levels[level - 1];
            let mut near = [None, None];
            for (k, c) in [2 * i, 2 * i + 1].into_iter().enumerate() {
                if let Some(b) = below.get(c) {
                    near[k] = enter(b, origin, inv, max, pad).map(|t| (c, t));
                }
            }
            // The farther child first onto the stack, so the nearer is walked first.
            if let [Some(a), Some(b)] = near
                && b.1 < a.1
            {
                near = [Some(b), Some(a)];
            }
            for (c, t) in near.into_iter().rev().flatten() {
                stack[len] = ((level - 1) as u32, c as u32, t);
                len += 1;
            }
        }
    }
}

/// Where the segment `o + t d`, `t` in `[0, max]` (`inv` = `1 / d` per axis), enters `b`
/// widened by `pad` per axis (touching counts), or `None` if it misses. The margin covers
/// rounding, so a segment that only grazes a box is never lost (the exact test follows).
#[inline]
fn enter(b: &Bounds, o: Vec2, inv: Vec2, max: f64, pad: Vec2) -> Option<f64> {
    let (lo, hi) = (b.min - pad, b.max + pad);
    let (mut enter, mut exit) = (0.0_f64, max);
    for axis in 0..2 {
        let (ok, ik) = (o[axis], inv[axis]);
        if ik.is_infinite() {
            // Parallel to this axis' faces: inside the slab or never.
            if ok < lo[axis] || ok > hi[axis] {
                return None;
            }
            continue;
        }
        let t1 = (lo[axis] - ok) * ik;
        let t2 = (hi[axis] - ok) * ik;
        let (near, far) = if t1 < t2 { (t1, t2) } else { (t2, t1) };
        enter = enter.max(near);
        exit = exit.min(far);
        if enter > exit {
            return None;
        }
    }
    Some(enter)
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
