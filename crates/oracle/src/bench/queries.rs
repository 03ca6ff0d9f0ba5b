//! The rapier side of `ricochet bench --queries`: scene queries on a [`RapierScene`]'s
//! colliders through rapier's [`QueryPipeline`], as a rapier user asks them.
//!
//! The pipeline is the broad phase's own BVH (`BroadPhaseBvh::as_query_pipeline`, rapier
//! 0.36's query API: there is no separate query structure to update), with the narrow phase's
//! query dispatcher and no filter (`QueryFilter::default()`: every collider, as
//! `ricochet_sim::QueryFilter::all()`). Every answer is exact:
//!
//! - a ray is `cast_ray_and_get_normal` with `solid = true` (a ray starting inside a shape
//!   hits it at distance 0, Ricochet's convention) and a unit direction, so rapier's time of
//!   impact is the distance;
//! - a box overlap is `intersect_shape` with a cuboid at the box's centre (parry's exact
//!   intersection test on every collider whose BVH box meets the query's), not
//!   `intersect_aabb_conservative` (BVH boxes only);
//! - a point overlap is `intersect_point` (`contains_point` on every collider whose BVH box
//!   holds it).
//!
//! Entities come back through the collider's `user_data` (the dense index the scene tagged
//! it with), overlaps sorted in id order as Ricochet returns them.
//!
//! [`QueryPipeline`]: rapier2d_f64::prelude::QueryPipeline

use rapier2d_f64::math::Pose as PPose;
use rapier2d_f64::parry::shape::Cuboid;
use rapier2d_f64::prelude::{ColliderHandle, QueryFilter, QueryPipeline, Ray};
use ricochet_geom::{Bounds, Vec2};
use ricochet_sim::Entity;

use super::RapierScene;
use crate::convert::{from_vector, to_vector};
use crate::pairs::index;

/// One ray's first hit, as rapier reports it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RapierRayHit {
    /// The body hit.
    pub entity: Entity,
    /// How far along the (unit) direction, world units.
    pub distance: f64,
    /// The surface normal at the hit, pointing out of the body.
    pub normal: Vec2,
}

impl RapierScene {
    /// Rapier's query pipeline over this scene's colliders (see the module docs).
    fn query_pipeline(&self) -> QueryPipeline<'_> {
        self.broad_phase.as_query_pipeline(
            self.narrow_phase.query_dispatcher(),
            &self.bodies,
            &self.colliders,
            QueryFilter::default(),
        )
    }

    /// The entity of a collider of this scene.
    fn entity_of(&self, handle: ColliderHandle) -> Option<Entity> {
        self.colliders
            .get(handle)
            .and_then(|c| self.entities.get(index(c)).copied())
    }

    /// The first body the ray from `origin` along `direction` (unit length) meets within
    /// `max_distance`, solid (a ray starting inside a body hits it at 0). Call after
    /// [`step`](RapierScene::step): the BVH is the broad phase's.
    #[must_use]
    pub fn cast_ray(
        &self,
        origin: Vec2,
        direction: Vec2,
        max_distance: f64,
    ) -> Option<RapierRayHit> {
        let ray = Ray::new(to_vector(origin), to_vector(direction));
        let (handle, hit) =
            self.query_pipeline()
                .cast_ray_and_get_normal(&ray, max_distance, true)?;
        Some(RapierRayHit {
            entity: self.entity_of(handle)?,
            distance: hit.time_of_impact,
            normal: from_vector(hit.normal),
        })
    }

    /// Every body whose shape overlaps `bounds` (touching counts, as parry's intersection
    /// test has it), in id order.
    #[must_use]
    pub fn overlap_aabb(&self, bounds: Bounds) -> Vec<Entity> {
        let half = bounds.half_extents();
        let cuboid = Cuboid::new(to_vector(half));
        let pose = PPose::from_translation(to_vector(bounds.center()));
        let pipeline = self.query_pipeline();
        let mut hits: Vec<Entity> = pipeline
            .intersect_shape(pose, &cuboid)
            .filter_map(|(h, _)| self.entity_of(h))
            .collect();
        hits.sort_unstable();
        hits
    }

    /// Every body whose shape contains `point`, in id order.
    #[must_use]
    pub fn overlap_point(&self, point: Vec2) -> Vec<Entity> {
        let pipeline = self.query_pipeline();
        let mut hits: Vec<Entity> = pipeline
            .intersect_point(to_vector(point))
            .filter_map(|(h, _)| self.entity_of(h))
            .collect();
        hits.sort_unstable();
        hits
    }
}
