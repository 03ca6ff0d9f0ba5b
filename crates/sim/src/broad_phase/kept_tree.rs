//! `Tree` for moving bodies: one layer's [`DynamicTree`] of fat boxes, kept from one call to
//! the next. A body's leaf holds its bounds grown by [`MARGIN`] of its size; each call, a
//! body still inside its fat box costs one containment test and nothing else (its exact
//! bounds are stored apart, for the pair tests). A body that left it gets a new fat box in
//! place, its ancestors' boxes grown to hold it, as Box2D v3 does (removing and reinserting
//! it instead made `Tree` on asteroids-10000 three times slower than sort and sweep, in the
//! study of BENCHMARKS.md); once as many leaves were enlarged as the layer has, the tree is
//! rebuilt top-down. Bodies gone are removed and new ones inserted by the heuristic, in key
//! order; when more than half the leaves are new in one call (the first call), the tree is
//! built anew top-down instead.
//!
//! The pairs found are a function of the bodies' exact bounds only: the fat boxes decide
//! which leaves are visited, never which pairs come out.

use ricochet_geom::{Bounds, Vec2};

use super::dynamic_tree::{DynamicTree, NONE};
use super::{BodyEntry, Member, member};

/// A fat box is the body's bounds grown on every side by this fraction of its larger side.
/// Box2D grows by a fixed 0.1 m; a fraction suits scenes of any scale. A quarter lets a body
/// travel a quarter of its size before its leaf moves, and makes a leaf 2.25 times the area
/// of a square body's box.
pub(super) const MARGIN: f64 = 0.25;

/// One layer's moving bodies in a [`DynamicTree`], kept across calls.
#[derive(Debug, Default, Clone)]
pub(super) struct KeptTree {
    /// The call the tree was last brought up to.
    pub(super) frame: u64,
    pub(super) tree: DynamicTree,
    /// The layer's keys at the last update, in key order (`local` indexes it).
    keys: Vec<u64>,
    /// Each body's leaf.
    leaves: Vec<u32>,
    /// This call's bodies, by `local` (the leaves' items).
    pub(super) members: Vec<Member>,
    /// Buffers: bodies whose leaf must move, and the old-to-new index of the merge.
    moved: Vec<u32>,
    remap: Vec<u32>,
    /// Leaves enlarged in place since the last rebuild.
    enlarged: usize,
}

/// `b` grown by [`MARGIN`] of its larger side (a box with a side that is NaN, infinite or
/// negative is not grown: it is reinserted whenever it changes, which is rare and exact).
fn fat(b: &Bounds) -> Bounds {
    let m = MARGIN * (b.max.x - b.min.x).max(b.max.y - b.min.y);
    let m = if m.is_finite() && m > 0.0 { m } else { 0.0 };
    Bounds {
        min: b.min - Vec2::splat(m),
        max: b.max + Vec2::splat(m),
    }
}

/// Whether `fat` holds `b` (false with a NaN coordinate).
#[inline]
fn holds(fat: &Bounds, b: &Bounds) -> bool {
    fat.min.x <= b.min.x && fat.min.y <= b.min.y && b.max.x <= fat.max.x && b.max.y <= fat.max.y
}

impl KeptTree {
    /// Heap bytes held.
    pub(super) fn heap_bytes(&self) -> usize {
        self.tree.heap_bytes()
            + self.keys.capacity() * 8
            + (self.leaves.capacity() + self.moved.capacity() + self.remap.capacity()) * 4
            + self.members.capacity() * size_of::<Member>()
    }

    /// Reconciles the tree with this call's bodies of the layer (`handles`, key order).
    /// Returns the leaves moved, inserted or removed.
    pub(super) fn update(&mut self, handles: &[u32], bodies: &[BodyEntry]) -> u64 {
        self.members.clear();
        self.members
            .extend(handles.iter().map(|&h| member(&bodies[h as usize], h)));
        let same = self.keys.len() == handles.len()
            && handles
                .iter()
                .zip(&self.keys)
                .all(|(&h, &k)| bodies[h as usize].key == k);
        if !same {
            return self.merge(handles, bodies);
        }
        self.moved.clear();
        for (local, m) in self.members.iter().enumerate() {
            if !holds(self.tree.fat(self.leaves[local]), &m.bounds) {
                self.moved.push(local as u32);
            }
        }
        for &local in &self.moved {
            let leaf = self.leaves[local as usize];
            self.tree
                .enlarge(leaf, fat(&self.members[local as usize].bounds));
        }
        self.enlarged += self.moved.len();
        if self.enlarged > self.members.len() {
            // As many enlargements as leaves: the inner boxes are stale, build them anew.
            self.tree.rebuild();
            self.enlarged = 0;
        }
        self.moved.len() as u64
    }

    /// The slow path of [`KeptTree::update`]: bodies came or went.
    fn merge(&mut self, handles: &[u32], bodies: &[BodyEntry]) -> u64 {
        // Old local -> new local (or NONE: gone), by merging the two key orders.
        self.remap.clear();
        self.remap.resize(self.keys.len(), NONE);
        let mut leaves = vec![NONE; handles.len()];
        let mut i = 0;
        for (j, &h) in handles.iter().enumerate() {
            let key = bodies[h as usize].key;
            while i < self.keys.len() && self.keys[i] < key {
                i += 1;
            }
            if i < self.keys.len() && self.keys[i] == key {
                self.remap[i] = j as u32;
                leaves[j] = self.leaves[i];
                i += 1;
            }
        }
        let mut changed = 0;
        for (old, &j) in self.remap.iter().enumerate() {
            if j == NONE {
                self.tree.remove(self.leaves[old]);
                changed += 1;
            }
        }
        let fresh = leaves.iter().filter(|&&l| l == NONE).count();
        let bulk = 2 * fresh > handles.len();
        for (j, m) in self.members.iter().enumerate() {
            let f = fat(&m.bounds);
            if leaves[j] == NONE {
                leaves[j] = if bulk {
                    self.tree.insert_later(f, j as u32)
                } else {
                    self.tree.insert(f, j as u32)
                };
                changed += 1;
                continue;
            }
            self.tree.set_item(leaves[j], j as u32);
            if !holds(self.tree.fat(leaves[j]), &m.bounds) {
                if bulk {
                    self.tree.relocate_later(leaves[j], f);
                } else {
                    self.tree.relocate(leaves[j], f);
                }
                changed += 1;
            }
        }
        if bulk {
            self.tree.rebuild();
            self.enlarged = 0;
        }
        self.leaves = leaves;
        self.keys.clear();
        self.keys
            .extend(handles.iter().map(|&h| bodies[h as usize].key));
        changed
    }

    /// Calls `f` on every body whose exact bounds overlap `q`. Returns the bodies tested.
    #[inline]
    pub(super) fn query(
        &self,
        q: &Bounds,
        stack: &mut Vec<u32>,
        f: impl FnMut(u32, &Member),
    ) -> u64 {
        query_exact(&self.tree, &self.members, q, stack, f)
    }

    /// Every overlapping pair of the layer's bodies with a dynamic one: each body queries
    /// the tree, and a pair is kept from the body earlier in key order. Returns the tests.
    pub(super) fn self_pairs(&self, stack: &mut Vec<u32>, out: &mut Vec<(u32, u32)>) -> u64 {
        let mut tested = 0;
        for (local, p) in self.members.iter().enumerate() {
            let local = local as u32;
            tested += self.tree.query(&p.bounds, stack, |other| {
                if other <= local {
                    return;
                }
                let q = &self.members[other as usize];
                if (p.dynamic || q.dynamic) && p.bounds.overlaps(&q.bounds) {
                    out.push((p.handle, q.handle));
                }
            });
        }
        tested
    }
}

/// `Tree` for static bodies: one layer's [`DynamicTree`] over their exact boxes, built once
/// top-down.
#[derive(Debug, Default, Clone)]
pub(super) struct StaticDynamicTree {
    tree: DynamicTree,
    members: Vec<Member>,
}

impl StaticDynamicTree {
    /// The tree over `members`.
    pub(super) fn new(members: Vec<Member>) -> StaticDynamicTree {
        let mut tree = DynamicTree::default();
        for (i, m) in members.iter().enumerate() {
            tree.insert_later(m.bounds, i as u32);
        }
        tree.rebuild();
        StaticDynamicTree { tree, members }
    }

    /// Heap bytes held.
    pub(super) fn heap_bytes(&self) -> usize {
        self.tree.heap_bytes() + self.members.capacity() * size_of::<Member>()
    }

    /// Calls `f` on every member overlapping `q`. Returns the members tested.
    #[inline]
    pub(super) fn query(
        &self,
        q: &Bounds,
        stack: &mut Vec<u32>,
        f: impl FnMut(u32, &Member),
    ) -> u64 {
        query_exact(&self.tree, &self.members, q, stack, f)
    }
}

/// Calls `f` on every member of `tree` (items index `members`) whose exact bounds overlap
/// `q`: the tree's boxes (fat or exact) only narrow the search. Returns the members tested.
#[inline]
fn query_exact(
    tree: &DynamicTree,
    members: &[Member],
    q: &Bounds,
    stack: &mut Vec<u32>,
    mut f: impl FnMut(u32, &Member),
) -> u64 {
    tree.query(q, stack, |i| {
        let m = &members[i as usize];
        if m.bounds.overlaps(q) {
            f(i, m);
        }
    })
}
