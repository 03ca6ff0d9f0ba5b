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
//! - **Wrap worlds**: every image of a body is seen (see `wrap.rs`).

mod filter;
mod hits;

use ricochet_geom::{Bounds, Pose, Ray, Shape, Sweep, Vec2};

pub use filter::QueryFilter;
pub use hits::{RayHit, ShapeHit};

use crate::entity::Entity;
use crate::pipeline::Simulation;

impl Simulation {
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
        let mut best: Option<RayHit> = None;
        self.ray_hits(origin, direction, max_distance, filter, &mut |h| {
            if best.is_none_or(|b| (h.distance, h.entity) < (b.distance, b.entity)) {
                best = Some(h);
            }
        });
        best
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
        let mut all: Vec<RayHit> = Vec::new();
        self.ray_hits(origin, direction, max_distance, filter, &mut |h| {
            all.push(h)
        });
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
    /// body: the smallest fraction of the translation, the lowest id on a tie. A shape
    /// already overlapping a body touches it at fraction 0. `None` for no touch or bad
    /// input.
    #[must_use]
    pub fn cast_shape(
        &self,
        shape: &Shape,
        pose: Pose,
        translation: Vec2,
        filter: &QueryFilter,
    ) -> Option<ShapeHit> {
        if !(pose.position.is_finite() && pose.angle.is_finite() && translation.is_finite()) {
            return None;
        }
        let sweep = Sweep {
            start: pose.position,
            end: pose.position + translation,
            angle: pose.angle,
        };
        let w = &self.world;
        let mut best: Option<ShapeHit> = None;
        for i in 0..w.len() {
            if !filter.accepts(w.layer[i], w.entity[i]) {
                continue;
            }
            let body = Sweep {
                start: w.position[i],
                end: w.position[i],
                angle: w.angle[i],
            };
            if let Some(hit) = ricochet_geom::time_of_impact(shape, &sweep, w.shape(i), &body) {
                let h = ShapeHit {
                    entity: w.entity[i],
                    fraction: hit.t,
                    point: hit.contact.point,
                    normal: hit.contact.normal,
                };
                if best.is_none_or(|b| (h.fraction, h.entity) < (b.fraction, b.entity)) {
                    best = Some(h);
                }
            }
        }
        best
    }

    /// The bodies `point` is strictly inside, in id order.
    #[must_use]
    pub fn overlap_point(&self, point: Vec2, filter: &QueryFilter) -> Vec<Entity> {
        if !point.is_finite() {
            return Vec::new();
        }
        let w = &self.world;
        (0..w.len())
            .filter(|&i| {
                filter.accepts(w.layer[i], w.entity[i])
                    && ricochet_geom::contains_point(w.shape(i), &w.pose(i), point)
            })
            .map(|i| w.entity[i])
            .collect()
    }

    /// The bodies whose shape overlaps the box `bounds` (exact shape against box, touching
    /// not counted), in id order. Empty for a non-finite or inverted box.
    #[must_use]
    pub fn overlap_aabb(&self, bounds: Bounds, filter: &QueryFilter) -> Vec<Entity> {
        let ok = bounds.min.is_finite()
            && bounds.max.is_finite()
            && bounds.min.x <= bounds.max.x
            && bounds.min.y <= bounds.max.y;
        if !ok {
            return Vec::new();
        }
        let Ok(shape) = Shape::aabb(bounds.half_extents()) else {
            return Vec::new();
        };
        self.overlap_shape(&shape, Pose::new(bounds.center(), 0.0), filter)
    }

    /// The bodies `shape` at `pose` overlaps (touching not counted), in id order.
    #[must_use]
    pub fn overlap_shape(&self, shape: &Shape, pose: Pose, filter: &QueryFilter) -> Vec<Entity> {
        if !(pose.position.is_finite() && pose.angle.is_finite()) {
            return Vec::new();
        }
        let w = &self.world;
        (0..w.len())
            .filter(|&i| {
                filter.accepts(w.layer[i], w.entity[i])
                    && ricochet_geom::overlaps(shape, &pose, w.shape(i), &w.pose(i))
            })
            .map(|i| w.entity[i])
            .collect()
    }

    /// Calls `f` with each body's first hit by the ray (in no set order).
    fn ray_hits(
        &self,
        origin: Vec2,
        direction: Vec2,
        max_distance: f64,
        filter: &QueryFilter,
        f: &mut impl FnMut(RayHit),
    ) {
        let Some(ray) = Ray::new(origin, direction) else {
            return;
        };
        if max_distance.is_nan() || max_distance < 0.0 {
            return;
        }
        let w = &self.world;
        for i in 0..w.len() {
            if !filter.accepts(w.layer[i], w.entity[i]) {
                continue;
            }
            if let Some(h) = ricochet_geom::cast_ray(w.shape(i), &w.pose(i), &ray, max_distance) {
                f(RayHit {
                    entity: w.entity[i],
                    point: h.point,
                    normal: h.normal,
                    distance: h.distance,
                });
            }
        }
    }
}
