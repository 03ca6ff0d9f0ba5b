//! The query referee's rapier side: every body of a [`Simulation`] as a rapier collider
//! (any shape, compounds included), asked through rapier's `QueryPipeline` exactly as
//! Ricochet's scene queries are asked (`crates/oracle/tests/queries.rs` compares them;
//! `docs/validation.md`, "Scene queries", has the tolerances and the rules).
//!
//! - Colliders are placed by `convert::place` in world coordinates (a frame at the world
//!   origin), so a scene at `1e6` is a scene at `1e6` to rapier too: its rounding is part of
//!   what the tolerances allow ([`QueryTolerance`]).
//! - Each collider's `user_data` is the body's dense index, read back as its entity.
//! - A filter is rapier's `QueryFilter::predicate` over Ricochet's own [`ricochet_sim::QueryFilter`]
//!   (layers and one entity left out), so rapier sees the same bodies.
//! - A compound *query* shape (overlap or cast) is asked part by part, and the answers joined
//!   (the union of the overlaps, the earliest cast): parry's dispatcher has no compound
//!   against compound test.
//!
//! The checks a rule needs ([`QueryReferee::depth`], [`QueryReferee::point_distance`]) use
//! the referee's exact pair query (`reference_contact`: capsules as core segments).

use rapier2d_f64::math::Pose as PPose;
use rapier2d_f64::parry::query::ShapeCastOptions;
use rapier2d_f64::parry::shape::{Cuboid, SharedShape};
use rapier2d_f64::prelude::{
    Aabb, BroadPhaseBvh, ColliderBuilder, ColliderHandle, ColliderSet, CollisionPipeline,
    IslandManager, NarrowPhase, QueryFilter as RapierFilter, QueryPipeline, Ray, RigidBodySet,
};
use ricochet_geom::{Bounds, Pose, Shape, Vec2};
use ricochet_sim::{Entity, QueryFilter, Simulation};

use crate::OracleError;
use crate::convert::{from_vector, place, reference_contact, size, to_vector};

/// How far apart two answers may be and still agree: `absolute` world units plus `relative`
/// times the size of the body concerned (half its local bounding box's diagonal).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QueryTolerance {
    /// The rounding of world coordinates: `8 ε` times the largest coordinate the query
    /// and the body involve (both engines place shapes and rays in world coordinates, each
    /// with its own operation order).
    pub absolute: f64,
    /// Relative to the body's size: the narrow phase's depth tolerance, `1e-9`.
    pub relative: f64,
}

impl QueryTolerance {
    /// The tolerance for queries whose coordinates reach `magnitude` (world units).
    #[must_use]
    pub fn at(magnitude: f64) -> QueryTolerance {
        QueryTolerance {
            absolute: 8.0 * f64::EPSILON * magnitude.max(1.0),
            relative: 1e-9,
        }
    }

    /// The band for a body of shape `s`, world units.
    #[must_use]
    pub fn band(&self, s: &Shape) -> f64 {
        self.absolute + self.relative * size(s).max(1.0)
    }
}

/// Rapier's answer to a ray: the body, the distance along the unit direction, the normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReferenceRayHit {
    /// The body hit.
    pub entity: Entity,
    /// Distance along the unit direction.
    pub distance: f64,
    /// Parry's normal (zero for a solid ray starting inside).
    pub normal: Vec2,
}

/// Every body of a simulation as a rapier collider, and rapier's `QueryPipeline` over them.
pub struct QueryReferee {
    broad_phase: BroadPhaseBvh,
    narrow_phase: NarrowPhase,
    bodies: RigidBodySet,
    colliders: ColliderSet,
    /// By dense index: the body's entity, layer, shape and pose.
    entities: Vec<Entity>,
    layers: Vec<ricochet_sim::LayerId>,
    shapes: Vec<Shape>,
    poses: Vec<Pose>,
}

impl QueryReferee {
    /// Rapier colliders for every body of `sim` at its current pose, and the BVH over them
    /// (built by one collision-pipeline step).
    pub fn new(sim: &Simulation) -> Result<QueryReferee, OracleError> {
        let w = sim.world();
        let mut r = QueryReferee {
            broad_phase: BroadPhaseBvh::new(),
            narrow_phase: NarrowPhase::new(),
            bodies: RigidBodySet::new(),
            colliders: ColliderSet::new(),
            entities: w.entity.clone(),
            layers: w.layer.clone(),
            shapes: (0..w.len()).map(|i| w.shape(i).clone()).collect(),
            poses: (0..w.len()).map(|i| w.pose(i)).collect(),
        };
        for i in 0..w.len() {
            let (pose, shape) = place(w.shape(i), &w.pose(i), Vec2::ZERO)?;
            let collider = ColliderBuilder::new(shape)
                .position(pose)
                .user_data(i as u128)
                .build();
            r.colliders.insert(collider);
        }
        CollisionPipeline::new().step(
            0.0,
            &mut IslandManager::new(),
            &mut r.broad_phase,
            &mut r.narrow_phase,
            &mut r.bodies,
            &mut r.colliders,
            &(),
            &(),
        );
        Ok(r)
    }

    /// The dense index of a collider (its `user_data`).
    fn index(&self, h: ColliderHandle) -> Option<usize> {
        self.colliders
            .get(h)
            .and_then(|c| usize::try_from(c.user_data).ok())
    }

    /// The body's shape and pose, by entity.
    #[must_use]
    pub fn body(&self, e: Entity) -> Option<(&Shape, Pose)> {
        let i = self.entities.iter().position(|x| *x == e)?;
        Some((&self.shapes[i], self.poses[i]))
    }

    /// Runs `f` with rapier's pipeline seeing exactly the bodies `filter` accepts.
    fn with_pipeline<T>(&self, filter: &QueryFilter, f: impl FnOnce(QueryPipeline<'_>) -> T) -> T {
        let accepts = |_: ColliderHandle, c: &rapier2d_f64::prelude::Collider| {
            usize::try_from(c.user_data)
                .ok()
                .is_some_and(|i| filter.accepts(self.layers[i], self.entities[i]))
        };
        let rf = RapierFilter::default().predicate(&accepts);
        f(self.broad_phase.as_query_pipeline(
            self.narrow_phase.query_dispatcher(),
            &self.bodies,
            &self.colliders,
            rf,
        ))
    }

    /// `cast_ray_and_get_normal`, solid, `direction` of unit length.
    #[must_use]
    pub fn cast_ray(
        &self,
        origin: Vec2,
        direction: Vec2,
        max_distance: f64,
        filter: &QueryFilter,
    ) -> Option<ReferenceRayHit> {
        let ray = Ray::new(to_vector(origin), to_vector(direction));
        let (h, hit) = self.with_pipeline(filter, |p| {
            p.cast_ray_and_get_normal(&ray, max_distance, true)
        })?;
        Some(ReferenceRayHit {
            entity: self.entities[self.index(h)?],
            distance: hit.time_of_impact,
            normal: from_vector(hit.normal),
        })
    }

    /// `intersect_ray`, solid: every body the ray hits, sorted by distance then entity.
    #[must_use]
    pub fn cast_ray_all(
        &self,
        origin: Vec2,
        direction: Vec2,
        max_distance: f64,
        filter: &QueryFilter,
    ) -> Vec<ReferenceRayHit> {
        let ray = Ray::new(to_vector(origin), to_vector(direction));
        let mut all: Vec<ReferenceRayHit> = self.with_pipeline(filter, |p| {
            p.intersect_ray(ray, max_distance, true)
                .filter_map(|(h, _, hit)| {
                    Some(ReferenceRayHit {
                        entity: self.entities[self.index(h)?],
                        distance: hit.time_of_impact,
                        normal: from_vector(hit.normal),
                    })
                })
                .collect()
        });
        all.sort_by(|a, b| {
            a.distance
                .total_cmp(&b.distance)
                .then(a.entity.cmp(&b.entity))
        });
        all
    }

    /// `intersect_point`, in id order.
    #[must_use]
    pub fn overlap_point(&self, point: Vec2, filter: &QueryFilter) -> Vec<Entity> {
        let mut out: Vec<Entity> = self.with_pipeline(filter, |p| {
            p.intersect_point(to_vector(point))
                .filter_map(|(h, _)| Some(self.entities[self.index(h)?]))
                .collect()
        });
        out.sort_unstable();
        out
    }

    /// `intersect_aabb_conservative` (BVH boxes), then parry's exact intersection test of
    /// the box against each candidate, in id order.
    #[must_use]
    pub fn overlap_aabb(&self, bounds: Bounds, filter: &QueryFilter) -> Vec<Entity> {
        let aabb = Aabb::new(to_vector(bounds.min), to_vector(bounds.max));
        let cuboid = Cuboid::new(to_vector(bounds.half_extents()));
        let at = PPose::from_translation(to_vector(bounds.center()));
        let mut out: Vec<Entity> = self.with_pipeline(filter, |p| {
            p.intersect_aabb_conservative(aabb)
                .filter(|(_, c)| {
                    rapier2d_f64::parry::query::intersection_test(
                        &at,
                        &cuboid,
                        c.position(),
                        c.shape(),
                    )
                    .is_ok_and(|hit| hit.intersecting)
                })
                .filter_map(|(h, _)| Some(self.entities[self.index(h)?]))
                .collect()
        });
        out.sort_unstable();
        out
    }

    /// `intersect_shape` with each part of `shape` at `pose`, joined, in id order.
    pub fn overlap_shape(
        &self,
        shape: &Shape,
        pose: Pose,
        filter: &QueryFilter,
    ) -> Result<Vec<Entity>, OracleError> {
        let mut out = Vec::new();
        for (at, part) in parts(shape, pose)? {
            self.with_pipeline(filter, |p| {
                out.extend(
                    p.intersect_shape(at, &*part)
                        .filter_map(|(h, _)| Some(self.entities[self.index(h)?])),
                );
            });
        }
        out.sort_unstable();
        out.dedup();
        Ok(out)
    }

    /// `cast_shape` of each part of `shape` from `pose` along `translation` (time of
    /// impact as a fraction of it, stopping at penetration): the earliest, and its body.
    pub fn cast_shape(
        &self,
        shape: &Shape,
        pose: Pose,
        translation: Vec2,
        filter: &QueryFilter,
    ) -> Result<Option<(Entity, f64)>, OracleError> {
        let options = ShapeCastOptions {
            max_time_of_impact: 1.0,
            target_distance: 0.0,
            stop_at_penetration: true,
            compute_impact_geometry_on_penetration: false,
        };
        let mut best: Option<(Entity, f64)> = None;
        for (at, part) in parts(shape, pose)? {
            let hit = self.with_pipeline(filter, |p| {
                p.cast_shape(&at, to_vector(translation), &*part, options)
            });
            if let Some((h, hit)) = hit
                && let Some(i) = self.index(h)
                && best.is_none_or(|(_, t)| hit.time_of_impact < t)
            {
                best = Some((self.entities[i], hit.time_of_impact));
            }
        }
        Ok(best)
    }

    /// Parry's exact depth of `shape` at `pose` against body `e` (`> 0` overlap, `< 0`
    /// minus the gap). The check of the `touching` rule and of a cast's stopping gap.
    ///
    /// `reference_contact` first (exact, capsules as core segments); when parry's GJK
    /// answers "proximity" (shapes within its own epsilon of touching, where `contact` gives
    /// no answer), minus parry's `distance` between the closest parts.
    pub fn depth(&self, shape: &Shape, pose: Pose, e: Entity) -> Result<f64, OracleError> {
        let Some((body, at)) = self.body(e) else {
            return Ok(f64::NEG_INFINITY);
        };
        if let Some(c) = reference_contact(shape, &pose, body, &at, 1.0)? {
            return Ok(c.depth);
        }
        let mut gap = f64::INFINITY;
        for (pa, sa) in parts(shape, pose)? {
            for (pb, sb) in parts(body, at)? {
                let d = rapier2d_f64::parry::query::distance(&pa, &*sa, &pb, &*sb)
                    .map_err(|_| OracleError::Conversion("parry has no distance query"))?;
                gap = gap.min(d.distance);
            }
        }
        Ok(-gap)
    }

    /// Parry's depth of the segment from `a` to `b` against body `e` (a ray as the segment
    /// it sweeps): about 0 when the ray grazes the body or ends on its boundary. The check
    /// of the `grazing` rule.
    pub fn segment_depth(&self, a: Vec2, b: Vec2, e: Entity) -> Result<f64, OracleError> {
        let Some((body, at)) = self.body(e) else {
            return Ok(f64::NEG_INFINITY);
        };
        // The segment as a zero-radius capsule, which `reference_contact` queries as its
        // core segment: exact.
        let mid = (a + b) * 0.5;
        let seg = Shape::capsule(a - mid, b - mid, ricochet_geom::MIN_SIZE)
            .map_err(|_| OracleError::Conversion("degenerate ray segment"))?;
        Ok(
            reference_contact(&seg, &Pose::new(mid, 0.0), body, &at, 1.0)?
                .map_or(f64::NEG_INFINITY, |c| c.depth - ricochet_geom::MIN_SIZE),
        )
    }

    /// Parry's signed distance from `point` to body `e`'s boundary (`< 0` inside), part by
    /// part: inside some part, minus the largest distance to the boundary of a part holding
    /// it; else the distance to the nearest part. (Parry's own compound projection takes the
    /// nearest part boundary, which may be another part's outside.) The check of the
    /// `boundary` rule.
    pub fn point_distance(&self, point: Vec2, e: Entity) -> Result<f64, OracleError> {
        let Some((body, at)) = self.body(e) else {
            return Ok(f64::INFINITY);
        };
        let (mut inside, mut outside) = (f64::NEG_INFINITY, f64::INFINITY);
        for (p, s) in parts(body, at)? {
            let proj = s.project_point(&p, to_vector(point), false);
            let d = (from_vector(proj.point) - point).length();
            if proj.is_inside {
                inside = inside.max(d);
            } else {
                outside = outside.min(d);
            }
        }
        Ok(if inside > f64::NEG_INFINITY {
            -inside
        } else {
            outside
        })
    }
}

/// The parts of a query shape placed in world coordinates (one for a primitive).
fn parts(shape: &Shape, pose: Pose) -> Result<Vec<(PPose, SharedShape)>, OracleError> {
    let (at, s) = place(shape, &pose, Vec2::ZERO)?;
    Ok(match s.as_compound() {
        Some(c) => c.shapes().to_vec(),
        None => vec![(at, s)],
    })
}
