//! Shape casts: the first body a shape moving in a straight line touches.

use ricochet_geom::{MAX_COORDINATE, Pose, Shape, Sweep, Vec2, time_of_impact};

use super::{QueryFilter, ShapeHit};
use crate::pipeline::Simulation;

/// Whether `v` is a coordinate the geometry accepts.
pub(super) fn in_range(v: Vec2) -> bool {
    v.is_finite() && v.abs().max_element() <= MAX_COORDINATE
}

impl Simulation {
    /// The first body that `shape`, moved from `pose` by `translation` (without turning),
    /// touches on the way (Box2D's `b2World_CastShape`, rapier's
    /// `QueryPipeline::cast_shape`): [`ricochet_geom::time_of_impact`] with the cast shape
    /// swept and each body still, so touching is within `1e-9` of the smaller shape's size,
    /// and a shape overlapping a body at `pose` hits it at fraction 0. Ties go to the lower
    /// entity. A zero translation is an overlap test at `pose`.
    ///
    /// `None` for a miss, and for bad input: a pose or translation that is not finite or
    /// beyond [`ricochet_geom::MAX_COORDINATE`].
    #[must_use]
    pub fn cast_shape(
        &self,
        shape: &Shape,
        pose: Pose,
        translation: Vec2,
        filter: &QueryFilter,
    ) -> Option<ShapeHit> {
        let end = pose.position + translation;
        if !(in_range(pose.position) && in_range(end) && pose.angle.is_finite()) {
            return None;
        }
        let region = shape
            .bounds(&pose)
            .union(shape.bounds(&Pose::new(end, pose.angle)));
        let w = &self.world;
        let mut best: Option<ShapeHit> = None;
        self.region_candidates(&region, filter, |i, offset| {
            // The cast shape moved back by the image's offset meets the body itself.
            let start = pose.position - offset;
            let sweep = Sweep {
                start,
                end: start + translation,
                angle: pose.angle,
            };
            let p = w.position[i];
            let still = Sweep {
                start: p,
                end: p,
                angle: w.angle[i],
            };
            let Some(hit) = time_of_impact(shape, &sweep, w.shape(i), &still) else {
                return;
            };
            let e = w.entity[i];
            let better = best
                .is_none_or(|b| hit.t < b.fraction || (hit.t == b.fraction && e < b.entity));
            if better {
                best = Some(ShapeHit {
                    entity: e,
                    fraction: hit.t,
                    point: hit.contact.point,
                    normal: hit.contact.normal,
                });
            }
        });
        best
    }
}
