//! The scene queries' broad phase: packed trees (the STR trees of `broad_phase/static_tree.rs`)
//! per layer, one set over the static bodies and one over the moving bodies, each built on
//! the first query that needs it and kept until the world changes.
//!
//! - **Static trees** hold every static body's bounds, by layer. They are kept while
//!   [`World::static_generation`] stays the same (statics never move without bumping it),
//!   so a scene of 10,000 tiles is indexed once, not once a frame.
//! - **Moving trees** hold every moving body's [`World::bounds`], by layer, as they are
//!   now. Every `&mut self` method of `Simulation` that can move, add, remove or reshape a
//!   body drops them ([`QueryCache::invalidate`]); the next query rebuilds them, in
//!   `O(m log m)` for `m` moving bodies. A step costs nothing more when no query is made:
//!   dropping an empty cell is a branch.
//!
//! Members are named by their index into the tree set's entity list, and a candidate is
//! found in the world by entity (a binary search): dense indices shift when any body is
//! removed, entities never do. Both sets sit behind an `Arc`, so cloning a `Simulation`
//! shares them instead of copying trees.

use std::sync::{Arc, OnceLock};

use ricochet_geom::Bounds;

use crate::broad_phase::Member;
use crate::broad_phase::static_tree::StaticTree;
use crate::def::{BodyKind, LayerId};
use crate::entity::Entity;
use crate::world::World;

/// One tree over one set of bodies (the static ones or the moving ones), every layer in it.
///
/// One tree per set, not per layer, as rapier's one BVH and Box2D's one tree per body type:
/// a query that sees every layer walks one tree, not one per layer; a filter is applied to
/// each candidate by its layer, read from [`Trees::layers`] before the body is looked up.
#[derive(Debug, Default)]
pub(crate) struct Trees {
    /// The static generation they were built at (static trees only).
    generation: u64,
    /// The tree; a member's handle indexes the vectors below.
    pub(crate) tree: StaticTree,
    /// Each member's entity, by handle.
    pub(crate) entities: Vec<Entity>,
    /// Each member's layer, by handle.
    pub(crate) layers: Vec<LayerId>,
    /// Each member's dense index when the tree was built: still right unless a body was
    /// removed since (then the entity is looked up, [`Trees::index`]).
    dense: Vec<u32>,
    /// The box around every member (`None` when empty): an image of a query that misses it
    /// skips this set without walking its tree. In a wrap world most of the nine images of
    /// a query lie outside the world, so this is what keeps a query near one tree walk.
    pub(crate) bounds: Option<Bounds>,
}

impl Trees {
    /// The trees over the bodies `which` picks.
    fn build(world: &World, generation: u64, which: impl Iterator<Item = usize>) -> Trees {
        Trees::over(
            generation,
            &world.entity,
            &world.layer,
            which.map(|i| (i, world.bounds_now(i))),
        )
    }

    /// The trees over the bodies `members` names, each by its dense index into `entity`
    /// and `layer` and with its bounds (a past frame's bodies, `history.rs`, as the
    /// world's).
    pub(crate) fn over(
        generation: u64,
        entity: &[Entity],
        layer: &[LayerId],
        members: impl Iterator<Item = (usize, Bounds)>,
    ) -> Trees {
        let n = members.size_hint().0;
        let mut list = Vec::with_capacity(n);
        let (mut entities, mut layers, mut dense) = (
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        );
        let mut all: Option<Bounds> = None;
        for (i, bounds) in members {
            all = Some(all.map_or(bounds, |a| a.union(bounds)));
            list.push(Member {
                bounds,
                handle: entities.len() as u32,
                dynamic: false,
            });
            entities.push(entity[i]);
            layers.push(layer[i]);
            dense.push(i as u32);
        }
        Trees {
            generation,
            tree: StaticTree::new(list),
            entities,
            layers,
            dense,
            bounds: all,
        }
    }

    /// Whether `q` may meet a member of this set (touching counts).
    pub(crate) fn may_meet(&self, q: &Bounds) -> bool {
        self.bounds.is_some_and(|b| b.overlaps(q))
    }

    /// The dense index among the bodies `entity` (ascending) of the member `handle`, if
    /// its body is still there: the index it was built with when that still names the body
    /// (a lookup by entity else).
    pub(crate) fn index(&self, entity: &[Entity], handle: u32) -> Option<usize> {
        let h = handle as usize;
        let e = self.entities[h];
        let i = self.dense[h] as usize;
        if entity.get(i) == Some(&e) {
            Some(i)
        } else {
            entity.binary_search(&e).ok()
        }
    }
}

/// The two tree sets, built lazily (see the module docs).
#[derive(Clone, Debug, Default)]
pub(crate) struct QueryCache {
    statics: OnceLock<Arc<Trees>>,
    movers: OnceLock<Arc<Trees>>,
}

impl QueryCache {
    /// Forgets what the world's last change made stale: the moving trees always, the
    /// static trees when the static generation moved on.
    pub(crate) fn invalidate(&mut self, world: &World) {
        self.movers = OnceLock::new();
        if self
            .statics
            .get()
            .is_some_and(|t| t.generation != world.static_generation())
        {
            self.statics = OnceLock::new();
        }
    }

    /// The static trees and the moving trees of `world`, built if needed.
    pub(crate) fn trees(&self, world: &World) -> [Arc<Trees>; 2] {
        let generation = world.static_generation();
        let build_statics = || {
            Arc::new(Trees::build(
                world,
                generation,
                (0..world.len()).filter(|&i| world.kind[i] == BodyKind::Static),
            ))
        };
        let mut statics = Arc::clone(self.statics.get_or_init(build_statics));
        if statics.generation != generation {
            // A change that did not go through `invalidate`: answer from fresh trees.
            statics = build_statics();
        }
        let movers = self.movers.get_or_init(|| {
            Arc::new(Trees::build(
                world,
                generation,
                world.movers().iter().map(|&i| i as usize),
            ))
        });
        [statics, Arc::clone(movers)]
    }
}

/// Calls `f` with the dense index of every body of an accepted layer whose bounds overlap
/// `q` (touching counts), in no set order.
pub(crate) fn each_in_box(
    entity: &[Entity],
    trees: &[Arc<Trees>; 2],
    accepts_layer: impl Fn(LayerId) -> bool,
    q: &Bounds,
    stack: &mut Vec<(u32, u32)>,
    f: &mut impl FnMut(usize),
) {
    for set in trees {
        if !set.may_meet(q) {
            continue;
        }
        set.tree.query(q, stack, &mut |m: &Member| {
            if accepts_layer(set.layers[m.handle as usize])
                && let Some(i) = set.index(entity, m.handle)
            {
                f(i);
            }
        });
    }
}
