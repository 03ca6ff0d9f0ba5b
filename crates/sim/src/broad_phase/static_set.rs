//! The static bodies, kept from one call to the next, and their structures (a tree, a grid,
//! a quadtree or a dynamic tree per layer), built when the set changes and never per call.

use ricochet_geom::Bounds;

use super::hash_grid::HashGrid;
use super::kept_tree::StaticDynamicTree;
use super::quadtree::Quadtree;
use super::static_tree::StaticTree;
use super::{BodyEntry, BroadPhaseKind, LAYERS, Member, STATIC_BIT, Scratch};

/// The static bodies, sorted by key, and their structures.
#[derive(Debug, Default, Clone)]
pub(super) struct StaticSet {
    pub(super) loaded: bool,
    /// The caller's generation (`pairs_split`), or `None` when loaded by content (`pairs`).
    pub(super) generation: Option<u64>,
    pub(super) keys: Vec<u64>,
    pub(super) entries: Vec<(Bounds, u8)>,
    /// `pairs`: this call's dense index of each static body.
    pub(super) dense: Vec<u32>,
    /// Layers with static bodies, ascending (the inert ones' included).
    pub(super) layers: Vec<u8>,
    /// Static bodies the caller keeps out because their layers pair with nothing
    /// ([`BroadPhase::set_inert_statics`](super::BroadPhase::set_inert_statics)): counted,
    /// never stored.
    pub(super) inert: usize,
    pub(super) inert_layers: Vec<u8>,
    /// Whether `trees` (`SortAndSweep`) and `grids` (`Grid`) hold the current set.
    pub(super) built_trees: bool,
    pub(super) built_grids: bool,
    /// Whether `quadtrees` (`Quadtree`) and `dynamic_trees` (`Tree`) hold the current set.
    pub(super) built_quadtrees: bool,
    pub(super) built_dynamic_trees: bool,
    /// Whether the broad phase's static strip lists (`Strips`) hold the current set.
    pub(super) built_strips: bool,
    pub(super) trees: Vec<StaticTree>,
    pub(super) grids: Vec<HashGrid>,
    pub(super) quadtrees: Vec<Quadtree>,
    pub(super) dynamic_trees: Vec<StaticDynamicTree>,
}

impl StaticSet {
    /// How many static bodies there are, the inert ones included.
    pub(super) fn count(&self) -> usize {
        self.keys.len() + self.inert
    }

    /// Whether static body `s` is `b`, bit for bit.
    pub(super) fn same(&self, s: usize, b: &BodyEntry) -> bool {
        self.keys.get(s).is_some_and(|&k| k == b.key) && {
            let (bounds, layer) = &self.entries[s];
            let bits = |b: &Bounds| [b.min.x, b.min.y, b.max.x, b.max.y].map(f64::to_bits);
            *layer == b.layer && bits(bounds) == bits(&b.bounds)
        }
    }

    /// Stores `statics` (in key order), dropping the structures built for the old ones.
    pub(super) fn load<'a>(
        &mut self,
        statics: impl Iterator<Item = &'a BodyEntry>,
        generation: Option<u64>,
    ) {
        self.loaded = true;
        self.generation = generation;
        self.keys.clear();
        self.entries.clear();
        for b in statics {
            self.keys.push(b.key);
            self.entries.push((b.bounds, b.layer));
        }
        let mut present = [false; LAYERS];
        for (_, l) in &self.entries {
            present[usize::from(*l)] = true;
        }
        for &l in &self.inert_layers {
            present[usize::from(l)] = true;
        }
        self.layers = (0..LAYERS)
            .filter(|&l| present[l])
            .map(|l| l as u8)
            .collect();
        self.built_trees = false;
        self.built_grids = false;
        self.built_quadtrees = false;
        self.built_dynamic_trees = false;
        self.built_strips = false;
        // Free the old structures now: a million tiles' worth should not linger.
        self.trees = Vec::new();
        self.grids = Vec::new();
        self.quadtrees = Vec::new();
        self.dynamic_trees = Vec::new();
    }

    /// Builds the structures `kind` queries, one per layer.
    pub(super) fn build(&mut self, kind: BroadPhaseKind, scratch: &mut Scratch) {
        let mut by_layer: Vec<Vec<Member>> = (0..LAYERS).map(|_| Vec::new()).collect();
        for (s, &(bounds, layer)) in self.entries.iter().enumerate() {
            by_layer[usize::from(layer)].push(Member {
                bounds,
                handle: s as u32 | STATIC_BIT,
                dynamic: false,
            });
        }
        if kind == BroadPhaseKind::SortAndSweep {
            self.trees = by_layer.into_iter().map(StaticTree::new).collect();
        } else if kind == BroadPhaseKind::Quadtree {
            self.quadtrees = by_layer
                .into_iter()
                .map(|members| {
                    let mut q = Quadtree::default();
                    q.members = members;
                    q.build();
                    q
                })
                .collect();
        } else if kind == BroadPhaseKind::Tree {
            self.dynamic_trees = by_layer.into_iter().map(StaticDynamicTree::new).collect();
        } else {
            self.grids = by_layer
                .into_iter()
                .map(|members| {
                    let mut g = HashGrid::default();
                    g.members = members;
                    g.build(&mut scratch.extents, true);
                    g
                })
                .collect();
        }
    }
}
