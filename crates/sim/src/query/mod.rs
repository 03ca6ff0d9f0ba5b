//! Scene queries: what a game asks the world between two steps (rapier's `QueryPipeline`,
//! Box2D's `b2World_CastRay` / `b2World_OverlapAABB`): the first body a ray hits, every body
//! it hits, where a swept shape first touches a body, and the bodies at a point, in a box
//! or overlapping a shape.
//!
//! # Conventions
//! - **Exact**, like the narrow phase: rays use [`ricochet_geom::cast_ray`] and
//!   [`ricochet_geom::contains_point`], overlaps [`ricochet_geom::overlaps`], casts
//!   [`ricochet_geom::time_of_impact`] (the cast shape swept, the body still), each in a
//!   frame centred on the body.
//! - **Solid bodies**: a ray starting strictly inside a body hits it at distance 0, at its
//!   origin, with a zero normal (rapier's `cast_ray_and_get_normal` with `solid = true`).
//!   Otherwise the normal points out of the body, against the ray.
//! - **Touching** counts as [`ricochet_geom::overlaps`] counts it: not at all (`depth > 0`).
//!   A point on a body's boundary is not in it; a box or shape that only touches a body
//!   does not overlap it. A ray that grazes a body (tangent, or along a face) hits it.
//! - **Input**: a direction of any length is normalised; a zero or non-finite direction,
//!   origin, point, pose or translation, or a negative or NaN `max_distance`, gives `None`
//!   or nothing, never a panic.
//! - **Order**: overlaps in id order; [`Simulation::cast_ray_all`] by distance, then id;
//!   a tie for the first hit goes to the lowest id.
//! - **Filter**: [`QueryFilter`] picks layers and leaves one entity out.
//! - **Wrap worlds**: every image of a body is seen, and a ray leaving one edge goes on
//!   from the opposite one, its distance accumulated (`wrap.rs`). A query's origin, point
//!   or pose outside a wrap world is first wrapped into it.
//!
//! # Candidates
//! Never a loop over every body: a tree over the static bodies (kept while the static
//! generation stays) and one over the moving bodies (refit by the first query after the
//! world changed, rebuilt when the bodies did), walked along the ray or by the query's
//! bounds (`index.rs`, `tree.rs`), each member's pose and rotation kept with it. The
//! overlap queries (point, box, shape) and the rays ask a uniform grid over each set
//! instead where it can answer (`grid.rs`, built beside the tree once the set has answered
//! 1,024 queries): a few cells, not the tree's levels.
//! A candidate of a layer the filter refuses is dropped before its exact test.
//!
//! # Now and then
//! Every query is written once, over a [`Bodies`] view: the world now, or a frame kept for
//! lag compensation (`history.rs`, [`crate::Past`]), whose one tree over all its bodies is
//! built by its first query. So a past frame answers exactly as the world restored there.

pub(crate) mod cache;
mod filter;
mod grid;
mod hits;
pub(crate) mod index;
mod slab;
mod tree;
mod wrap;

use ricochet_geom::{
    Aabb, Bounds, PlacedAabb, PlacedPrimitive, Pose, Primitive, Ray, Shape, Sweep, Vec2,
};

pub use filter::QueryFilter;
pub use hits::{RayHit, ShapeHit};
pub(crate) use wrap::wrapping;

use cache::{Lent, QueryCache};

use crate::def::{LayerId, WorldBounds};
use crate::entity::Entity;
use crate::pipeline::Simulation;
use crate::world::World;

/// What a query reads of a set of bodies, by dense index (ascending entities): the world
/// now, or a past frame kept by `history.rs`. The query code runs over either alike, so a
/// past frame answers as the world restored there would.
pub(crate) trait Bodies {
    /// Each body's entity, ascending.
    fn entity(&self) -> &[Entity];
    /// Each body's layer.
    fn layer(&self) -> &[LayerId];
    /// Body `i`'s shape, local coordinates.
    fn shape(&self, i: usize) -> &Shape;
    /// Body `i`'s pose.
    fn pose(&self, i: usize) -> Pose;
    /// The static trees and the moving trees over the bodies (`index.rs`), built if needed,
    /// lent for the query.
    fn trees(&self) -> [Lent<'_>; 2];
}

/// The world now, with the simulation's cached trees.
pub(crate) struct Now<'a> {
    world: &'a World,
    cache: &'a QueryCache,
}

impl Bodies for Now<'_> {
    fn entity(&self) -> &[Entity] {
        &self.world.entity
    }

    fn layer(&self) -> &[LayerId] {
        &self.world.layer
    }

    #[inline]
    fn shape(&self, i: usize) -> &Shape {
        self.world.shape(i)
    }

    #[inline]
    fn pose(&self, i: usize) -> Pose {
        self.world.pose(i)
    }

    fn trees(&self) -> [Lent<'_>; 2] {
        self.cache.trees(self.world)
    }
}

/// A set of bodies and the world's wrap: what every query runs over.
pub(crate) struct Scene<'a, B: Bodies> {
    pub(crate) bodies: B,
    /// The world's bounds if it wraps.
    pub(crate) wrap: Option<&'a WorldBounds>,
}

impl Simulation {
    /// The world now, to query.
    fn scene(&self) -> Scene<'_, Now<'_>> {
        Scene {
            bodies: Now {
                world: &self.world,
                cache: &self.queries,
            },
            wrap: wrap::wrapping(self.scenario.world.bounds.as_ref()),
        }
    }

    /// The first body the ray from `origin` along `direction` hits within `max_distance`
    /// (the module's conventions: solid bodies, the normal out of the body, the lowest id
    /// on a tie). `None` for a miss or bad input.
    #[must_use]
    pub fn cast_ray(
        &self,
        origin: Vec2,
        direction: Vec2,
        max_distance: f64,
        filter: &QueryFilter,
    ) -> Option<RayHit> {
        self.scene()
            .cast_ray(origin, direction, max_distance, filter)
    }

    /// Every body the ray hits within `max_distance`, once each (its first hit), by
    /// distance, then id. Empty for bad input.
    #[must_use]
    pub fn cast_ray_all(
        &self,
        origin: Vec2,
        direction: Vec2,
        max_distance: f64,
        filter: &QueryFilter,
    ) -> Vec<RayHit> {
        self.scene()
            .cast_ray_all(origin, direction, max_distance, filter)
    }

    /// Where `shape` at `pose`, moved by `translation` (its angle fixed), first touches a
    /// body ([`ricochet_geom::time_of_impact`]: within `1e-9` of the smaller size of
    /// touching): the smallest fraction of the translation, the lowest id on a tie. A shape
    /// already overlapping a body touches it at fraction 0. In a wrap world the path goes
    /// on from the opposite edge, as a ray's does. `None` for no touch or bad input.
    #[must_use]
    pub fn cast_shape(
        &self,
        shape: &Shape,
        pose: Pose,
        translation: Vec2,
        filter: &QueryFilter,
    ) -> Option<ShapeHit> {
        self.scene().cast_shape(shape, pose, translation, filter)
    }

    /// The bodies `point` is strictly inside, in id order.
    #[must_use]
    pub fn overlap_point(&self, point: Vec2, filter: &QueryFilter) -> Vec<Entity> {
        self.scene().overlap_point(point, filter)
    }

    /// The bodies whose shape overlaps the box `bounds` (exact shape against box, touching
    /// not counted), in id order. Empty for a non-finite or inverted box, or one thinner
    /// than [`ricochet_geom::MIN_SIZE`] (it has no inside to overlap).
    #[must_use]
    pub fn overlap_aabb(&self, bounds: Bounds, filter: &QueryFilter) -> Vec<Entity> {
        self.scene().overlap_aabb(bounds, filter)
    }

    /// The bodies `shape` at `pose` overlaps (touching not counted), in id order.
    #[must_use]
    pub fn overlap_shape(&self, shape: &Shape, pose: Pose, filter: &QueryFilter) -> Vec<Entity> {
        self.scene().overlap_shape(shape, pose, filter)
    }
}

impl<B: Bodies> Scene<'_, B> {
    /// The first body the ray from `origin` along `direction` hits within `max_distance`
    /// (the module's conventions: solid bodies, the normal out of the body, the lowest id
    /// on a tie). `None` for a miss or bad input.
    #[must_use]
    pub(crate) fn cast_ray(
        &self,
        origin: Vec2,
        direction: Vec2,
        max_distance: f64,
        filter: &QueryFilter,
    ) -> Option<RayHit> {
        let mut best: Option<RayHit> = None;
        self.ray_hits(origin, direction, max_distance, filter, true, &mut |h| {
            if best.is_none_or(|b| (h.distance, h.entity) < (b.distance, b.entity)) {
                best = Some(h);
            }
            best.map_or(f64::INFINITY, |b| b.distance)
        });
        best
    }

    /// Every body the ray hits within `max_distance`, once each (its first hit), by
    /// distance, then id. Empty for bad input.
    #[must_use]
    pub(crate) fn cast_ray_all(
        &self,
        origin: Vec2,
        direction: Vec2,
        max_distance: f64,
        filter: &QueryFilter,
    ) -> Vec<RayHit> {
        let mut all: Vec<RayHit> = Vec::new();
        self.ray_hits(origin, direction, max_distance, filter, false, &mut |h| {
            all.push(h);
            f64::INFINITY
        });
        // Each body once, at its first hit (a body may be met in several images).
        all.sort_by(|a, b| {
            a.entity
                .cmp(&b.entity)
                .then(a.distance.total_cmp(&b.distance))
        });
        all.dedup_by_key(|h| h.entity);
        all.sort_by(|a, b| {
            a.distance
                .total_cmp(&b.distance)
                .then(a.entity.cmp(&b.entity))
        });
        all
    }

    /// Where `shape` at `pose`, moved by `translation` (its angle fixed), first touches a
    /// body ([`ricochet_geom::time_of_impact`]: within `1e-9` of the smaller size of
    /// touching): the smallest fraction of the translation, the lowest id on a tie. A shape
    /// already overlapping a body touches it at fraction 0. In a wrap world the path goes
    /// on from the opposite edge, as a ray's does. `None` for no touch or bad input.
    #[must_use]
    pub(crate) fn cast_shape(
        &self,
        shape: &Shape,
        pose: Pose,
        translation: Vec2,
        filter: &QueryFilter,
    ) -> Option<ShapeHit> {
        if !(pose.position.is_finite() && pose.angle.is_finite() && translation.is_finite()) {
            return None;
        }
        let bodies = &self.bodies;
        let (entity, layer) = (bodies.entity(), bodies.layer());
        let wrap = self.wrap;
        let start = wrap.map_or(pose.position, |b| wrap::wrap_point(b, pose.position));
        let total = translation.length();
        let dir = if total > 0.0 {
            translation / total
        } else {
            Vec2::ZERO
        };
        let lent = bodies.trees();
        let trees = [&*lent[0], &*lent[1]];
        let (offsets, images) = wrap::offsets(wrap);
        let mut best: Option<ShapeHit> = None;
        let mut segment = |from: Vec2, travelled: f64, len: f64| {
            let to = from + dir * len;
            for &o in &offsets[..images] {
                let sweep = Sweep {
                    start: from - o,
                    end: to - o,
                    angle: pose.angle,
                };
                let q = shape
                    .bounds(&Pose::new(sweep.start, pose.angle))
                    .union(shape.bounds(&Pose::new(sweep.end, pose.angle)));
                index::each_in_box(
                    entity,
                    &trees,
                    |l| filter.accepts_layer(l),
                    &q,
                    false,
                    &mut |_, _, i| {
                        if !filter.accepts(layer[i], entity[i]) {
                            return;
                        }
                        let at = bodies.pose(i);
                        let body = Sweep {
                            start: at.position,
                            end: at.position,
                            angle: at.angle,
                        };
                        let Some(hit) =
                            ricochet_geom::time_of_impact(shape, &sweep, bodies.shape(i), &body)
                        else {
                            return;
                        };
                        let fraction = if total > 0.0 {
                            ((travelled + hit.t * len) / total).min(1.0)
                        } else {
                            0.0
                        };
                        let h = ShapeHit {
                            entity: entity[i],
                            fraction,
                            point: hit.contact.point + o,
                            normal: hit.contact.normal,
                        };
                        if best.is_none_or(|b| (h.fraction, h.entity) < (b.fraction, b.entity)) {
                            best = Some(h);
                        }
                    },
                );
            }
            // A touch in this segment comes before any in the next.
            best.is_none()
        };
        if total > 0.0 {
            wrap::segments(wrap, start, dir, total, &mut segment);
        } else {
            segment(start, 0.0, 0.0);
        }
        best
    }

    /// The bodies `point` is strictly inside, in id order.
    #[must_use]
    pub(crate) fn overlap_point(&self, point: Vec2, filter: &QueryFilter) -> Vec<Entity> {
        if !point.is_finite() {
            return Vec::new();
        }
        let q = Bounds {
            min: point,
            max: point,
        };
        self.overlapping(q, filter, &mut |set, k, i, o| {
            set.contains_point(k, self.bodies.shape(i), point - o)
        })
    }

    /// The bodies whose shape overlaps the box `bounds` (exact shape against box, touching
    /// not counted), in id order. Empty for a non-finite or inverted box, or one thinner
    /// than [`ricochet_geom::MIN_SIZE`] (it has no inside to overlap).
    #[must_use]
    pub(crate) fn overlap_aabb(&self, bounds: Bounds, filter: &QueryFilter) -> Vec<Entity> {
        let ok = bounds.min.is_finite()
            && bounds.max.is_finite()
            && bounds.min.x <= bounds.max.x
            && bounds.min.y <= bounds.max.y;
        if !ok {
            return Vec::new();
        }
        let half = bounds.half_extents();
        if half.x < ricochet_geom::MIN_SIZE || half.y < ricochet_geom::MIN_SIZE {
            return Vec::new();
        }
        // Checked above as `Shape::aabb` would check it, without its error text: that
        // validation formats its field names, two allocations a query.
        let shape = Shape::Primitive(Primitive::Aabb(Aabb {
            center: Vec2::ZERO,
            half_extents: half,
        }));
        let center = bounds.center();
        // `shape.bounds` at `center`, angle 0, and the box placed about its centre: a box
        // turns with no rotation, so its centre moves by exactly zero (the same bits as
        // `Shape::bounds` and `overlap_shape`'s placement, without the general placing).
        let q = Bounds::around(center, half);
        let one = [PlacedPrimitive::Aabb(PlacedAabb {
            center: Vec2::ZERO,
            half,
        })];
        let probe = index::Probe {
            shape: &shape,
            angle: 0.0,
            placed: &one,
        };
        self.overlap_probe(q, &probe, center, filter)
    }

    /// The bodies `shape` at `pose` overlaps (touching not counted), in id order.
    #[must_use]
    pub(crate) fn overlap_shape(
        &self,
        shape: &Shape,
        pose: Pose,
        filter: &QueryFilter,
    ) -> Vec<Entity> {
        if !(pose.position.is_finite() && pose.angle.is_finite()) {
            return Vec::new();
        }
        // Placed about its own position (the frame of `ricochet_geom::overlaps`): one part
        // (the usual query: a box, a circle) on the stack, more in a `Vec`.
        let rot = shape.rotation(pose.angle);
        let place = |p| ricochet_geom::place_rotated(p, Vec2::ZERO, rot, pose.angle);
        let (one, many);
        let placed: &[PlacedPrimitive] = if let [p] = shape.primitives() {
            one = [place(p)];
            &one
        } else {
            many = shape.primitives().iter().map(place).collect::<Vec<_>>();
            &many
        };
        let probe = index::Probe {
            shape,
            angle: pose.angle,
            placed,
        };
        self.overlap_probe(shape.bounds(&pose), &probe, pose.position, filter)
    }

    /// The bodies `probe` at `at` overlaps, `q` its bounds there, in id order.
    fn overlap_probe(
        &self,
        q: Bounds,
        probe: &index::Probe<'_>,
        at: Vec2,
        filter: &QueryFilter,
    ) -> Vec<Entity> {
        self.overlapping(q, filter, &mut |set, k, i, o| {
            set.overlaps(k, self.bodies.shape(i), probe, at - o)
        })
    }

    /// The accepted bodies, in id order, for which `test(i, offset)` holds at some image
    /// offset whose translated bounds meet `q` (moved into a wrap world first).
    fn overlapping(
        &self,
        q: Bounds,
        filter: &QueryFilter,
        test: &mut impl FnMut(&index::Trees, usize, usize, Vec2) -> bool,
    ) -> Vec<Entity> {
        let (entity, layer) = (self.bodies.entity(), self.bodies.layer());
        let wrap = self.wrap;
        let shift = wrap.map_or(Vec2::ZERO, |b| wrap::wrap_point(b, q.center()) - q.center());
        let lent = self.bodies.trees();
        let trees = [&*lent[0], &*lent[1]];
        let mut found = Vec::new();
        let images = wrap::images(wrap, Some(&q), shift, index::hull(&trees));
        for o in images.iter() {
            // The query moved by `shift - o`: the body's image at `o` against the query.
            let d = shift - o;
            let qo = q.translated(d);
            index::each_in_box(
                entity,
                &trees,
                |l| filter.accepts_layer(l),
                &qo,
                true,
                &mut |set, k, i| {
                    if filter.accepts(layer[i], entity[i]) && test(set, k, i, o - shift) {
                        found.push(entity[i]);
                    }
                },
            );
        }
        found.sort_unstable();
        found.dedup();
        found
    }

    /// Calls `f` with each body's first hit by the ray in each image it is met in (in no
    /// set order); `f` returns the distance beyond which hits no longer matter.
    /// `first`: stop at the first wrap segment with a hit.
    fn ray_hits(
        &self,
        origin: Vec2,
        direction: Vec2,
        max_distance: f64,
        filter: &QueryFilter,
        first: bool,
        f: &mut impl FnMut(RayHit) -> f64,
    ) {
        if max_distance.is_nan() || max_distance < 0.0 {
            return;
        }
        let Some(ray) = Ray::new(origin, direction) else {
            return;
        };
        let bodies = &self.bodies;
        let (entity, layer) = (bodies.entity(), bodies.layer());
        let wrap = self.wrap;
        let start = wrap.map_or(origin, |b| wrap::wrap_point(b, origin));
        let dir = ray.direction();
        let lent = bodies.trees();
        let trees = [&*lent[0], &*lent[1]];
        let hull = index::hull(&trees);
        let mut limit = f64::INFINITY;
        let mut segment = |from: Vec2, travelled: f64, len: f64| {
            let mut hit_here = false;
            let room = len.min(limit - travelled);
            // The segment's box (none for an endless ray): an image whose box misses a tree
            // set's skips that set.
            let reach = room.is_finite().then(|| {
                let to = from + dir * room.max(0.0);
                Bounds {
                    min: from.min(to),
                    max: from.max(to),
                }
            });
            for o in wrap::images(wrap, reach.as_ref(), Vec2::ZERO, hull).iter() {
                let seen = reach.map(|r| r.translated(-o));
                let meets = |set: &index::Trees| seen.is_none_or(|q| set.may_meet(&q));
                if !trees.iter().any(|set| meets(set)) {
                    continue;
                }
                let Some(seg) = Ray::new(from - o, dir) else {
                    continue;
                };
                for set in trees {
                    if !meets(set) {
                        continue;
                    }
                    let room = len.min(limit - travelled);
                    if room < 0.0 {
                        continue;
                    }
                    set.ray(seg.origin(), dir, room, &mut |k, max| {
                        if !filter.accepts_layer(set.layers[k]) {
                            return max;
                        }
                        let Some(i) = set.index(entity, k) else {
                            return max;
                        };
                        let e = entity[i];
                        if !filter.accepts(layer[i], e) {
                            return max;
                        }
                        let Some(h) = set.cast_ray(k, bodies.shape(i), &seg, max) else {
                            return max;
                        };
                        hit_here = true;
                        limit = f(RayHit {
                            entity: e,
                            point: if h.distance == 0.0 { from } else { h.point + o },
                            normal: h.normal,
                            distance: travelled + h.distance,
                        });
                        max.min(limit - travelled)
                    });
                }
            }
            !(first && hit_here)
        };
        wrap::segments(wrap, start, dir, max_distance, &mut segment);
    }
}
