//! The order in which `detect` computes its pairs' contacts: grouped by the classes of their
//! two shapes (`interned::shape_class`: a circle, a box, a polygon of five vertices, ...).
//!
//! The narrow phase's code is one path per pairing, and loops over each shape's vertices.
//! Taken in the plan's order, the pairings come at random (rain: five kinds of shapes), and
//! the processor mispredicts the branch to the pairing's code and the loops' ends at nearly
//! every pair. Grouped, the same branches go the same way from one pair to the next.
//!
//! The pairs are grouped within each thread's chunk of the narrow phase's map
//! (`Workers::chunk`), not across the whole plan: grouped across it, one thread took the
//! cheap pairings (circles) and the other the costly ones (polygons), and rain-10000's
//! second thread gained nothing.
//!
//! The contacts are still used in the plan's order: each is a pure function of the two
//! shapes and the poses the pass starts from, so the order they are computed in changes no
//! bit of any result.

use crate::def::Response;
use crate::interned::SHAPE_CLASSES;
use crate::world::World;

/// Class pairs: a pair's group is `class(a) * CLASSES + class(b)`.
const CLASSES: usize = SHAPE_CLASSES as usize;
const _: () = assert!(CLASSES * CLASSES <= 256, "a group fits in a byte");

/// The plan's pairs grouped by class pair, and each pair's place in that order.
#[derive(Clone, Debug, Default)]
pub(crate) struct ByClass {
    /// Each pair's group, by place in the plan.
    groups: Vec<u8>,
    /// Places in the plan, group by group, in plan order within a group.
    order: Vec<u32>,
    /// Each pair's place in `order`, by place in the plan.
    rank: Vec<u32>,
}

impl ByClass {
    /// Groups `plan`'s pairs within each `chunk` of it (the last may be shorter), by a
    /// counting sort: stable, so a group keeps the plan's order.
    pub(crate) fn sort(&mut self, w: &World, plan: &[(usize, usize, Response)], chunk: usize) {
        self.groups.clear();
        // A byte a body, read by its shape id: not the shape.
        let (table, ids) = (w.shape_table(), w.looks());
        let class = |i: usize| usize::from(table.class(ids[i]));
        self.groups.extend(plan.iter().map(|&(i, j, _)| {
            // At most CLASSES * CLASSES - 1: a byte (checked above).
            (class(i) * CLASSES + class(j)) as u8
        }));
        self.order.resize(plan.len(), 0);
        self.rank.resize(plan.len(), 0);
        let mut first = 0;
        for groups in self.groups.chunks(chunk.max(1)) {
            // Where each group starts in the order, then where its next pair goes.
            let mut start = [first as u32; CLASSES * CLASSES + 1];
            for &g in groups {
                start[usize::from(g) + 1] += 1;
            }
            for g in 1..start.len() {
                start[g] += start[g - 1] - first as u32;
            }
            for (k, &g) in (first..).zip(groups) {
                let at = &mut start[usize::from(g)];
                self.order[*at as usize] = k as u32;
                self.rank[k] = *at;
                *at += 1;
            }
            first += groups.len();
        }
    }

    /// The plan's places in the grouped order.
    pub(crate) fn order(&self) -> &[u32] {
        &self.order
    }

    /// Where the pair at place `k` of the plan is in the grouped order.
    #[inline]
    pub(crate) fn rank(&self, k: usize) -> usize {
        self.rank[k] as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use proptest::prelude::*;
    use ricochet_geom::{Shape, Vec2};

    use crate::def::BodyDef;
    use crate::interned::shape_class;

    fn shape(class: usize) -> Shape {
        match class % 4 {
            0 => Shape::circle(1.0).unwrap(),
            1 => Shape::aabb(Vec2::ONE).unwrap(),
            2 => Shape::obb(Vec2::ONE).unwrap(),
            _ => Shape::capsule(Vec2::ZERO, Vec2::X, 0.5).unwrap(),
        }
    }

    proptest! {
        /// Within each chunk, the order is a permutation of the chunk's places in the plan,
        /// grouped by class pair, in plan order within a group; `rank` is its inverse.
        #[test]
        fn the_order_groups_each_chunk_and_rank_undoes_it(
            kinds in prop::collection::vec(0usize..4, 2..12),
            pairs in prop::collection::vec((0usize..12, 0usize..12), 0..60),
            chunk in 0usize..70,
        ) {
            let mut w = World::new();
            for &k in &kinds {
                w.spawn(&BodyDef { shape: shape(k), ..BodyDef::default() });
            }
            let n = kinds.len();
            let plan: Vec<_> =
                pairs.iter().map(|&(i, j)| (i % n, j % n, Response::Report)).collect();
            let mut by = ByClass::default();
            by.sort(&w, &plan, chunk);
            let class = |i: usize| shape_class(w.shape(i));
            let group = |k: usize| (class(plan[k].0), class(plan[k].1));
            let order: Vec<usize> = by.order().iter().map(|&k| k as usize).collect();
            prop_assert_eq!(order.len(), plan.len());
            for (c, part) in order.chunks(chunk.max(1)).enumerate() {
                let first = c * chunk.max(1);
                let mut seen = part.to_vec();
                seen.sort_unstable();
                prop_assert_eq!(seen, (first..first + part.len()).collect::<Vec<_>>());
                for m in 1..part.len() {
                    let (a, b) = (part[m - 1], part[m]);
                    prop_assert!((group(a), a) < (group(b), b), "{:?}", order);
                }
            }
            for (m, &k) in order.iter().enumerate() {
                prop_assert_eq!(by.rank(k), m);
            }
        }
    }
}
