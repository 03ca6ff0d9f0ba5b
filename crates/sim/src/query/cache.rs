//! The cache of a simulation's query trees ([`QueryCache`]): the static set kept while
//! the statics stay, the moving set kept aside by each change and refit by the next frame's
//! first query (see `index.rs` for what a set holds and when it is rebuilt), and how a
//! query holds a set ([`Lent`]).

use std::sync::{Arc, Mutex, OnceLock, PoisonError};

use super::index::Trees;
use crate::def::BodyKind;
use crate::world::World;

/// The two tree sets, built lazily (see the module docs).
#[derive(Debug, Default)]
pub(crate) struct QueryCache {
    statics: OnceLock<Arc<Trees>>,
    pub(super) movers: OnceLock<Arc<Trees>>,
    /// The moving trees of the last frame that asked a query, stale: the next frame's
    /// first query refits them ([`Trees::refit`]) instead of building new ones. A lock
    /// only because a query holds the cache shared; it is taken once a frame, never held.
    stale: Mutex<Option<Arc<Trees>>>,
}

impl Clone for QueryCache {
    /// The trees shared; the stale moving trees left to the original, which refits them
    /// in place (shared, neither could).
    fn clone(&self) -> QueryCache {
        QueryCache {
            statics: self.statics.clone(),
            movers: self.movers.clone(),
            stale: Mutex::default(),
        }
    }
}

impl QueryCache {
    /// Forgets what the world's last change made stale: the moving trees always (kept
    /// aside to refit), the static trees when the static generation moved on.
    pub(crate) fn invalidate(&mut self, world: &World) {
        if let Some(movers) = self.movers.take() {
            *self.stale.get_mut().unwrap_or_else(PoisonError::into_inner) = Some(movers);
        }
        if self
            .statics
            .get()
            .is_some_and(|t| t.generation != world.static_generation())
        {
            self.statics = OnceLock::new();
        }
    }

    /// The static trees and the moving trees of `world`, built if needed, lent: no `Arc`
    /// count is touched (two atomic increments and decrements a query of a few hundred
    /// nanoseconds).
    pub(crate) fn trees(&self, world: &World) -> [Lent<'_>; 2] {
        let generation = world.static_generation();
        let build_statics = || {
            Arc::new(Trees::build(
                world,
                generation,
                (0..world.len()).filter(|&i| world.kind[i] == BodyKind::Static),
                false,
            ))
        };
        let kept = self.statics.get_or_init(build_statics);
        let statics = if kept.generation == generation {
            Lent::Kept(kept)
        } else {
            // A change that did not go through `invalidate`: answer from fresh trees.
            Lent::Fresh(build_statics())
        };
        let movers = self.movers.get_or_init(|| {
            let stale = self
                .stale
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .take();
            if let Some(mut kept) = stale
                && Arc::get_mut(&mut kept).is_some_and(|t| t.refit(world))
            {
                return kept;
            }
            Arc::new(Trees::movers(world, generation))
        });
        [statics, Lent::Kept(movers)]
    }
}

/// A tree set as a query holds it: lent by the cache, or built for this query alone.
pub(crate) enum Lent<'a> {
    Kept(&'a Trees),
    Fresh(Arc<Trees>),
}

impl std::ops::Deref for Lent<'_> {
    type Target = Trees;

    #[inline]
    fn deref(&self) -> &Trees {
        match self {
            Lent::Kept(t) => t,
            Lent::Fresh(t) => t,
        }
    }
}
