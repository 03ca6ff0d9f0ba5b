//! The narrow phase: one pure function per pairing (`collide_<a>_<b>`, `overlaps_<a>_<b>`),
//! and the one dispatch that routes a pair to it, flipping the result when the pair comes in
//! the other order.

pub(crate) mod aabb_aabb;
pub(crate) mod aabb_capsule;
pub(crate) mod aabb_obb;
pub(crate) mod aabb_polygon;
pub(crate) mod capsule_capsule;
pub(crate) mod capsule_polygon;
pub(crate) mod circle_aabb;
pub(crate) mod circle_capsule;
pub(crate) mod circle_circle;
pub(crate) mod circle_obb;
pub(crate) mod circle_polygon;
pub(crate) mod obb_capsule;
pub(crate) mod obb_obb;
pub(crate) mod obb_polygon;
pub(crate) mod polygon_polygon;

use crate::contact::Contact;
use crate::math::Pose;
use crate::placed::{PlacedPrimitive, place_with};
use crate::shape::{Shape, ShapeKind};

use aabb_aabb::*;
use aabb_capsule::*;
use aabb_obb::*;
use aabb_polygon::*;
use capsule_capsule::*;
use capsule_polygon::*;
use circle_aabb::*;
use circle_capsule::*;
use circle_circle::*;
use circle_obb::*;
use circle_polygon::*;
use obb_capsule::*;
use obb_obb::*;
use obb_polygon::*;
use polygon_polygon::*;

/// The contact of two primitives placed in one frame. The point is in that frame.
#[must_use]
pub fn contact_placed(a: &PlacedPrimitive, b: &PlacedPrimitive) -> Contact {
    use PlacedPrimitive as P;
    match (a, b) {
        (P::Circle(a), P::Circle(b)) => collide_circle_circle(a, b),
        (P::Circle(a), P::Aabb(b)) => collide_circle_aabb(a, b),
        (P::Circle(a), P::Obb(b)) => collide_circle_obb(a, b),
        (P::Circle(a), P::Capsule(b)) => collide_circle_capsule(a, b),
        (P::Circle(a), P::Polygon(b)) => collide_circle_polygon(a, b),
        (P::Aabb(a), P::Circle(b)) => collide_circle_aabb(b, a).flipped(),
        (P::Aabb(a), P::Aabb(b)) => collide_aabb_aabb(a, b),
        (P::Aabb(a), P::Obb(b)) => collide_aabb_obb(a, b),
        (P::Aabb(a), P::Capsule(b)) => collide_aabb_capsule(a, b),
        (P::Aabb(a), P::Polygon(b)) => collide_aabb_polygon(a, b),
        (P::Obb(a), P::Circle(b)) => collide_circle_obb(b, a).flipped(),
        (P::Obb(a), P::Aabb(b)) => collide_aabb_obb(b, a).flipped(),
        (P::Obb(a), P::Obb(b)) => collide_obb_obb(a, b),
        (P::Obb(a), P::Capsule(b)) => collide_obb_capsule(a, b),
        (P::Obb(a), P::Polygon(b)) => collide_obb_polygon(a, b),
        (P::Capsule(a), P::Circle(b)) => collide_circle_capsule(b, a).flipped(),
        (P::Capsule(a), P::Aabb(b)) => collide_aabb_capsule(b, a).flipped(),
        (P::Capsule(a), P::Obb(b)) => collide_obb_capsule(b, a).flipped(),
        (P::Capsule(a), P::Capsule(b)) => collide_capsule_capsule(a, b),
        (P::Capsule(a), P::Polygon(b)) => collide_capsule_polygon(a, b),
        (P::Polygon(a), P::Circle(b)) => collide_circle_polygon(b, a).flipped(),
        (P::Polygon(a), P::Aabb(b)) => collide_aabb_polygon(b, a).flipped(),
        (P::Polygon(a), P::Obb(b)) => collide_obb_polygon(b, a).flipped(),
        (P::Polygon(a), P::Capsule(b)) => collide_capsule_polygon(b, a).flipped(),
        (P::Polygon(a), P::Polygon(b)) => collide_polygon_polygon(a, b),
    }
}

/// Whether two primitives placed in one frame overlap; the same answer as
/// `contact_placed(a, b).overlaps()` but cheaper.
#[must_use]
pub fn overlaps_placed(a: &PlacedPrimitive, b: &PlacedPrimitive) -> bool {
    use PlacedPrimitive as P;
    match (a, b) {
        (P::Circle(a), P::Circle(b)) => overlaps_circle_circle(a, b),
        (P::Circle(a), P::Aabb(b)) | (P::Aabb(b), P::Circle(a)) => overlaps_circle_aabb(a, b),
        (P::Circle(a), P::Obb(b)) | (P::Obb(b), P::Circle(a)) => overlaps_circle_obb(a, b),
        (P::Circle(a), P::Capsule(b)) | (P::Capsule(b), P::Circle(a)) => {
            overlaps_circle_capsule(a, b)
        }
        (P::Circle(a), P::Polygon(b)) | (P::Polygon(b), P::Circle(a)) => {
            overlaps_circle_polygon(a, b)
        }
        (P::Aabb(a), P::Aabb(b)) => overlaps_aabb_aabb(a, b),
        (P::Aabb(a), P::Obb(b)) | (P::Obb(b), P::Aabb(a)) => overlaps_aabb_obb(a, b),
        (P::Aabb(a), P::Capsule(b)) | (P::Capsule(b), P::Aabb(a)) => overlaps_aabb_capsule(a, b),
        (P::Aabb(a), P::Polygon(b)) | (P::Polygon(b), P::Aabb(a)) => overlaps_aabb_polygon(a, b),
        (P::Obb(a), P::Obb(b)) => overlaps_obb_obb(a, b),
        (P::Obb(a), P::Capsule(b)) | (P::Capsule(b), P::Obb(a)) => overlaps_obb_capsule(a, b),
        (P::Obb(a), P::Polygon(b)) | (P::Polygon(b), P::Obb(a)) => overlaps_obb_polygon(a, b),
        (P::Capsule(a), P::Capsule(b)) => overlaps_capsule_capsule(a, b),
        (P::Capsule(a), P::Polygon(b)) | (P::Polygon(b), P::Capsule(a)) => {
            overlaps_capsule_polygon(a, b)
        }
        (P::Polygon(a), P::Polygon(b)) => overlaps_polygon_polygon(a, b),
    }
}

/// The contact of two shapes at two poses. The pair is computed in a frame centred on
/// `pose_a`, so accuracy does not depend on the distance from the world origin; the returned
/// point is in world coordinates.
///
/// For a compound, every part of one shape is tested against every part of the other and the
/// deepest contact is returned (the nearest when none overlaps). The distance between two
/// compounds is exact; for overlapping compounds the deepest part pair is what Box2D and
/// rapier resolve too, though the union's true minimum translation may be longer.
#[must_use]
pub fn contact(a: &Shape, pose_a: &Pose, b: &Shape, pose_b: &Pose) -> Contact {
    let origin = pose_a.position;
    let (rot_a, rot_b) = (a.rotation(pose_a.angle), b.rotation(pose_b.angle));
    let offset_b = pose_b.position - origin;
    let mut best: Option<Contact> = None;
    for pa in a.primitives() {
        let pa = place_with(pa, glam::DVec2::ZERO, rot_a, pose_a.angle);
        for pb in b.primitives() {
            let pb = place_with(pb, offset_b, rot_b, pose_b.angle);
            let c = contact_placed(&pa, &pb);
            if best.is_none_or(|best| c.depth > best.depth) {
                best = Some(c);
            }
        }
    }
    // Shapes always have at least one primitive (validated on construction).
    best.map_or(
        Contact {
            depth: f64::NEG_INFINITY,
            normal: glam::DVec2::Y,
            point: origin,
        },
        |c| c.translated(origin),
    )
}

/// Whether two shapes at two poses overlap: any part of one with any part of the other.
#[must_use]
pub fn overlaps(a: &Shape, pose_a: &Pose, b: &Shape, pose_b: &Pose) -> bool {
    let origin = pose_a.position;
    let (rot_a, rot_b) = (a.rotation(pose_a.angle), b.rotation(pose_b.angle));
    let offset_b = pose_b.position - origin;
    a.primitives().iter().any(|pa| {
        let pa = place_with(pa, glam::DVec2::ZERO, rot_a, pose_a.angle);
        b.primitives()
            .iter()
            .any(|pb| overlaps_placed(&pa, &place_with(pb, offset_b, rot_b, pose_b.angle)))
    })
}

/// The name of a pairing as the shared cases spell it, in canonical order
/// (`circle-aabb`, never `aabb-circle`).
#[must_use]
pub fn pair_name(a: ShapeKind, b: ShapeKind) -> String {
    let (a, b) = if a <= b { (a, b) } else { (b, a) };
    format!("{}-{}", a.name(), b.name())
}
