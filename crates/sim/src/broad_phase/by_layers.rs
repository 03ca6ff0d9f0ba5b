//! The per-layer-pair dispatch of the algorithms that keep structures (`SortAndSweep`,
//! `Grid`, `Strips`, `Quadtree`, `Tree`): every pair of interacting moving layers through the per-call
//! structures, every moving layer's dynamic bodies against every interacting static layer
//! through the static ones, counting the layer combinations skipped.

use ricochet_geom::Bounds;

use crate::def::BodyKind;

use super::hash_grid::HashGrid;
use super::kept_tree::KeptTree;
use super::quadtree::Quadtree;
use super::sort_and_sweep::{SweepView, sweep_cross, sweep_self};
use super::{
    BodyEntry, BroadPhase, BroadPhaseKind, BroadPhaseStats, Extent, Interactions, Member, member,
    of_layer,
};

impl BroadPhase {
    /// Per pair of interacting layers: moving–moving through the per-call structures,
    /// dynamic–static through the static ones.
    pub(super) fn by_layers(
        &mut self,
        kind: BroadPhaseKind,
        (bodies, given): (&[BodyEntry], Option<Extent>),
        interactions: &Interactions,
        out: &mut Vec<(u32, u32)>,
        stats: &mut BroadPhaseStats,
    ) {
        if kind == BroadPhaseKind::Strips {
            self.prepare_strips(bodies, given);
        } else {
            let built = match kind {
                BroadPhaseKind::SortAndSweep => &mut self.statics.built_trees,
                BroadPhaseKind::Quadtree => &mut self.statics.built_quadtrees,
                BroadPhaseKind::Tree => &mut self.statics.built_dynamic_trees,
                _ => &mut self.statics.built_grids,
            };
            if !*built {
                *built = true;
                self.statics.build(kind, &mut self.scratch);
                self.static_rebuilds += 1;
            }
        }
        let layers = std::mem::take(&mut self.mover_layers);
        let static_layers = std::mem::take(&mut self.statics.layers);
        for (k, &a) in layers.iter().enumerate() {
            if self.filter.filtered(a) {
                // Every pair of `a` with the moving layers it meets (`cell_filter.rs`).
                let (tested, resorted) = self.filtered_pairs(a, &layers, interactions, bodies, out);
                stats.tested += tested;
                stats.resorted += resorted;
            }
            for &b in &layers[k..] {
                if !interactions.interacts(a, b) {
                    stats.layer_pairs_skipped += 1;
                    continue;
                }
                let (da, db) = (self.dynamic[usize::from(a)], self.dynamic[usize::from(b)]);
                let filtered = self.filter.filtered(a) || self.filter.filtered(b);
                if (da != 0 || db != 0) && !filtered {
                    self.moving_pairs(kind, (a, b), bodies, out, stats);
                }
            }
            if self.dynamic[usize::from(a)] == 0 {
                continue;
            }
            for &b in &static_layers {
                if interactions.interacts(a, b) {
                    self.static_pairs(kind, (a, b), bodies, out, stats);
                } else {
                    stats.layer_pairs_skipped += 1;
                }
            }
        }
        self.mover_layers = layers;
        self.statics.layers = static_layers;
    }

    /// The pairs of moving layers `a` and `b` (the same layer, or two) with a dynamic body.
    fn moving_pairs(
        &mut self,
        kind: BroadPhaseKind,
        (a, b): (u8, u8),
        bodies: &[BodyEntry],
        out: &mut Vec<(u32, u32)>,
        stats: &mut BroadPhaseStats,
    ) {
        match kind {
            BroadPhaseKind::Strips => self.strip_pairs((a, b), bodies, out, stats),
            BroadPhaseKind::SortAndSweep => {
                stats.resorted += self.ensure_sweep(a, bodies);
                stats.resorted += self.ensure_sweep(b, bodies);
                let mut ranges = std::mem::take(&mut self.scratch.ranges);
                let view = |l: u8| SweepView {
                    list: &self.sweeps[usize::from(l)],
                    handles: self.layer_movers(l),
                    bodies,
                };
                if a == b {
                    stats.tested += sweep_self(view(a), out);
                } else {
                    stats.tested += sweep_cross(view(a), view(b), &mut ranges, out);
                }
                self.scratch.ranges = ranges;
            }
            _ => self.indexed_pairs(kind, (a, b), bodies, out, stats),
        }
    }

    /// The pairs of moving layer `a`'s dynamic bodies with static layer `b`.
    fn static_pairs(
        &mut self,
        kind: BroadPhaseKind,
        (a, b): (u8, u8),
        bodies: &[BodyEntry],
        out: &mut Vec<(u32, u32)>,
        stats: &mut BroadPhaseStats,
    ) {
        if kind == BroadPhaseKind::Strips {
            self.strip_static_pairs((a, b), bodies, out, stats);
            return;
        }
        for &h in of_layer(&self.movers, &self.layer_start, a) {
            let q = &bodies[h as usize];
            if q.kind != BodyKind::Dynamic {
                continue;
            }
            let mut emit = |m: &Member| out.push((h, m.handle));
            let st = &self.statics;
            let nodes = &mut self.scratch.nodes;
            stats.tested += match kind {
                BroadPhaseKind::SortAndSweep => {
                    let tree = &st.trees[usize::from(b)];
                    tree.query(&q.bounds, &mut self.scratch.stack, &mut emit)
                }
                BroadPhaseKind::Quadtree => {
                    st.quadtrees[usize::from(b)].query(&q.bounds, nodes, |_, m| emit(m))
                }
                BroadPhaseKind::Tree => {
                    st.dynamic_trees[usize::from(b)].query(&q.bounds, nodes, |_, m| emit(m))
                }
                _ => st.grids[usize::from(b)].query(&q.bounds, &mut emit),
            };
        }
    }

    /// Brings layer `l`'s sorted list up to this call, once per call. Returns the re-sort's
    /// moves.
    pub(super) fn ensure_sweep(&mut self, l: u8, bodies: &[BodyEntry]) -> u64 {
        let list = &mut self.sweeps[usize::from(l)];
        if list.frame == self.frame {
            return 0;
        }
        list.frame = self.frame;
        let handles = of_layer(&self.movers, &self.layer_start, l);
        list.update(handles, bodies, &mut self.scratch)
    }

    /// `Grid`, `Quadtree` and `Tree`: the pairs of moving layers `a` and `b`. One layer: its
    /// structure finds its own pairs. Two: the larger layer's structure is queried with the
    /// smaller's bodies (only the one queried is brought up to date).
    fn indexed_pairs(
        &mut self,
        kind: BroadPhaseKind,
        (a, b): (u8, u8),
        bodies: &[BodyEntry],
        out: &mut Vec<(u32, u32)>,
        stats: &mut BroadPhaseStats,
    ) {
        let (na, nb) = (self.layer_movers(a).len(), self.layer_movers(b).len());
        let (index, query) = if na > nb { (a, b) } else { (b, a) };
        let l = usize::from(index);
        let structure = match kind {
            BroadPhaseKind::Quadtree => {
                let qt = &mut self.quadtrees[l];
                if qt.frame != self.frame {
                    qt.frame = self.frame;
                    layer_members(
                        &self.movers,
                        &self.layer_start,
                        index,
                        bodies,
                        &mut qt.members,
                    );
                    qt.build();
                }
                Indexed::Quadtree(qt)
            }
            BroadPhaseKind::Tree => {
                stats.resorted += self.ensure_tree(index, bodies);
                Indexed::Tree(&self.trees[l])
            }
            _ => {
                let grid = &mut self.grids[l];
                if grid.frame != self.frame {
                    grid.frame = self.frame;
                    layer_members(
                        &self.movers,
                        &self.layer_start,
                        index,
                        bodies,
                        &mut grid.members,
                    );
                    grid.build(&mut self.scratch.extents, false);
                }
                Indexed::Grid(grid)
            }
        };
        let nodes = &mut self.scratch.nodes;
        if a == b {
            stats.tested += structure.self_pairs(nodes, out);
            return;
        }
        for &h in of_layer(&self.movers, &self.layer_start, query) {
            let q = member(&bodies[h as usize], h);
            stats.tested += structure.query(&q.bounds, nodes, |m| {
                if q.dynamic || m.dynamic {
                    out.push((q.handle, m.handle));
                }
            });
        }
    }

    /// Brings layer `l`'s kept tree up to this call, once per call. Returns the leaves
    /// moved, inserted or removed.
    fn ensure_tree(&mut self, l: u8, bodies: &[BodyEntry]) -> u64 {
        let tree = &mut self.trees[usize::from(l)];
        if tree.frame == self.frame {
            return 0;
        }
        tree.frame = self.frame;
        tree.update(of_layer(&self.movers, &self.layer_start, l), bodies)
    }
}

/// Layer `l`'s moving bodies as members, in key order, into `members` (cleared first).
fn layer_members(
    movers: &[u32],
    layer_start: &[u32],
    l: u8,
    bodies: &[BodyEntry],
    members: &mut Vec<Member>,
) {
    members.clear();
    members.extend(
        of_layer(movers, layer_start, l)
            .iter()
            .map(|&h| member(&bodies[h as usize], h)),
    );
}

/// One layer's structure of moving bodies, whichever kind built it.
enum Indexed<'a> {
    Grid(&'a HashGrid),
    Quadtree(&'a Quadtree),
    Tree(&'a KeptTree),
}

impl Indexed<'_> {
    /// Calls `f` on every member overlapping `q`. Returns the members tested.
    #[inline]
    fn query(&self, q: &Bounds, nodes: &mut Vec<u32>, mut f: impl FnMut(&Member)) -> u64 {
        match self {
            Indexed::Grid(g) => g.query(q, f),
            Indexed::Quadtree(t) => t.query(q, nodes, |_, m| f(m)),
            Indexed::Tree(t) => t.query(q, nodes, |_, m| f(m)),
        }
    }

    /// Every overlapping pair of the members with a dynamic one. Returns the tests.
    fn self_pairs(&self, nodes: &mut Vec<u32>, out: &mut Vec<(u32, u32)>) -> u64 {
        match self {
            Indexed::Grid(g) => g.self_pairs(out),
            Indexed::Quadtree(t) => t.self_pairs(nodes, out),
            Indexed::Tree(t) => t.self_pairs(nodes, out),
        }
    }
}
