//! `Tree`'s structure: a dynamic bounding-volume tree, the kind Box2D keeps its proxies in
//! (`dynamic_tree.c`; the algorithms below are the textbook ones, written anew).
//!
//! A binary tree whose leaves hold boxes (for moving bodies, *fat* boxes: the body's bounds
//! grown by a margin, see [`KeptTree`](super::kept_tree::KeptTree)) and whose inner nodes
//! hold the hull of their children. A leaf is inserted next to the sibling that the
//! surface-area heuristic (in 2D, the perimeter) finds cheapest: descend towards the child
//! whose hull grows least, and stop where making a new parent costs less than going on.
//! On the way back up every ancestor is refitted and, when one child is two levels taller
//! than the other, rotated (an AVL rotation), so the height stays `O(log n)` whatever the
//! insertion order. A leaf is removed by putting its sibling in its parent's place.
//! [`DynamicTree::rebuild`] builds the whole tree anew top-down (median split along the
//! longer axis of the leaves' centres), for a bulk load or when most leaves moved at once,
//! where `n` insertions would cost more and give a worse tree.
//!
//! # Determinism
//! Nodes live in one `Vec`, named by index; freed nodes go on a stack and are reused last
//! in, first out, so which index a node gets is a function of the operations before. Every
//! choice compares numbers (ties go to the second child) or, in the rebuild, centres with
//! the leaf's item as tie-break. The tree's shape depends on the order of the calls, never on
//! addresses or hashing, and the pairs it finds do not depend on its shape at all.

use ricochet_geom::{Bounds, Vec2};

/// No node.
pub(super) const NONE: u32 = u32::MAX;

/// A node: a leaf (`child1 == NONE`) or an inner node with two children.
#[derive(Clone, Copy, Debug)]
struct Node {
    /// A leaf's (fat) box; an inner node's hull of its children's boxes.
    bounds: Bounds,
    parent: u32,
    child1: u32,
    child2: u32,
    /// A leaf's item (the caller's id); unused in an inner node.
    item: u32,
    /// 0 for a leaf, else one more than the taller child.
    height: u32,
}

/// A dynamic bounding-volume tree of boxes, each leaf naming an item (a `u32` the caller
/// chooses).
#[derive(Debug, Clone)]
pub(super) struct DynamicTree {
    nodes: Vec<Node>,
    /// Freed nodes, reused last in, first out.
    free: Vec<u32>,
    root: u32,
    /// Leaves made by [`DynamicTree::insert_later`], for the next rebuild.
    pending: Vec<u32>,
    /// Buffers for [`DynamicTree::rebuild`].
    leaves: Vec<u32>,
    stack: Vec<u32>,
}

impl Default for DynamicTree {
    fn default() -> DynamicTree {
        DynamicTree {
            nodes: Vec::new(),
            free: Vec::new(),
            root: NONE,
            pending: Vec::new(),
            leaves: Vec::new(),
            stack: Vec::new(),
        }
    }
}

impl DynamicTree {
    /// Heap bytes held.
    pub(super) fn heap_bytes(&self) -> usize {
        self.nodes.capacity() * size_of::<Node>()
            + (self.free.capacity()
                + self.pending.capacity()
                + self.leaves.capacity()
                + self.stack.capacity())
                * 4
    }

    /// Leaf `leaf`'s box.
    #[inline]
    pub(super) fn fat(&self, leaf: u32) -> &Bounds {
        &self.nodes[leaf as usize].bounds
    }

    /// Renames leaf `leaf`'s item.
    pub(super) fn set_item(&mut self, leaf: u32, item: u32) {
        self.nodes[leaf as usize].item = item;
    }

    /// A new node, from the free stack if it has one.
    fn alloc(&mut self, node: Node) -> u32 {
        if let Some(i) = self.free.pop() {
            self.nodes[i as usize] = node;
            i
        } else {
            self.nodes.push(node);
            (self.nodes.len() - 1) as u32
        }
    }

    /// A leaf for `item` with box `bounds`, not yet in the tree.
    fn new_leaf(&mut self, bounds: Bounds, item: u32) -> u32 {
        self.alloc(Node {
            bounds,
            parent: NONE,
            child1: NONE,
            child2: NONE,
            item,
            height: 0,
        })
    }

    /// Inserts a leaf for `item` with box `bounds`; returns the leaf.
    pub(super) fn insert(&mut self, bounds: Bounds, item: u32) -> u32 {
        let leaf = self.new_leaf(bounds, item);
        self.attach(leaf);
        leaf
    }

    /// Removes leaf `leaf` (from [`DynamicTree::insert`]).
    pub(super) fn remove(&mut self, leaf: u32) {
        self.detach(leaf);
        self.free.push(leaf);
    }

    /// Gives leaf `leaf` the box `bounds` and puts it where the heuristic says.
    pub(super) fn relocate(&mut self, leaf: u32, bounds: Bounds) {
        self.detach(leaf);
        self.nodes[leaf as usize].bounds = bounds;
        self.attach(leaf);
    }

    /// A leaf for `item` with box `bounds`, left out of the tree until the next
    /// [`DynamicTree::rebuild`] (which must come before any query).
    pub(super) fn insert_later(&mut self, bounds: Bounds, item: u32) -> u32 {
        let leaf = self.new_leaf(bounds, item);
        self.pending.push(leaf);
        leaf
    }

    /// Gives leaf `leaf` the box `bounds`, leaving the inner nodes stale until the next
    /// [`DynamicTree::rebuild`] (which must come before any query or other change).
    pub(super) fn relocate_later(&mut self, leaf: u32, bounds: Bounds) {
        self.nodes[leaf as usize].bounds = bounds;
    }

    /// Gives leaf `leaf` the box `bounds`, growing its ancestors' boxes to hold it (up to the
    /// first that already does) and moving nothing: `O(depth)`, and the tree stays exact,
    /// only looser until the next [`DynamicTree::rebuild`] (Box2D v3 enlarges the same way).
    pub(super) fn enlarge(&mut self, leaf: u32, bounds: Bounds) {
        self.nodes[leaf as usize].bounds = bounds;
        let bits = |b: &Bounds| [b.min.x, b.min.y, b.max.x, b.max.y].map(f64::to_bits);
        let mut at = self.nodes[leaf as usize].parent;
        while at != NONE {
            let n = &mut self.nodes[at as usize];
            let grown = hull(&n.bounds, &bounds);
            if bits(&grown) == bits(&n.bounds) {
                break;
            }
            n.bounds = grown;
            at = n.parent;
        }
    }

    /// Puts a detached leaf next to the cheapest sibling.
    fn attach(&mut self, leaf: u32) {
        if self.root == NONE {
            self.root = leaf;
            self.nodes[leaf as usize].parent = NONE;
            return;
        }
        let b = self.nodes[leaf as usize].bounds;
        let mut at = self.root;
        loop {
            let n = self.nodes[at as usize];
            if n.child1 == NONE {
                break;
            }
            let combined = perimeter(&hull(&n.bounds, &b));
            // A new parent of `at` and the leaf here costs its perimeter (twice, as it is
            // counted once for the node and once more for the growth of every ancestor);
            // going down makes `at` grow by this much whatever comes below.
            let here = 2.0 * combined;
            let inherited = 2.0 * (combined - perimeter(&n.bounds));
            let below = |c: u32| {
                let cn = &self.nodes[c as usize];
                let grown = perimeter(&hull(&cn.bounds, &b));
                let growth = if cn.child1 == NONE {
                    grown
                } else {
                    grown - perimeter(&cn.bounds)
                };
                growth + inherited
            };
            let (c1, c2) = (below(n.child1), below(n.child2));
            if here < c1 && here < c2 {
                break;
            }
            at = if c1 < c2 { n.child1 } else { n.child2 };
        }
        let sibling = at;
        let old_parent = self.nodes[sibling as usize].parent;
        let s = self.nodes[sibling as usize];
        let parent = self.alloc(Node {
            bounds: hull(&s.bounds, &b),
            parent: old_parent,
            child1: sibling,
            child2: leaf,
            item: 0,
            height: s.height + 1,
        });
        self.nodes[sibling as usize].parent = parent;
        self.nodes[leaf as usize].parent = parent;
        if old_parent == NONE {
            self.root = parent;
        } else {
            self.replace_child(old_parent, sibling, parent);
        }
        self.fix_upwards(parent);
    }

    /// Takes a leaf out of the tree (its node stays allocated).
    fn detach(&mut self, leaf: u32) {
        if leaf == self.root {
            self.root = NONE;
            return;
        }
        let parent = self.nodes[leaf as usize].parent;
        let p = self.nodes[parent as usize];
        let sibling = if p.child1 == leaf { p.child2 } else { p.child1 };
        self.nodes[sibling as usize].parent = p.parent;
        if p.parent == NONE {
            self.root = sibling;
        } else {
            self.replace_child(p.parent, parent, sibling);
            self.fix_upwards(p.parent);
        }
        self.free.push(parent);
    }

    /// In `parent`, `old` becomes `new`.
    fn replace_child(&mut self, parent: u32, old: u32, new: u32) {
        let p = &mut self.nodes[parent as usize];
        if p.child1 == old {
            p.child1 = new;
        } else {
            p.child2 = new;
        }
    }

    /// Balances and refits `at` and every ancestor.
    fn fix_upwards(&mut self, mut at: u32) {
        while at != NONE {
            at = self.balance(at);
            self.refit(at);
            at = self.nodes[at as usize].parent;
        }
    }

    /// An inner node's box and height from its children's.
    fn refit(&mut self, at: u32) {
        let n = self.nodes[at as usize];
        let (a, b) = (
            &self.nodes[n.child1 as usize],
            &self.nodes[n.child2 as usize],
        );
        let (bounds, height) = (hull(&a.bounds, &b.bounds), 1 + a.height.max(b.height));
        let n = &mut self.nodes[at as usize];
        n.bounds = bounds;
        n.height = height;
    }

    /// If one child of `a` is two or more levels taller than the other, rotates it up into
    /// `a`'s place. Returns the node now in `a`'s place.
    fn balance(&mut self, a: u32) -> u32 {
        let n = self.nodes[a as usize];
        if n.child1 == NONE || n.height < 2 {
            return a;
        }
        let (h1, h2) = (self.height(n.child1), self.height(n.child2));
        if h2 > h1 + 1 {
            self.rotate_up(a, n.child2, n.child1)
        } else if h1 > h2 + 1 {
            self.rotate_up(a, n.child1, n.child2)
        } else {
            a
        }
    }

    fn height(&self, i: u32) -> u32 {
        self.nodes[i as usize].height
    }

    /// `up`, the taller child of `a` (`other` the shorter), takes `a`'s place; `a` keeps
    /// `other` and takes `up`'s shorter child, `up` keeps its taller one.
    fn rotate_up(&mut self, a: u32, up: u32, other: u32) -> u32 {
        let u = self.nodes[up as usize];
        let (keep, give) = if self.height(u.child1) > self.height(u.child2) {
            (u.child1, u.child2)
        } else {
            (u.child2, u.child1)
        };
        let grand = self.nodes[a as usize].parent;
        self.nodes[up as usize].parent = grand;
        if grand == NONE {
            self.root = up;
        } else {
            self.replace_child(grand, a, up);
        }
        {
            let un = &mut self.nodes[up as usize];
            un.child1 = a;
            un.child2 = keep;
        }
        {
            let an = &mut self.nodes[a as usize];
            an.parent = up;
            an.child1 = other;
            an.child2 = give;
        }
        self.nodes[give as usize].parent = a;
        self.refit(a);
        self.refit(up);
        up
    }

    /// Builds the tree anew over its leaves: the inner nodes are freed, then the leaves are
    /// split top-down at the median centre along the longer axis of their centres' hull.
    pub(super) fn rebuild(&mut self) {
        let mut leaves = std::mem::take(&mut self.leaves);
        leaves.clear();
        if self.root != NONE {
            // Walk the tree, freeing inner nodes (in walk order) and collecting leaves.
            let stack = &mut self.stack;
            stack.clear();
            stack.push(self.root);
            while let Some(i) = stack.pop() {
                let n = self.nodes[i as usize];
                if n.child1 == NONE {
                    leaves.push(i);
                } else {
                    self.free.push(i);
                    stack.push(n.child2);
                    stack.push(n.child1);
                }
            }
        }
        leaves.append(&mut self.pending);
        self.root = self.build(&mut leaves, NONE);
        self.leaves = leaves;
    }

    /// The subtree over `leaves`, below `parent`.
    fn build(&mut self, leaves: &mut [u32], parent: u32) -> u32 {
        match leaves {
            [] => return NONE,
            [leaf] => {
                self.nodes[*leaf as usize].parent = parent;
                return *leaf;
            }
            _ => {}
        }
        let nodes = &self.nodes;
        let center = |i: u32| centre(&nodes[i as usize].bounds);
        let (mut lo, mut hi) = (Vec2::splat(f64::INFINITY), Vec2::splat(f64::NEG_INFINITY));
        for &l in leaves.iter() {
            let c = center(l);
            lo = Vec2::new(lo.x.min(c.x), lo.y.min(c.y));
            hi = Vec2::new(hi.x.max(c.x), hi.y.max(c.y));
        }
        let axis = usize::from(hi.y - lo.y > hi.x - lo.x);
        let mid = leaves.len() / 2;
        leaves.select_nth_unstable_by(mid, |&a, &b| {
            let (ca, cb) = (center(a)[axis], center(b)[axis]);
            let (ia, ib) = (nodes[a as usize].item, nodes[b as usize].item);
            ca.total_cmp(&cb).then(ia.cmp(&ib))
        });
        let node = self.alloc(Node {
            bounds: Bounds {
                min: Vec2::ZERO,
                max: Vec2::ZERO,
            },
            parent,
            child1: NONE,
            child2: NONE,
            item: 0,
            height: 0,
        });
        let (left, right) = leaves.split_at_mut(mid);
        let c1 = self.build(left, node);
        let c2 = self.build(right, node);
        let n = &mut self.nodes[node as usize];
        n.child1 = c1;
        n.child2 = c2;
        self.refit(node);
        node
    }

    /// Calls `f` with the item of every leaf whose box overlaps `q` (touching counts).
    /// Returns the leaves visited.
    #[inline]
    pub(super) fn query(&self, q: &Bounds, stack: &mut Vec<u32>, mut f: impl FnMut(u32)) -> u64 {
        let mut visited = 0;
        if self.root == NONE {
            return 0;
        }
        stack.clear();
        stack.push(self.root);
        while let Some(i) = stack.pop() {
            let n = &self.nodes[i as usize];
            if !n.bounds.overlaps(q) {
                continue;
            }
            if n.child1 == NONE {
                visited += 1;
                f(n.item);
            } else {
                stack.push(n.child2);
                stack.push(n.child1);
            }
        }
        visited
    }

    /// Checks the links, heights and hulls (tests).
    #[cfg(test)]
    fn validate(&self) -> usize {
        if self.root == NONE {
            return 0;
        }
        assert_eq!(self.nodes[self.root as usize].parent, NONE);
        let mut leaves = 0;
        let mut stack = vec![self.root];
        while let Some(i) = stack.pop() {
            let n = self.nodes[i as usize];
            if n.child1 == NONE {
                assert_eq!(n.height, 0);
                leaves += 1;
                continue;
            }
            for c in [n.child1, n.child2] {
                assert_eq!(self.nodes[c as usize].parent, i);
                stack.push(c);
            }
            let (a, b) = (self.nodes[n.child1 as usize], self.nodes[n.child2 as usize]);
            assert_eq!(n.height, 1 + a.height.max(b.height));
            let h = hull(&a.bounds, &b.bounds);
            assert_eq!(format!("{:?}", n.bounds), format!("{h:?}"));
        }
        leaves
    }
}

/// The box's centre, with an unbounded or NaN coordinate as 0 (a position only the rebuild's
/// split uses; the hulls stay exact).
fn centre(b: &Bounds) -> Vec2 {
    let c = |lo: f64, hi: f64| {
        let m = 0.5 * lo + 0.5 * hi;
        if m.is_finite() { m } else { 0.0 }
    };
    Vec2::new(c(b.min.x, b.max.x), c(b.min.y, b.max.y))
}

/// Half the perimeter (the 2D surface-area heuristic's measure).
#[inline]
fn perimeter(b: &Bounds) -> f64 {
    (b.max.x - b.min.x) + (b.max.y - b.min.y)
}

/// The smallest box holding both (`f64::min` and `max` skip a NaN coordinate; a NaN box
/// overlaps nothing, so nothing is lost, and an inverted box overlapping a query makes any
/// box holding its `min` and `max` overlap it too).
#[inline]
pub(super) fn hull(a: &Bounds, b: &Bounds) -> Bounds {
    Bounds {
        min: Vec2::new(a.min.x.min(b.min.x), a.min.y.min(b.min.y)),
        max: Vec2::new(a.max.x.max(b.max.x), a.max.y.max(b.max.y)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn boxed(x: f64, y: f64, h: f64) -> Bounds {
        Bounds::around(Vec2::new(x, y), Vec2::new(h, h))
    }

    /// Inserts, moves, removes and rebuilds in a fixed pseudo-random order; after each step
    /// the tree is well formed, balanced, and a query finds exactly the overlapping items.
    #[test]
    fn stays_balanced_and_exact_through_inserts_moves_removals_and_rebuilds() {
        let mut tree = DynamicTree::default();
        let mut leaves: Vec<Option<(u32, Bounds)>> = Vec::new();
        let mut seed = 12345u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 33) as f64 / f64::from(1u32 << 31)
        };
        let mut stack = Vec::new();
        for step in 0..3000 {
            let r = next();
            let b = boxed(next() * 100.0, next() * 100.0, next() * 3.0);
            let live: Vec<usize> = (0..leaves.len()).filter(|&i| leaves[i].is_some()).collect();
            if r < 0.5 || live.is_empty() {
                let item = leaves.len() as u32;
                leaves.push(Some((tree.insert(b, item), b)));
            } else if r < 0.8 {
                let i = live[(next() * live.len() as f64) as usize];
                let (leaf, _) = leaves[i].unwrap();
                tree.relocate(leaf, b);
                leaves[i] = Some((leaf, b));
            } else {
                let i = live[(next() * live.len() as f64) as usize];
                tree.remove(leaves[i].unwrap().0);
                leaves[i] = None;
            }
            if step % 500 == 499 {
                tree.rebuild();
            }
            assert_eq!(tree.validate(), leaves.iter().flatten().count());
            let q = boxed(next() * 100.0, next() * 100.0, 10.0);
            let mut found = Vec::new();
            tree.query(&q, &mut stack, |i| found.push(i));
            found.sort_unstable();
            let expected: Vec<u32> = (0..leaves.len() as u32)
                .filter(|&i| leaves[i as usize].is_some_and(|(_, b)| b.overlaps(&q)))
                .collect();
            assert_eq!(found, expected);
        }
        let height = tree.nodes[tree.root as usize].height;
        let n = leaves.iter().flatten().count() as f64;
        assert!(
            f64::from(height) <= 2.0 * n.log2() + 2.0,
            "height {height} for {n} leaves"
        );
    }
}
