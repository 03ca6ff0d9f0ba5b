//! Overlap queries: the bodies at a point, in a box, or overlapping a shape.

use ricochet_geom::{
    Bounds, MAX_COORDINATE, PlacedAabb, PlacedPrimitive, Pose, Shape, Vec2, contains_point,
    overlaps, overlaps_placed, place,
};

use super::QueryFilter;
use super::shapes::in_range;
use crate::entity::Entity;
use crate::pipeline::Simulation;

impl Simulation {
    /// The bodies with `point` strictly inside (a point on a body's boundary is not: touching
    /// is not overlapping, as for [`ricochet_geom::overlaps`]), in id order. In a wrap world
    /// a body counts when any of its images holds the point. Empty for a point that is not
    /// finite or beyond [`ricochet_geom::MAX_COORDINATE`].
    #[must_use]
    pub fn overlap_point(&self, point: Vec2, filter: &QueryFilter) -> Vec<Entity> {
        if !in_range(point) {
            return Vec::new();
        }
        let w = &self.world;
        let region = Bounds {
            min: point,
            max: point,
        };
        let mut found = Vec::new();
        self.region_candidates(&region, filter, |i, offset| {
            if contains_point(w.shape(i), &w.pose(i), point - offset) {
                found.push(i);
            }
        });
        self.entities(found)
    }

    /// The bodies whose shape overlaps the box `bounds` (exact shape-against-box, not
    /// bounds against bounds; touching is not overlapping), in id order (Box2D's
    /// `b2World_OverlapAABB`, which tests bounds only). A box of zero width or height is a
    /// segment or a point. In a wrap world a body counts when any of its images overlaps.
    /// Empty for a box that is not finite, inverted (`min > max` on an axis), or beyond
    /// [`ricochet_geom::MAX_COORDINATE`].
    #[must_use]
    pub fn overlap_aabb(&self, bounds: Bounds, filter: &QueryFilter) -> Vec<Entity> {
        let ok = in_range(bounds.min)
            && in_range(bounds.max)
            && bounds.min.x <= bounds.max.x
            && bounds.min.y <= bounds.max.y;
        if !ok {
            return Vec::new();
        }
        let (center, half) = (bounds.center(), bounds.half_extents());
        debug_assert!(half.max_element() <= MAX_COORDINATE);
        let w = &self.world;
        let mut found = Vec::new();
        self.region_candidates(&bounds, filter, |i, offset| {
            let pose = w.pose(i);
            // In a frame centred on the body, as the narrow phase works.
            let query = PlacedPrimitive::Aabb(PlacedAabb {
                center: center - offset - pose.position,
                half,
            });
            let hit = w
                .shape(i)
                .primitives()
                .iter()
                .any(|p| overlaps_placed(&query, &place(p, &pose, pose.position)));
            if hit {
                found.push(i);
            }
        });
        self.entities(found)
    }

    /// The bodies that `shape` at `pose` overlaps ([`ricochet_geom::overlaps`]: touching is
    /// not overlapping), in id order (rapier's `intersections_with_shape`). In a wrap world
    /// a body counts when any of its images overlaps. Empty for a pose that is not finite
    /// or beyond [`ricochet_geom::MAX_COORDINATE`].
    #[must_use]
    pub fn overlap_shape(&self, shape: &Shape, pose: Pose, filter: &QueryFilter) -> Vec<Entity> {
        if !(in_range(pose.position) && pose.angle.is_finite()) {
            return Vec::new();
        }
        let region = shape.bounds(&pose);
        let w = &self.world;
        let mut found = Vec::new();
        self.region_candidates(&region, filter, |i, offset| {
            let moved = Pose::new(pose.position - offset, pose.angle);
            if overlaps(shape, &moved, w.shape(i), &w.pose(i)) {
                found.push(i);
            }
        });
        self.entities(found)
    }

    /// Dense indices, any order and repeats, to entities in id order, each once.
    fn entities(&self, mut found: Vec<usize>) -> Vec<Entity> {
        found.sort_unstable();
        found.dedup();
        found.into_iter().map(|i| self.world.entity[i]).collect()
    }
}
