//! The scene queries' broad phase: one tree (`tree.rs`) over the static bodies and one over
//! the moving bodies, every layer in each, each built on the first query that needs it and
//! kept until the world changes.
//!
//! - **Static tree**: every static body. Kept while [`World::static_generation`] stays
//!   the same (statics never move without bumping it), so a scene of 10,000 tiles is
//!   indexed once, not once a frame.
//! - **Moving tree**: every moving body as it is now. Every `&mut self` method of
//!   `Simulation` that can move, add, remove or reshape a body makes it stale
//!   ([`QueryCache::invalidate`](super::cache::QueryCache::invalidate) keeps it aside); the next query refits it
//!   ([`Trees::refit`]: each member's pose and box recomputed, a sine and cosine only for
//!   a member that turned, the nodes' boxes recomputed bottom up, in `O(m)` for `m` moving
//!   bodies, with no allocation), or rebuilds it in `O(m log m)` when the bodies changed
//!   (another [`World::layout`]) or the refit tree walks worse than a fresh one would
//!   ([`REFIT_COST`]). The tree's shape so depends on which frames asked a query; the
//!   answers do not (they are exact and ordered by id). A step costs nothing more when no
//!   query is made: moving an empty cell aside is a branch.
//!
//! Each set's grid (`grid.rs`) is built after the set's first [`GRID_AFTER`] queries (the
//! tree answers those), and the moving set's is dropped by each refit.
//!
//! Each member keeps its pose and rotation as the tree was built, and its box is its
//! shape's exact box there: a candidate is tested with no sine or cosine, with the same
//! arithmetic (so the same bits) as [`ricochet_geom::cast_ray`], [`ricochet_geom::overlaps`]
//! and [`ricochet_geom::contains_point`]. A candidate is found in the world by its dense
//! index when built, checked against its entity (a binary search by entity if a body was
//! removed since: dense indices shift, entities never do). Both sets sit behind an `Arc`,
//! so cloning a `Simulation` shares them instead of copying trees.

use std::sync::OnceLock;
use std::sync::atomic::{AtomicU32, Ordering};

use ricochet_geom::{
    Bounds, PlacedPrimitive, Pose, Ray, RayIntersection, Rot, Shape, Vec2, place_rotated,
    placed_bounds,
};

use super::grid::Grid;
use super::tree::QueryTree;
use crate::def::LayerId;
use crate::entity::Entity;
use crate::world::{World, placed};

/// Part pairs of a query shape and a body up to which [`Trees::overlaps`] tests every pair
/// with the kept rotation (the bodies of a game have one part or a few); beyond, the pair
/// goes to [`ricochet_geom::overlaps`], which culls the parts (the same answer).
const ALL_PAIRS: usize = 64;

/// How much costlier than a fresh build ([`QueryTree::cost`]: the summed perimeters of its
/// nodes) a refit moving tree may grow before the next frame's query rebuilds it: bodies
/// that drift apart from their leaf-mates (or wrap to the far edge) stretch their nodes.
const REFIT_COST: f64 = 1.5;

/// Queries a set answers by its tree alone before it builds its grid: building the grid
/// costs about what it saves over a few thousand queries (a grid query takes some 300
/// instructions fewer than a tree walk; the grid over 10,000 members, about half a
/// millisecond), so a frame that asks a few queries of the moving set (a game's usual
/// frame) never pays for one, and a frame that asks thousands does.
const GRID_AFTER: u32 = 1024;

/// One tree over one set of bodies (the static ones or the moving ones), every layer in it.
///
/// One tree per set, not per layer, as rapier's one BVH and Box2D's one tree per body type:
/// a query that sees every layer walks one tree, not one per layer; a filter is applied to
/// each candidate by its layer, read from [`Trees::layers`] before the body is looked up.
///
/// A member is named by its position in the tree (its handle), and every column below is
/// in that order. Each member's pose and rotation are kept as the tree was built (rapier
/// keeps each collider's world pose): a candidate is placed from them, with no sine or
/// cosine a query, and its box in the tree is its shape's exact box at that angle.
#[derive(Debug, Default)]
pub(crate) struct Trees {
    /// The static generation they were built at (static trees only).
    pub(super) generation: u64,
    /// The tree; a member's handle indexes the vectors below.
    pub(crate) tree: QueryTree,
    /// Each member's entity, by handle.
    pub(crate) entities: Vec<Entity>,
    /// Each member's layer, by handle.
    pub(crate) layers: Vec<LayerId>,
    /// Each member's dense index when the tree was built: still right unless a body was
    /// removed since (then the entity is looked up, [`Trees::index`]).
    dense: Vec<u32>,
    /// Each member's pose and rotation when the tree was built, by handle.
    ready: Vec<Ready>,
    /// Each member's box about its position at its kept angle (before `placed`), by handle:
    /// a refit of a member that did not turn places it again, with no sine or cosine. Kept
    /// by the moving trees only (empty in the others, which are never refit).
    local: Vec<Bounds>,
    /// The world's layout ([`World::layout`]) the moving trees were built at: a refit
    /// needs the same bodies, layers and shapes.
    layout: u64,
    /// The tree's [`QueryTree::cost`] when built fresh: a refit that makes it costlier
    /// than [`REFIT_COST`] times this rebuilds instead.
    fresh_cost: f64,
    /// The box around every member (`None` when empty): an image of a query that misses it
    /// skips this set without walking its tree. In a wrap world most of the nine images of
    /// a query lie outside the world, so this is what keeps a query near one tree walk.
    pub(crate) bounds: Option<Bounds>,
    /// The grid over the members' boxes (`grid.rs`), built by the set's query after the
    /// first [`GRID_AFTER`] ones; `None` inside when the members' boxes do not suit one
    /// (the tree answers then).
    grid: OnceLock<Option<Grid>>,
    /// Queries that asked for the grid before it was built (at most a few past
    /// [`GRID_AFTER`]: counted only until then).
    asked: AtomicU32,
}

/// A member's pose as the tree was built, with what placing it needs.
#[derive(Clone, Copy, Debug)]
struct Ready {
    position: Vec2,
    angle: f64,
    /// `Rot::from_angle(angle)`: what a ray places the body's parts with
    /// ([`ricochet_geom::cast_ray`]).
    rot: Rot,
    /// Whether any part turns with the body ([`Shape::rotation`]: an overlap places the
    /// parts with `rot`, else with no rotation).
    turns: bool,
}

impl Ready {
    fn new(shape: &Shape, pose: Pose) -> Ready {
        Ready {
            position: pose.position,
            angle: pose.angle,
            rot: Rot::from_angle(pose.angle),
            turns: shape.primitives().iter().any(|p| p.turns_with_body()),
        }
    }

    /// [`Shape::rotation`] at this angle.
    fn shape_rot(&self) -> Rot {
        if self.turns { self.rot } else { Rot::IDENTITY }
    }

    /// The shape's box at this angle about the body's position: its parts placed about the
    /// body; [`world::placed`](placed) at the position pads it for the translation, as the
    /// world's own bounds.
    fn local_bounds(&self, shape: &Shape) -> Bounds {
        let rot = self.shape_rot();
        let mut parts = shape
            .primitives()
            .iter()
            .map(|p| placed_bounds(p, Vec2::ZERO, rot, self.angle));
        parts
            .next()
            .map_or(Bounds::around(Vec2::ZERO, Vec2::ZERO), |b| {
                parts.fold(b, Bounds::union)
            })
    }
}

impl Trees {
    /// The trees over the bodies `which` picks, ready to refit if `refit`.
    pub(super) fn build(
        world: &World,
        generation: u64,
        which: impl Iterator<Item = usize>,
        refit: bool,
    ) -> Trees {
        Trees::gather(
            generation,
            &world.entity,
            &world.layer,
            which.map(|i| (i, world.shape(i), world.pose(i))),
            refit,
        )
    }

    /// The trees over the bodies `members` names, each by its dense index into `entity`
    /// and `layer`, with its shape and pose (a past frame's bodies, `history.rs`, as the
    /// world's).
    pub(crate) fn over<'s>(
        generation: u64,
        entity: &[Entity],
        layer: &[LayerId],
        members: impl Iterator<Item = (usize, &'s Shape, Pose)>,
    ) -> Trees {
        Trees::gather(generation, entity, layer, members, false)
    }

    /// [`Trees::over`], keeping each member's box about its position ([`Trees::local`]:
    /// 32 bytes a member) if the trees are to be refit.
    fn gather<'s>(
        generation: u64,
        entity: &[Entity],
        layer: &[LayerId],
        members: impl Iterator<Item = (usize, &'s Shape, Pose)>,
        refit: bool,
    ) -> Trees {
        let n = members.size_hint().0;
        let (mut boxes, mut dense, mut ready, mut local) = (
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        );
        for (i, shape, pose) in members {
            let r = Ready::new(shape, pose);
            let l = r.local_bounds(shape);
            boxes.push(placed(l, r.position));
            local.push(l);
            dense.push(i as u32);
            ready.push(r);
        }
        let all = boxes.iter().copied().reduce(Bounds::union);
        let (tree, order) = QueryTree::new(&boxes);
        let by = |k: &u32| dense[*k as usize] as usize;
        Trees {
            generation,
            fresh_cost: tree.cost(),
            tree,
            entities: order.iter().map(|k| entity[by(k)]).collect(),
            layers: order.iter().map(|k| layer[by(k)]).collect(),
            ready: order.iter().map(|&k| ready[k as usize]).collect(),
            local: if refit {
                order.iter().map(|&k| local[k as usize]).collect()
            } else {
                Vec::new()
            },
            dense: order.iter().map(|&k| dense[k as usize]).collect(),
            layout: 0,
            bounds: all,
            grid: OnceLock::new(),
            asked: AtomicU32::new(0),
        }
    }

    /// The trees over the world's moving bodies as they are now, built fresh.
    pub(super) fn movers(world: &World, generation: u64) -> Trees {
        let mut t = Trees::build(
            world,
            generation,
            world.movers().iter().map(|&i| i as usize),
            true,
        );
        t.layout = world.layout();
        t
    }

    /// Moves these moving trees to the world's moving bodies as they are now, keeping the
    /// members' order and the tree's shape (`QueryTree::refit`): each member's pose and
    /// box recomputed as [`Trees::over`] computes them (its sine and cosine only if it
    /// turned), so a query answers exactly as over a fresh build. False when the bodies
    /// are not the same ones (then `self` is half moved: rebuild), or when the refit tree
    /// costs more than [`REFIT_COST`] times a fresh one (a fresh build walks faster).
    pub(super) fn refit(&mut self, world: &World) -> bool {
        let n = self.entities.len();
        if self.layout != world.layout() || world.movers().len() != n || self.local.len() != n {
            return false;
        }
        let mut all: Option<Bounds> = None;
        for k in 0..n {
            let i = self.dense[k] as usize;
            if world.entity.get(i) != Some(&self.entities[k]) {
                return false;
            }
            let pose = world.pose(i);
            let r = &mut self.ready[k];
            if pose.angle.to_bits() == r.angle.to_bits() {
                r.position = pose.position;
            } else {
                let shape = world.shape(i);
                *r = Ready::new(shape, pose);
                self.local[k] = r.local_bounds(shape);
            }
            let b = placed(self.local[k], pose.position);
            self.tree.set_member(k, b);
            all = Some(all.map_or(b, |a| a.union(b)));
        }
        self.bounds = all;
        self.grid = OnceLock::new();
        *self.asked.get_mut() = 0;
        self.tree.refit() <= REFIT_COST * self.fresh_cost
    }

    /// [`QueryTree::ray`] by the grid where it can walk the segment (`grid.rs`), else by
    /// the tree: `f` may see a member more than once, and in another order, with the same
    /// first hit and the same hits (its test is exact and `max` only shrinks).
    #[inline]
    pub(crate) fn ray(
        &self,
        origin: Vec2,
        dir: Vec2,
        max: f64,
        f: &mut impl FnMut(usize, f64) -> f64,
    ) {
        if let Some(g) = self.grid()
            && g.ray(origin, dir, max, f)
        {
            return;
        }
        self.tree.ray(origin, dir, max, f);
    }

    /// The grid over the members, built if needed after the set's first [`GRID_AFTER`]
    /// queries (`None` before, and when the members do not suit one). The tree and the
    /// grid give the same answers, so which one answers depends on nothing an answer
    /// shows.
    #[inline]
    fn grid(&self) -> Option<&Grid> {
        if let Some(g) = self.grid.get() {
            return g.as_ref();
        }
        if self.asked.fetch_add(1, Ordering::Relaxed) < GRID_AFTER {
            return None;
        }
        self.grid
            .get_or_init(|| Grid::new(&self.tree.member_boxes(self.entities.len())))
            .as_ref()
    }

    /// Calls `f` with every member whose box overlaps `q` (touching counts), once each, in
    /// no order: by the grid for a finite `q` (built here if needed), else by the tree.
    #[inline]
    pub(crate) fn each_overlapping(&self, q: &Bounds, f: &mut impl FnMut(usize)) {
        let finite = q.min.is_finite() && q.max.is_finite();
        match self.grid() {
            Some(g) if finite => g.query(q, f),
            _ => self.tree.query(q, f),
        }
    }

    /// Whether `q` may meet a member of this set (touching counts).
    pub(crate) fn may_meet(&self, q: &Bounds) -> bool {
        self.bounds.is_some_and(|b| b.overlaps(q))
    }

    /// The dense index among the bodies `entity` (ascending) of the member `handle`, if
    /// its body is still there: the index it was built with when that still names the body
    /// (a lookup by entity else).
    #[inline]
    pub(crate) fn index(&self, entity: &[Entity], handle: usize) -> Option<usize> {
        let e = self.entities[handle];
        let i = self.dense[handle] as usize;
        if entity.get(i) == Some(&e) {
            Some(i)
        } else {
            entity.binary_search(&e).ok()
        }
    }

    /// [`ricochet_geom::cast_ray`] of `ray` against member `handle`, whose shape is
    /// `shape`, from its kept rotation: the same arithmetic, so the same bits.
    #[inline]
    pub(crate) fn cast_ray(
        &self,
        handle: usize,
        shape: &Shape,
        ray: &Ray,
        max_distance: f64,
    ) -> Option<RayIntersection> {
        let r = &self.ready[handle];
        if max_distance.is_nan() || max_distance < 0.0 || !r.position.is_finite() {
            return None;
        }
        let origin = ray.origin() - r.position;
        let d = ray.direction();
        let mut best: Option<(f64, Vec2)> = None;
        for p in shape.primitives() {
            let placed = place_rotated(p, Vec2::ZERO, r.rot, r.angle);
            if let Some((t, n)) = ricochet_geom::cast_placed(&placed, origin, d, max_distance)
                && best.is_none_or(|(b, _)| t < b)
            {
                best = Some((t, n));
                if t == 0.0 {
                    break;
                }
            }
        }
        best.map(|(t, normal)| RayIntersection {
            distance: t,
            point: if t == 0.0 {
                ray.origin()
            } else {
                ray.point_at(t)
            },
            normal,
        })
    }

    /// [`ricochet_geom::contains_point`] of `point` in member `handle` (shape `shape`),
    /// from its kept rotation.
    #[inline]
    pub(crate) fn contains_point(&self, handle: usize, shape: &Shape, point: Vec2) -> bool {
        let r = &self.ready[handle];
        let p = point - r.position;
        shape.primitives().iter().any(|prim| {
            ricochet_geom::contains_placed(&place_rotated(prim, Vec2::ZERO, r.rot, r.angle), p)
        })
    }

    /// [`ricochet_geom::overlaps`] of the query `probe` (its parts placed about its own
    /// position, `at`) with member `handle` (shape `shape`), from the member's kept
    /// rotation: the pair in the frame centred on the query, as that function places it.
    #[inline]
    pub(crate) fn overlaps(
        &self,
        handle: usize,
        shape: &Shape,
        probe: &Probe<'_>,
        at: Vec2,
    ) -> bool {
        let r = &self.ready[handle];
        let parts = shape.primitives();
        let placed = probe.placed;
        if placed.len() * parts.len() > ALL_PAIRS {
            let pose = Pose::new(r.position, r.angle);
            return ricochet_geom::overlaps(probe.shape, &Pose::new(at, probe.angle), shape, &pose);
        }
        let (position, rot) = (r.position - at, r.shape_rot());
        placed.iter().any(|a| {
            parts
                .iter()
                .any(|b| ricochet_geom::overlaps_placing(a, b, position, rot, r.angle))
        })
    }
}

/// A query shape placed once about its own position (the frame of
/// [`ricochet_geom::overlaps`]), for every candidate of the query. Its placed parts are
/// the caller's: a placed part is the size of the largest polygon, so moving a probe that
/// held one would copy that many bytes a query.
pub(crate) struct Probe<'a> {
    pub(crate) shape: &'a Shape,
    pub(crate) angle: f64,
    /// Its parts placed, with its rotation.
    pub(crate) placed: &'a [PlacedPrimitive],
}

/// The box around the members of both sets (`None` when both are empty): an image of a
/// query that misses it is not walked at all (`wrap::images`).
#[inline]
pub(crate) fn hull(trees: &[&Trees; 2]) -> Option<Bounds> {
    // Matched by reference: a copy of the pair through the stack, stored in one split and
    // read back in another, stalled the loads (store forwarding fails).
    match (&trees[0].bounds, &trees[1].bounds) {
        (Some(a), Some(b)) => Some(a.union(*b)),
        (a, b) => a.or(*b),
    }
}

/// Calls `f` with the set, handle and dense index of every body of an accepted layer whose
/// box overlaps `q` (touching counts), in no set order: by each set's grid when `by_grid`
/// ([`Trees::each_overlapping`]: the overlap queries), else by its tree (the same bodies,
/// once each, in another order).
#[inline]
pub(crate) fn each_in_box(
    entity: &[Entity],
    trees: &[&Trees; 2],
    accepts_layer: impl Fn(LayerId) -> bool,
    q: &Bounds,
    by_grid: bool,
    f: &mut impl FnMut(&Trees, usize, usize),
) {
    for &set in trees {
        if !set.may_meet(q) {
            continue;
        }
        let mut accepted = |k| {
            if accepts_layer(set.layers[k])
                && let Some(i) = set.index(entity, k)
            {
                f(set, k, i);
            }
        };
        if by_grid {
            set.each_overlapping(q, &mut accepted);
        } else {
            set.tree.query(q, &mut accepted);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::Simulation;
    use crate::{BodyDef, QueryFilter, Scenario};

    /// 300 balls on a lattice, each with its own slow velocity, in an unbounded world.
    fn scene() -> Simulation {
        let bodies = (0..300)
            .map(|k| BodyDef {
                shape: Shape::circle(1.0).expect("radius"),
                position: Vec2::new((k % 20) as f64 * 5.0, (k / 20) as f64 * 5.0),
                // Apart by under a unit a second: they drift, the tree stays good.
                velocity: Vec2::new(
                    (k * 37 % 11) as f64 * 0.08 - 0.4,
                    (k * 53 % 7) as f64 * 0.12 - 0.36,
                ),
                ..BodyDef::default()
            })
            .collect();
        Simulation::new(&Scenario {
            bodies,
            ..Scenario::default()
        })
    }

    fn movers(sim: &Simulation) -> &Trees {
        sim.queries.movers.get().expect("built by a query")
    }

    fn ask(sim: &Simulation) -> usize {
        let q = Bounds::around(Vec2::splat(50.0), Vec2::splat(5.0));
        sim.overlap_aabb(q, &QueryFilter::all()).len()
    }

    /// Steps while the bodies stay the same are refits: the members keep the order of the
    /// build (a fresh build orders them otherwise by then); a spawn rebuilds.
    #[test]
    fn the_moving_tree_is_refit_while_the_bodies_stay_and_rebuilt_when_they_change() {
        let mut sim = scene();
        sim.step();
        ask(&sim);
        let built = movers(&sim).entities.clone();
        for _ in 0..20 {
            sim.step();
            ask(&sim);
        }
        assert!(movers(&sim).entities == built, "rebuilt");
        let w = sim.world();
        let fresh = Trees::build(w, 0, w.movers().iter().map(|&i| i as usize), true);
        assert_ne!(
            fresh.entities, built,
            "a fresh build would be the same tree"
        );
        sim.spawn(&BodyDef {
            shape: Shape::circle(1.0).expect("radius"),
            ..BodyDef::default()
        });
        ask(&sim);
        assert_eq!(movers(&sim).entities.len(), built.len() + 1);
    }

    /// A set's first [`GRID_AFTER`] queries are answered by its tree: a frame that asks a
    /// few builds no grid.
    #[test]
    fn the_grid_is_built_only_after_many_queries_of_a_frame() {
        let mut sim = scene();
        sim.step();
        for _ in 0..GRID_AFTER {
            ask(&sim);
        }
        assert!(movers(&sim).grid.get().is_none());
        ask(&sim);
        assert!(movers(&sim).grid.get().is_some());
        sim.step();
        ask(&sim);
        assert!(movers(&sim).grid.get().is_none(), "a new frame starts over");
    }
}
