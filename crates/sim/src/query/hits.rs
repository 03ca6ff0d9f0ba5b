//! What a cast reports: [`RayHit`] and [`ShapeHit`].

use ricochet_geom::Vec2;

use crate::entity::Entity;

/// Where a ray met a body (Box2D's `b2RayResult`, rapier's `RayIntersection` with its
/// collider).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayHit {
    /// The body hit.
    pub entity: Entity,
    /// The point hit, in world coordinates (in a wrap world, on the ray as it went on from
    /// the edge it crossed, inside the world: where the body's image is).
    pub point: Vec2,
    /// The body's outward unit normal at `point` (against the ray), or zero for a ray that
    /// starts inside the body (rapier's `solid = true` answer).
    pub normal: Vec2,
    /// Distance from the ray's origin along its unit direction (accumulated across wrap
    /// edges), `0` for a ray starting inside.
    pub distance: f64,
}

/// Where a swept shape first touched a body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeHit {
    /// The body touched.
    pub entity: Entity,
    /// The fraction of the translation travelled when it touched, in `0..=1` (`0`: it
    /// already overlaps there).
    pub fraction: f64,
    /// The contact point then, in world coordinates.
    pub point: Vec2,
    /// The unit contact normal then, from the cast shape towards the body.
    pub normal: Vec2,
}
