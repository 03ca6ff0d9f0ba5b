//! `Quadtree`'s structure: a **loose** quadtree of one layer's bodies, built in one pass
//! (every call for moving bodies, once for static ones).
//!
//! The root is the square around every body; a node splits into four quadrants. A body goes
//! down into the quadrant holding its *centre* as long as its larger side is at most the
//! quadrant's side, so each body sits in exactly one node, and no deeper than its size
//! allows. The quadrants are loose: a body in one may stick out of it by up to half its
//! side. Why loose: in a strict quadtree a body stays in the smallest node that contains it
//! *entirely*, so every small body lying across a split line (a tenth of them at every
//! level for bodies a tenth of a cell wide, and every body on the root's centre lines)
//! sits high up and is tested against everything below; loose quadrants send it down by its
//! centre instead, and a huge body stays near the root where it belongs (the mixed sizes
//! that break a uniform grid). A node splits when it holds more than [`LEAF`] bodies, down
//! to [`MAX_DEPTH`] levels.
//!
//! Queries do not use the loose squares: every node keeps the exact hull of the bodies in
//! its subtree, so a query visits a node only when its hull overlaps, and the pairs found
//! never depend on where a body was placed. Bodies with a coordinate that is not finite, or
//! inverted bounds, go into no node and are tested against every query.
//!
//! # Determinism
//! The nodes are an array built depth first; a node's bodies are a run of one array, put in
//! place by a stable sort on the quadrant, so every order is a function of the members'
//! order (key order) and bounds.

use ricochet_geom::{Bounds, Vec2};

use super::Member;
use super::dynamic_tree::hull;

/// A node with more bodies than this splits.
const LEAF: usize = 8;
/// Levels below the root at most (a crowd on one point stops here).
const MAX_DEPTH: u32 = 24;
/// No child.
const NONE: u32 = u32::MAX;

/// A node: its bodies are `order[start..start + own]`; its four children, if any, are
/// `nodes[children..children + 4]`.
#[derive(Clone, Copy, Debug)]
struct Node {
    /// The hull of every body in the subtree (empty: `+inf..-inf`, overlapping nothing).
    hull: Bounds,
    start: u32,
    own: u32,
    children: u32,
}

/// A loose quadtree over `members`.
#[derive(Debug, Default, Clone)]
pub(super) struct Quadtree {
    /// The call the tree was last built for (moving bodies).
    pub(super) frame: u64,
    /// The bodies indexed.
    pub(super) members: Vec<Member>,
    nodes: Vec<Node>,
    /// Member indices, each node's a run.
    order: Vec<u32>,
    /// Members in no node: tested against everything.
    big: Vec<u32>,
    /// Build buffer.
    quadrant: Vec<u8>,
}

/// The empty hull.
const EMPTY: Bounds = Bounds {
    min: Vec2::splat(f64::INFINITY),
    max: Vec2::splat(f64::NEG_INFINITY),
};

/// Whether `b` can be placed: finite and not inverted.
fn placeable(b: &Bounds) -> bool {
    [b.min.x, b.min.y, b.max.x, b.max.y]
        .iter()
        .all(|v| v.is_finite())
        && b.min.x <= b.max.x
        && b.min.y <= b.max.y
}

impl Quadtree {
    /// Heap bytes held.
    pub(super) fn heap_bytes(&self) -> usize {
        self.members.capacity() * size_of::<Member>()
            + self.nodes.capacity() * size_of::<Node>()
            + (self.order.capacity() + self.big.capacity()) * 4
            + self.quadrant.capacity()
    }

    /// Indexes `members`.
    pub(super) fn build(&mut self) {
        self.nodes.clear();
        self.order.clear();
        self.big.clear();
        let mut root = EMPTY;
        for (i, m) in self.members.iter().enumerate() {
            if placeable(&m.bounds) {
                self.order.push(i as u32);
                root = hull(&root, &m.bounds);
            } else {
                self.big.push(i as u32);
            }
        }
        if self.order.is_empty() {
            return;
        }
        let half = 0.5 * (root.max.x - root.min.x).max(root.max.y - root.min.y);
        let centre = Vec2::new(
            0.5 * root.min.x + 0.5 * root.max.x,
            0.5 * root.min.y + 0.5 * root.max.y,
        );
        self.quadrant.resize(self.members.len(), 0);
        self.nodes.push(Node {
            hull: EMPTY,
            start: 0,
            own: 0,
            children: NONE,
        });
        let n = self.order.len();
        self.split(0, (0, n), centre, half, 0);
    }

    /// Fills node `node` with `order[start..end]`, centred on `centre`, `half` its half
    /// side, at `depth`.
    fn split(
        &mut self,
        node: usize,
        (start, end): (usize, usize),
        centre: Vec2,
        half: f64,
        depth: u32,
    ) {
        let mut h = EMPTY;
        for &i in &self.order[start..end] {
            h = hull(&h, &self.members[i as usize].bounds);
        }
        self.nodes[node].hull = h;
        self.nodes[node].start = start as u32;
        // Quadrant sides are `half`: a body fits one when its larger side is at most that.
        if end - start <= LEAF || depth == MAX_DEPTH || half <= 0.0 || !half.is_finite() {
            self.nodes[node].own = (end - start) as u32;
            return;
        }
        for &i in &self.order[start..end] {
            let b = &self.members[i as usize].bounds;
            let side = (b.max.x - b.min.x).max(b.max.y - b.min.y);
            self.quadrant[i as usize] = if side > half {
                0
            } else {
                let c = b.center();
                1 + u8::from(c.x >= centre.x) + 2 * u8::from(c.y >= centre.y)
            };
        }
        let quadrant = &self.quadrant;
        self.order[start..end].sort_by_key(|&i| quadrant[i as usize]);
        let run =
            |q: u8| start + self.order[start..end].partition_point(|&i| quadrant[i as usize] < q);
        let bounds: [usize; 5] = [run(1), run(2), run(3), run(4), end];
        self.nodes[node].own = (bounds[0] - start) as u32;
        if bounds[0] == end {
            return;
        }
        let children = self.nodes.len();
        self.nodes[node].children = children as u32;
        self.nodes.extend(
            [Node {
                hull: EMPTY,
                start: 0,
                own: 0,
                children: NONE,
            }; 4],
        );
        let q = 0.5 * half;
        for k in 0..4 {
            let c = Vec2::new(
                centre.x + if k & 1 == 1 { q } else { -q },
                centre.y + if k & 2 == 2 { q } else { -q },
            );
            self.split(children + k, (bounds[k], bounds[k + 1]), c, q, depth + 1);
        }
    }

    /// Calls `f(index, member)` on every member overlapping `q`. Returns the body tests.
    #[inline]
    pub(super) fn query(
        &self,
        q: &Bounds,
        stack: &mut Vec<u32>,
        mut f: impl FnMut(u32, &Member),
    ) -> u64 {
        let mut tested = 0;
        stack.clear();
        if !self.nodes.is_empty() {
            stack.push(0);
        }
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n as usize];
            if !node.hull.overlaps(q) {
                continue;
            }
            let own = node.start as usize..(node.start + node.own) as usize;
            for &i in &self.order[own] {
                let m = &self.members[i as usize];
                tested += 1;
                if m.bounds.overlaps(q) {
                    f(i, m);
                }
            }
            if node.children != NONE {
                stack.extend((0..4).rev().map(|k| node.children + k));
            }
        }
        for &i in &self.big {
            let m = &self.members[i as usize];
            tested += 1;
            if m.bounds.overlaps(q) {
                f(i, m);
            }
        }
        tested
    }

    /// Every overlapping pair of members with a dynamic body: each member queries the
    /// tree, and a pair is kept from the member earlier in the order. Returns the tests.
    pub(super) fn self_pairs(&self, stack: &mut Vec<u32>, out: &mut Vec<(u32, u32)>) -> u64 {
        let mut tested = 0;
        for (i, p) in self.members.iter().enumerate() {
            let i = i as u32;
            tested += self.query(&p.bounds, stack, |j, q| {
                if j > i && (p.dynamic || q.dynamic) {
                    out.push((p.handle, q.handle));
                }
            });
        }
        tested
    }
}
