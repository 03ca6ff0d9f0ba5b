//! Ray casts: the first body a ray meets, and every body it meets.

use ricochet_geom::{Ray, Vec2, cast_ray};

use super::{QueryFilter, RayHit};
use crate::pipeline::Simulation;

impl Simulation {
    /// The first body the ray from `origin` along `direction` meets within `max_distance`
    /// (Box2D's `b2World_CastRayClosest`, rapier's `QueryPipeline::cast_ray` with
    /// `solid = true`). `direction` need not be unit: it is normalised, and distances are
    /// along the unit direction. Ties go to the lower entity. See the module docs of
    /// [`crate::query`] for the conventions (solid bodies, normals, wrap worlds).
    ///
    /// `None` for a miss, and for bad input: a zero or non-finite direction, a non-finite
    /// origin, a negative or non-finite `max_distance`.
    #[must_use]
    pub fn cast_ray(
        &self,
        origin: Vec2,
        direction: Vec2,
        max_distance: f64,
        filter: &QueryFilter,
    ) -> Option<RayHit> {
        let mut best: Option<RayHit> = None;
        self.ray_hits(origin, direction, max_distance, filter, |hit| {
            let better = best.is_none_or(|b| {
                hit.distance < b.distance || (hit.distance == b.distance && hit.entity < b.entity)
            });
            if better {
                best = Some(hit);
            }
            best.map_or(max_distance, |b| b.distance)
        });
        best
    }

    /// Every body the ray meets within `max_distance`, each once (at its first hit: in a
    /// wrap world, the nearest image), sorted by distance, then entity. Conventions and bad
    /// input as [`Simulation::cast_ray`] (bad input: empty).
    #[must_use]
    pub fn cast_ray_all(
        &self,
        origin: Vec2,
        direction: Vec2,
        max_distance: f64,
        filter: &QueryFilter,
    ) -> Vec<RayHit> {
        let mut hits: Vec<RayHit> = Vec::new();
        self.ray_hits(origin, direction, max_distance, filter, |hit| {
            hits.push(hit);
            max_distance
        });
        hits.sort_by(|a, b| a.entity.cmp(&b.entity).then(a.distance.total_cmp(&b.distance)));
        hits.dedup_by_key(|h| h.entity);
        hits.sort_by(|a, b| a.distance.total_cmp(&b.distance).then(a.entity.cmp(&b.entity)));
        hits
    }

    /// Calls `f` on every hit of a body (an image, in a wrap world) the ray meets; `f`
    /// returns how far the search must still go (hits beyond it may be skipped).
    fn ray_hits(
        &self,
        origin: Vec2,
        direction: Vec2,
        max_distance: f64,
        filter: &QueryFilter,
        mut f: impl FnMut(RayHit) -> f64,
    ) {
        let Some(ray) = Ray::new(origin, direction) else {
            return;
        };
        if !(max_distance.is_finite() && max_distance >= 0.0) {
            return;
        }
        let w = &self.world;
        let mut reach = max_distance;
        self.ray_candidates(&ray, max_distance, filter, |i, offset| {
            // The body's image at `offset` is the body met by the ray moved back by it:
            // the hit is then on the body itself, in a frame centred on it.
            let hit = cast_ray(w.shape(i), &w.pose(i), &ray.translated(-offset), reach)?;
            reach = f(RayHit {
                entity: w.entity[i],
                point: hit.point,
                normal: hit.normal,
                distance: hit.distance,
            });
            Some(reach)
        });
    }
}
