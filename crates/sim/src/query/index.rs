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

/// Trees over one set of bodies (the static ones or the moving ones), by layer.
#[derive(Debug, Default)]
pub(crate) struct Trees {
    /// The static generation they were built at (static trees only).
    generation: u64,
    /// The layers that have bodies, ascending, each with its tree.
    pub(crate) layers: Vec<(LayerId, StaticTree)>,
    /// Each member's entity, by handle.
    pub(crate) entities: Vec<Entity>,
}

impl Trees {
    /// The trees over the bodies `which` picks.
    fn build(world: &World, generation: u64, which: impl Iterator<Item = usize>) -> Trees {
        let mut by_layer: Vec<Vec<Member>> = Vec::new();
        let mut entities = Vec::new();
        for i in which {
            let layer = usize::from(world.layer[i]);
            if by_layer.len() <= layer {
                by_layer.resize_with(layer + 1, Vec::new);
            }
            by_layer[layer].push(Member {
                bounds: world.bounds_now(i),
                handle: entities.len() as u32,
                dynamic: false,
            });
            entities.push(world.entity[i]);
        }
        let layers = by_layer
            .into_iter()
            .enumerate()
            .filter(|(_, m)| !m.is_empty())
            .map(|(l, m)| (l as LayerId, StaticTree::new(m)))
            .collect();
        Trees {
            generation,
            layers,
            entities,
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
    world: &World,
    trees: &[Arc<Trees>; 2],
    accepts_layer: impl Fn(LayerId) -> bool,
    q: &Bounds,
    stack: &mut Vec<(u32, u32)>,
    f: &mut impl FnMut(usize),
) {
    for set in trees {
        for (layer, tree) in &set.layers {
            if accepts_layer(*layer) {
                tree.query(q, stack, &mut |m: &Member| {
                    if let Some(i) = world.index_of(set.entities[m.handle as usize]) {
                        f(i);
                    }
                });
            }
        }
    }
}
