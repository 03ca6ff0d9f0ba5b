//! The scene queries' tree: a packed tree over one set of bodies, four wide (rapier's `Bvh`
//! is too), built by median cuts, with its members stored in tree order so that a leaf's
//! boxes are contiguous and a member's position in the tree is its handle into the set's
//! columns (`index.rs`).
//!
//! Leaves of [`LEAF`] = 4 members (each member of a visited leaf costs a box test, and a
//! query's answer is a handful of bodies) and nodes of 4 children, each node's four boxes
//! stored by coordinate ([`Quad`]) and tested together with no branch per child; half the
//! levels of a binary tree, so fewer dependent loads. A box walk keeps, per level, a mask
//! of the children still to walk (no stack); a ray walk's stack is kept per thread (no
//! allocation and nothing zeroed a query), and its slab test (`slab.rs`) has the direction
//! inverted and the rounding margin taken once a walk.

use std::cell::RefCell;

use ricochet_geom::{Bounds, Vec2};

use super::slab::{Slab, larger};

/// Members per leaf, and children per node.
mod refit;

const LEAF: usize = 4;

/// A ray walk's node put off: its level, its index there, and where the segment enters it.
type Pending = (u32, u32, f64);

thread_local! {
    /// The ray walk's stack, one per thread: as an array on the thread's stack it was
    /// 1 KiB zeroed every walk (a `memset` call, two walks a ray where static bodies and
    /// moving ones are both met).
    static RAY_STACK: RefCell<[Pending; STACK]> = const { RefCell::new([(0, 0, 0.0); STACK]) };
}

/// Levels a tree has at most: a member's handle is a `u32`, so at most `2^30` leaves, 16
/// levels above them.
const LEVELS: usize = 17;

/// Entries a walk's stack holds: up to three pending siblings per level (a tree over 2^32
/// members has < 16 levels of four), plus the four children of the node being expanded.
const STACK: usize = 64;

/// Four boxes side by side, one array per coordinate, so that a walk tests a node's four
/// children in one pass with no branch per child. A missing child is the empty box
/// ([`Quad::EMPTY`]'s lanes), which nothing meets.
///
/// The coordinates are indexed ([`MIN_X`], [`MIN_Y`], [`MAX_X`], [`MAX_Y`]) so that a ray's
/// walk picks each axis' near face by an index set once a walk, not a branch per node.
#[derive(Clone, Copy, Debug)]
pub(super) struct Quad {
    pub(super) c: [[f64; 4]; 4],
}

/// [`Quad::c`]'s rows: min x, min y, max x, max y (a max row is its min row + 2).
pub(super) const MIN_X: usize = 0;
pub(super) const MIN_Y: usize = 1;
pub(super) const MAX_X: usize = 2;
pub(super) const MAX_Y: usize = 3;

impl Quad {
    /// Min at `+inf`, max at `-inf`: no box or segment meets it, and a hull ignores it.
    const EMPTY: Quad = Quad {
        c: [
            [f64::INFINITY; 4],
            [f64::INFINITY; 4],
            [f64::NEG_INFINITY; 4],
            [f64::NEG_INFINITY; 4],
        ],
    };

    /// Up to four boxes, the rest empty.
    fn of(boxes: &[Bounds]) -> Quad {
        let mut q = Quad::EMPTY;
        for (j, b) in boxes.iter().enumerate() {
            q.set_lane(j, b);
        }
        q
    }

    /// Sets lane `j` to `b` (what [`Quad::lane`] reads back).
    #[inline]
    pub(super) fn set_lane(&mut self, j: usize, b: &Bounds) {
        self.c[MIN_X][j] = b.min.x;
        self.c[MIN_Y][j] = b.min.y;
        self.c[MAX_X][j] = b.max.x;
        self.c[MAX_Y][j] = b.max.y;
    }

    /// The box around the four (ignoring empty and NaN lanes, as [`hull`]).
    fn hull(&self) -> Bounds {
        (1..4).fold(self.lane(0), |u, j| hull(u, self.lane(j)))
    }

    pub(super) fn lane(&self, j: usize) -> Bounds {
        Bounds {
            min: Vec2::new(self.c[MIN_X][j], self.c[MIN_Y][j]),
            max: Vec2::new(self.c[MAX_X][j], self.c[MAX_Y][j]),
        }
    }

    /// Bit `j` set when lane `j` overlaps `q` (touching counts), as [`meets`].
    #[inline]
    fn meets(&self, q: &Bounds) -> u32 {
        let [min_x, min_y, max_x, max_y] = &self.c;
        let mut mask = 0;
        for j in 0..4 {
            let m = (min_x[j] <= q.max.x)
                & (q.min.x <= max_x[j])
                & (min_y[j] <= q.max.y)
                & (q.min.y <= max_y[j]);
            mask |= u32::from(m) << j;
        }
        mask
    }

    /// [`Quad::meets`] for a finite `q`, as differences: `a <= b` is `a - b <= 0` (a
    /// difference is zero only between equal numbers, and keeps its sign when it overflows;
    /// `+inf - q` of an empty lane is `+inf`), and the largest of four differences is
    /// positive when any is. Written so, the four lanes compile to two-wide subtractions and
    /// maxima (about 30 instructions against 60 for the comparisons one by one). No lane is
    /// NaN: [`QueryTree::new`] stores a box with a NaN coordinate as the empty box.
    #[inline]
    fn meets_finite(&self, q: &Bounds) -> u32 {
        let [min_x, min_y, max_x, max_y] = &self.c;
        let mut mask = 0;
        for j in 0..4 {
            let below = larger(min_x[j] - q.max.x, min_y[j] - q.max.y);
            let above = larger(q.min.x - max_x[j], q.min.y - max_y[j]);
            mask |= u32::from(larger(below, above) <= 0.0) << j;
        }
        mask
    }
}

/// A packed tree over boxes, its members in tree order.
#[derive(Debug, Default)]
pub(crate) struct QueryTree {
    /// Every level's nodes, one level after another (one allocation: a node is one load
    /// from here, not two): node `k` of level `j` is `quads[start[j] + k]`. Level 0's node
    /// `k` holds the boxes of members `4k .. 4k + 4` (in tree order); level `j + 1`'s node
    /// `k` holds the boxes around level `j`'s nodes `4k .. 4k + 4`.
    /// The last level is one node, the root.
    quads: Vec<Quad>,
    /// Where each level starts in `quads`.
    start: [usize; LEVELS],
    /// The root's level (the last).
    top: usize,
    /// The box around every member.
    all: Option<Bounds>,
}

impl QueryTree {
    /// The tree over `boxes`, and the order it keeps them in: `order[k]` is the index in
    /// `boxes` of the tree's member `k`. Ties broken by index, so the tree is a pure
    /// function of the boxes.
    ///
    /// Built top down by median cuts (`split`), not sort-tile-recursive: the implicit
    /// layout groups leaves `4k .. 4k + 4` at every level, and over STR's slices that groups
    /// the end of one slice with the start of the next, boxes as tall as the world that a
    /// query then walks into. A median cut along the longer side at every binary level
    /// keeps each node's box compact; a node of four is two such levels.
    pub(crate) fn new(boxes: &[Bounds]) -> (QueryTree, Vec<u32>) {
        let mut order: Vec<u32> = (0..boxes.len() as u32).collect();
        if boxes.is_empty() {
            return (QueryTree::default(), order);
        }
        let centers: Vec<Vec2> = boxes.iter().map(Bounds::center).collect();
        let leaves = boxes.len().div_ceil(LEAF);
        split(
            &mut order,
            &centers,
            LEAF << leaves.next_power_of_two().trailing_zeros(),
        );
        let sorted: Vec<Bounds> = order.iter().map(|&k| stored(boxes[k as usize])).collect();
        let mut levels = vec![sorted.chunks(LEAF).map(Quad::of).collect::<Vec<Quad>>()];
        while levels[levels.len() - 1].len() > 1 {
            let hulls: Vec<Bounds> = levels[levels.len() - 1].iter().map(Quad::hull).collect();
            levels.push(hulls.chunks(LEAF).map(Quad::of).collect());
        }
        let all = levels[levels.len() - 1][0].hull();
        let top = levels.len() - 1;
        let mut start = [0; LEVELS];
        let mut quads = Vec::with_capacity(levels.iter().map(Vec::len).sum());
        for (j, level) in levels.iter().enumerate() {
            start[j] = quads.len();
            quads.extend_from_slice(level);
        }
        (
            QueryTree {
                quads,
                start,
                top,
                all: Some(all),
            },
            order,
        )
    }

    /// The boxes of the tree's first `n` members, by handle, as stored (a box with a NaN
    /// coordinate stored empty).
    pub(crate) fn member_boxes(&self, n: usize) -> Vec<Bounds> {
        (0..n)
            .map(|k| self.quads[k / LEAF].lane(k % LEAF))
            .collect()
    }

    /// Node `i` of level `level`.
    #[inline(always)]
    fn node(&self, level: usize, i: usize) -> &Quad {
        &self.quads[self.start[level] + i]
    }

    /// Calls `f` with every member whose box overlaps `q` (touching counts).
    #[inline]
    pub(crate) fn query(&self, q: &Bounds, f: &mut impl FnMut(usize)) {
        let Some(all) = self.all else {
            return;
        };
        if !meets(&all, q) {
            return;
        }
        if q.min.is_finite() && q.max.is_finite() {
            self.walk(q, f, Quad::meets_finite);
        } else {
            self.walk(q, f, Quad::meets);
        }
    }

    /// [`QueryTree::query`]'s walk, depth first, lowest child first, with `meets` the box
    /// test of a node's four children. No stack of nodes: the children still to walk of
    /// the node being walked at each level are a mask, and a node's parent is its index
    /// divided by four.
    #[inline(always)]
    fn walk(&self, q: &Bounds, f: &mut impl FnMut(usize), meets: impl Fn(&Quad, &Bounds) -> u32) {
        let top = self.top;
        let mut pending = [0u32; LEVELS];
        let (mut level, mut i) = (top, 0);
        pending[top] = meets(self.node(top, 0), q);
        loop {
            let mask = pending[level];
            if mask == 0 {
                if level == top {
                    return;
                }
                (level, i) = (level + 1, i / LEAF);
                continue;
            }
            pending[level] = mask & (mask - 1);
            let c = i * LEAF + mask.trailing_zeros() as usize;
            if level == 0 {
                f(c);
            } else {
                (level, i) = (level - 1, c);
                pending[level] = meets(self.node(level, i), q);
            }
        }
    }

    /// Calls `f` on every member whose box the segment `origin + t * dir`, `t` in
    /// `[0, max]`, may cross (a slab test, touching counts). `f` returns the new `max`: a
    /// first-hit search shrinks it, so boxes beyond the best hit so far are skipped. Of a
    /// node's children, the ones the segment enters first are walked first, so the first
    /// hit is found early and prunes the rest.
    pub(crate) fn ray(
        &self,
        origin: Vec2,
        dir: Vec2,
        max: f64,
        f: &mut impl FnMut(usize, f64) -> f64,
    ) {
        let Some(all) = self.all else {
            return;
        };
        let slab = Slab::new(origin, dir, &all);
        if slab.enter(&all, max).is_none() {
            return;
        }
        RAY_STACK.with(|cell| match cell.try_borrow_mut() {
            Ok(mut stack) => self.ray_walk(&slab, max, f, &mut stack),
            // A walk from within a walk's `f` (none today): a stack of its own.
            Err(_) => self.ray_walk(&slab, max, f, &mut [(0, 0, 0.0); STACK]),
        });
    }

    /// [`QueryTree::ray`]'s walk from the root, `stack` its scratch.
    #[inline(always)]
    fn ray_walk(
        &self,
        slab: &Slab,
        mut max: f64,
        f: &mut impl FnMut(usize, f64) -> f64,
        stack: &mut [Pending; STACK],
    ) {
        let top = self.top;
        let mut len = 0;
        let (mut level, mut i) = (top, 0);
        loop {
            let (t, mut mask) = slab.enter4(self.node(level, i), max);
            if level == 0 {
                // The members met, nearest entry first (ties: the lower first), so that a
                // first hit prunes the farther ones of the leaf before their exact test.
                let mut near = [0usize; LEAF];
                let mut n = 0;
                while mask != 0 {
                    let j = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    let mut at = n;
                    while at > 0 && t[near[at - 1]] > t[j] {
                        near[at] = near[at - 1];
                        at -= 1;
                    }
                    near[at] = j;
                    n += 1;
                }
                for &j in &near[..n] {
                    // `max` may have shrunk since the four were tested.
                    if t[j] <= max {
                        max = f(i * LEAF + j, max);
                    }
                }
            } else {
                // Pushed farthest first, so the nearest is walked first (ties: the lower
                // child first).
                let below = (level - 1) as u32;
                let start = len;
                while mask != 0 {
                    let j = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    let e = (below, (i * LEAF + j) as u32, t[j]);
                    // Insertion among this node's entries, kept by distance, descending.
                    let mut at = len;
                    while at > start && stack[at - 1].2 <= e.2 {
                        stack[at] = stack[at - 1];
                        at -= 1;
                    }
                    stack[at] = e;
                    len += 1;
                }
            }
            // The next node put off that the segment, as shortened, still reaches.
            loop {
                if len == 0 {
                    return;
                }
                len -= 1;
                let (l, c, t) = stack[len];
                if t <= max {
                    (level, i) = (l as usize, c as usize);
                    break;
                }
            }
        }
    }
}

/// Orders `ids` (the members of a node holding up to `cap`, a power of two times [`LEAF`])
/// so that the node's left child, holding `cap / 2`, gets those with the smallest centres
/// along the longer side of their spread (ties by index), and recurses into both children.
fn split(ids: &mut [u32], centers: &[Vec2], cap: usize) {
    if ids.len() <= LEAF {
        return;
    }
    let half = cap / 2;
    if ids.len() <= half {
        // Only a left child at this level.
        split(ids, centers, half);
        return;
    }
    let c = |k: &u32| centers[*k as usize];
    let (lo, hi) = ids.iter().fold(
        (Vec2::splat(f64::INFINITY), Vec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), k| (lo.min(c(k)), hi.max(c(k))),
    );
    let axis = usize::from(hi.y - lo.y > hi.x - lo.x);
    ids.select_nth_unstable_by(half, |a, b| {
        c(a)[axis].total_cmp(&c(b)[axis]).then(a.cmp(b))
    });
    let (left, right) = ids.split_at_mut(half);
    split(left, centers, half);
    split(right, centers, half);
}

/// A member's box as the tree stores it: a box with a NaN coordinate (a member whose pose
/// is not a number) overlaps nothing and no ray hits its member, so it is stored empty, and
/// no lane is NaN.
#[inline]
fn stored(b: Bounds) -> Bounds {
    if [b.min.x, b.min.y, b.max.x, b.max.y]
        .iter()
        .any(|v| v.is_nan())
    {
        Quad::EMPTY.lane(0)
    } else {
        b
    }
}

/// Whether `a` and `b` overlap, touching counted ([`Bounds::overlaps`]), with one branch
/// for the caller instead of four.
#[inline]
fn meets(a: &Bounds, b: &Bounds) -> bool {
    (a.min.x <= b.max.x) & (b.min.x <= a.max.x) & (a.min.y <= b.max.y) & (b.min.y <= a.max.y)
}

/// The smallest box holding both, ignoring NaN coordinates (`f64::min` and `max` do; a NaN
/// box overlaps nothing, so nothing is lost).
fn hull(a: Bounds, b: Bounds) -> Bounds {
    Bounds {
        min: Vec2::new(a.min.x.min(b.min.x), a.min.y.min(b.min.y)),
        max: Vec2::new(a.max.x.max(b.max.x), a.max.y.max(b.max.y)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Boxes on a grid, with one far off: every query's members, against a scan of all.
    fn boxes() -> Vec<Bounds> {
        let mut out: Vec<Bounds> = (0..97)
            .map(|k| {
                let c = Vec2::new((k % 10) as f64 * 3.0, (k / 10) as f64 * 2.5);
                Bounds::around(c, Vec2::new(1.0 + (k % 3) as f64 * 0.4, 0.8))
            })
            .collect();
        out.push(Bounds::around(Vec2::splat(500.0), Vec2::ONE));
        out
    }

    #[test]
    fn a_box_query_finds_every_overlapping_member_once() {
        let boxes = boxes();
        let (tree, order) = QueryTree::new(&boxes);
        for q in [
            Bounds::around(Vec2::new(7.0, 6.0), Vec2::new(2.0, 1.0)),
            Bounds::around(Vec2::new(-50.0, 0.0), Vec2::ONE),
            Bounds::around(Vec2::splat(500.0), Vec2::splat(0.5)),
            Bounds::around(Vec2::new(15.0, 12.0), Vec2::splat(40.0)),
            // Touching member 0 (x in [-1, 1]) along its right face only: it counts.
            Bounds {
                min: Vec2::new(1.0, -0.5),
                max: Vec2::new(1.5, 0.5),
            },
        ] {
            let mut got = Vec::new();
            tree.query(&q, &mut |k| got.push(order[k]));
            got.sort_unstable();
            let want: Vec<u32> = (0..boxes.len() as u32)
                .filter(|&k| boxes[k as usize].overlaps(&q))
                .collect();
            assert_eq!(got, want, "{q:?}");
        }
    }

    #[test]
    fn the_box_test_by_differences_agrees_with_the_comparisons() {
        // Lanes touching the query on each face, overlapping, apart by an ulp, empty,
        // huge and tiny, against queries on and off the lattice.
        let v = [
            -1e300,
            -3.0,
            -1.0,
            -0.0,
            0.0,
            1e-300,
            0.5,
            1.0,
            1.0 + f64::EPSILON,
            3.0,
        ];
        let mut lanes = Vec::new();
        for &a in &v {
            for &b in &v {
                if a <= b {
                    lanes.push((a, b));
                }
            }
        }
        let mut quads = Vec::new();
        for (k, &(x0, x1)) in lanes.iter().enumerate() {
            let (y0, y1) = lanes[(k * 7) % lanes.len()];
            let b = Bounds {
                min: Vec2::new(x0, y0),
                max: Vec2::new(x1, y1),
            };
            let c = Bounds {
                min: Vec2::new(y0, x0),
                max: Vec2::new(y1, x1),
            };
            quads.push(Quad::of(&[b, c, b.translated(Vec2::splat(0.5))]));
        }
        let mut met = 0;
        for &(qx0, qx1) in &lanes {
            for &(qy0, qy1) in lanes.iter().step_by(3) {
                let q = Bounds {
                    min: Vec2::new(qx0, qy0),
                    max: Vec2::new(qx1, qy1),
                };
                for quad in &quads {
                    let m = quad.meets(&q);
                    assert_eq!(quad.meets_finite(&q), m, "{quad:?} {q:?}");
                    met += m.count_ones();
                }
            }
        }
        assert!(met > 1000, "{met}");
    }

    #[test]
    fn a_member_box_with_a_nan_is_stored_empty_and_met_by_nothing() {
        let mut boxes = boxes();
        boxes[3].max.x = f64::NAN;
        let (tree, order) = QueryTree::new(&boxes);
        // Over every member but the far one; member 3's box, but for its NaN, is in it.
        let q = Bounds::around(Vec2::splat(10.0), Vec2::splat(100.0));
        let mut got = Vec::new();
        tree.query(&q, &mut |k| got.push(order[k]));
        got.sort_unstable();
        let want: Vec<u32> = (0..boxes.len() as u32)
            .filter(|&k| k != 3 && boxes[k as usize].overlaps(&q))
            .collect();
        assert_eq!(got, want);
    }

    #[test]
    fn a_ray_that_only_touches_a_corner_meets_that_box() {
        let boxes = boxes();
        let (tree, order) = QueryTree::new(&boxes);
        // The line x + y = 1.8 touches member 0 (x in [-1, 1], y in [-0.8, 0.8]) at its
        // corner (1, 0.8) only.
        let (o, d) = (Vec2::new(0.0, 1.8), Vec2::new(1.0, -1.0).normalize());
        let mut got = Vec::new();
        tree.ray(o, d, 10.0, &mut |k, max| {
            got.push(order[k]);
            max
        });
        assert!(got.contains(&0), "{got:?}");
    }

    #[test]
    fn a_ray_meets_every_box_it_crosses_including_a_grazed_one() {
        let boxes = boxes();
        let (tree, order) = QueryTree::new(&boxes);
        // Along y = 0.8 exactly: the top faces of the first row, grazed; and diagonals.
        for (o, d) in [
            (Vec2::new(-5.0, 0.8), Vec2::X),
            (Vec2::new(-5.0, -5.0), Vec2::new(1.0, 1.0).normalize()),
            (Vec2::new(3.0, -10.0), Vec2::Y),
        ] {
            let mut got = Vec::new();
            tree.ray(o, d, 60.0, &mut |k, max| {
                got.push(order[k]);
                max
            });
            got.sort_unstable();
            let crosses = |b: &Bounds| {
                // Sampled densely: a box the segment crosses contains some sample, within
                // the samples' spacing.
                (0..=60_000).any(|s| {
                    let p = o + d * (s as f64 * 1e-3);
                    p.x >= b.min.x - 1e-9
                        && p.x <= b.max.x + 1e-9
                        && p.y >= b.min.y - 1e-9
                        && p.y <= b.max.y + 1e-9
                })
            };
            for k in 0..boxes.len() as u32 {
                if crosses(&boxes[k as usize]) {
                    assert!(got.contains(&k), "ray {o:?} {d:?} lost box {k}");
                }
            }
        }
    }
}
