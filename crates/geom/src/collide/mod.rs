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
pub(crate) mod compound;
pub(crate) mod obb_capsule;
pub(crate) mod obb_obb;
pub(crate) mod obb_polygon;
pub(crate) mod polygon_polygon;
pub(crate) mod segment;

use crate::contact::Contact;
use crate::cores::collide_cores_unless;
use crate::math::{Pose, Rot, Vec2};
use crate::placed::{PlacedPrimitive, place_aabb, place_rotated};
use crate::shape::{Primitive, Shape, ShapeKind};

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
use segment::collide_segment;

/// The contact of two primitives placed in one frame. The point is in that frame.
#[must_use]
pub fn contact_placed(a: &PlacedPrimitive, b: &PlacedPrimitive) -> Contact {
    use PlacedPrimitive as P;
    match (a, b) {
        // A chain segment: any body's core against it, then the joint rule. Two segments
        // (a chain is static, so only in direct geometry calls) use `a` as a plain segment.
        (_, P::Segment(s)) => collide_segment(&a.core(), s),
        (P::Segment(s), _) => collide_segment(&b.core(), s).flipped(),
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

/// `contact_placed(a, b)`, with the same bits; or `None` when a separating axis alone shows
/// that its depth is at most `threshold` (the pairings the core algorithm answers; the others
/// are cheap and always computed).
pub(crate) fn contact_placed_unless(
    a: &PlacedPrimitive,
    b: &PlacedPrimitive,
    threshold: f64,
) -> Option<Contact> {
    use PlacedPrimitive as P;
    // `contact_placed`'s calls of `collide_cores`, in the same order.
    let cores = |x: &PlacedPrimitive, y: &PlacedPrimitive| {
        collide_cores_unless(&x.core(), &y.core(), threshold)
    };
    match (a, b) {
        (P::Circle(_), P::Circle(_) | P::Aabb(_) | P::Obb(_))
        | (P::Aabb(_) | P::Obb(_), P::Circle(_))
        | (P::Aabb(_), P::Aabb(_))
        | (P::Segment(_), _)
        | (_, P::Segment(_)) => Some(contact_placed(a, b)),
        (P::Circle(_), P::Capsule(_) | P::Polygon(_))
        | (P::Aabb(_), P::Obb(_) | P::Capsule(_) | P::Polygon(_))
        | (P::Obb(_), P::Obb(_) | P::Capsule(_) | P::Polygon(_))
        | (P::Capsule(_), P::Capsule(_) | P::Polygon(_))
        | (P::Polygon(_), P::Polygon(_)) => cores(a, b),
        (P::Obb(_), P::Aabb(_))
        | (P::Capsule(_), P::Circle(_) | P::Aabb(_) | P::Obb(_))
        | (P::Polygon(_), P::Circle(_) | P::Aabb(_) | P::Obb(_) | P::Capsule(_)) => {
            cores(b, a).map(Contact::flipped)
        }
    }
}

/// `overlaps_placed(a, &place_rotated(b, position, rot, angle))`, the same answer from the
/// same arithmetic, with the commonest pair of a box query (two axis-aligned boxes: a
/// query box against a tile) placed and tested inline.
#[must_use]
#[inline]
pub fn overlaps_placing(
    a: &PlacedPrimitive,
    b: &Primitive,
    position: Vec2,
    rot: Rot,
    angle: f64,
) -> bool {
    if let (PlacedPrimitive::Aabb(a), Primitive::Aabb(b)) = (a, b) {
        return overlaps_aabb_aabb(a, &place_aabb(b, position, rot));
    }
    overlaps_placed(a, &place_rotated(b, position, rot, angle))
}

/// Whether two primitives placed in one frame overlap; the same answer as
/// `contact_placed(a, b).overlaps()` but cheaper.
#[must_use]
pub fn overlaps_placed(a: &PlacedPrimitive, b: &PlacedPrimitive) -> bool {
    use PlacedPrimitive as P;
    match (a, b) {
        (P::Segment(_), _) | (_, P::Segment(_)) => contact_placed(a, b).overlaps(),
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
/// For a compound, the deepest contact of a part of one shape with a part of the other is
/// returned (the nearest when none overlaps; the first in part order among equals). Only
/// the part pairs near each other are tested, culled by their bounds, with the same answer
/// as testing every pair. The distance between two compounds is exact; for overlapping
/// compounds the deepest part pair is what Box2D and rapier resolve too, though the union's
/// true minimum translation may be longer.
#[must_use]
pub fn contact(a: &Shape, pose_a: &Pose, b: &Shape, pose_b: &Pose) -> Contact {
    let origin = pose_a.position;
    let (sa, sb) = sides(a, pose_a, b, pose_b);
    // Shapes always have at least one primitive (validated on construction).
    compound::deepest(sa, sb).map_or(
        Contact {
            depth: f64::NEG_INFINITY,
            normal: glam::DVec2::Y,
            point: origin,
        },
        |c| c.translated(origin),
    )
}

/// `Some(contact(a, pose_a, b, pose_b))` when its depth is above `threshold`, `None`
/// otherwise: the same bits, cheaper for a pair apart (what a broad phase hands over when
/// bounds overlap and shapes don't). A separating axis along which the pair is further apart
/// than `-threshold` (plus a margin far above rounding) rules it out before the exact
/// algorithm's closest-point scan.
///
/// `contact_deeper_than(.., 0.0)` is the contact of an overlapping pair, `None` for a pair
/// apart or touching.
#[must_use]
pub fn contact_deeper_than(
    a: &Shape,
    pose_a: &Pose,
    b: &Shape,
    pose_b: &Pose,
    threshold: f64,
) -> Option<Contact> {
    let origin = pose_a.position;
    let (sa, sb) = sides(a, pose_a, b, pose_b);
    compound::deepest_above(sa, sb, threshold).map(|c| c.translated(origin))
}

/// Whether two shapes at two poses overlap: any part of one with any part of the other.
#[must_use]
pub fn overlaps(a: &Shape, pose_a: &Pose, b: &Shape, pose_b: &Pose) -> bool {
    let (sa, sb) = sides(a, pose_a, b, pose_b);
    compound::any_overlap(sa, sb)
}

/// The two shapes of a pair, placed in the frame centred on `pose_a`.
fn sides<'s>(
    a: &'s Shape,
    pose_a: &Pose,
    b: &'s Shape,
    pose_b: &Pose,
) -> (compound::Side<'s>, compound::Side<'s>) {
    let side = |s: &'s Shape, pose: &Pose, position| compound::Side {
        parts: s.primitives(),
        position,
        rot: s.rotation(pose.angle),
        angle: pose.angle,
    };
    (
        side(a, pose_a, glam::DVec2::ZERO),
        side(b, pose_b, pose_b.position - pose_a.position),
    )
}

/// The name of a pairing as the shared cases spell it, in canonical order
/// (`circle-aabb`, never `aabb-circle`).
#[must_use]
pub fn pair_name(a: ShapeKind, b: ShapeKind) -> String {
    let (a, b) = if a <= b { (a, b) } else { (b, a) };
    format!("{}-{}", a.name(), b.name())
}
