//! Ricochet shapes as parry shapes, placed the way `ricochet_geom`'s `place_with` places them,
//! and rapier's contact expressed in Ricochet's conventions.
//!
//! Every primitive becomes one parry shape with its own pose in a frame whose origin is a
//! world point chosen by the caller (body `a`'s position for a pair, as Ricochet does):
//!
//! | Ricochet | parry shape | parry pose |
//! |---|---|---|
//! | circle | `Ball(radius)` | `p + R(θ)·center`, no rotation |
//! | aabb | `Cuboid(half_extents)` | `p + R(θ)·center`, **no rotation** (an AABB ignores the body angle) |
//! | obb | `Cuboid(half_extents)` | `p + R(θ)·center`, rotation `θ + angle` |
//! | capsule | `Capsule(a, b, radius)` (local ends) | `p`, rotation `θ` |
//! | polygon | `ConvexPolygon` (local vertices, unmodified) | `p`, rotation `θ` |
//! | compound | `Compound` of the above | the frame's origin (parts carry their own poses) |
//!
//! `R(θ)` is `ricochet_geom::Rot::from_angle` (libm), handed to parry as its cosine and sine,
//! so both engines place every shape with the same bits; what is compared is the narrow phase.

use rapier2d_f64::math::{Pose as PPose, Rot2, Vector};
use rapier2d_f64::parry::query::{self, ShapeCastOptions};
use rapier2d_f64::parry::shape::SharedShape;
use ricochet_geom::{Pose, Primitive, Rot, Shape, Vec2};

use crate::OracleError;

/// A Ricochet vector as a parry vector.
pub(crate) fn to_vector(v: Vec2) -> Vector {
    Vector::new(v.x, v.y)
}

/// A parry vector as a Ricochet vector.
pub(crate) fn from_vector(v: Vector) -> Vec2 {
    Vec2::new(v.x, v.y)
}

fn to_rot(r: Rot) -> Rot2 {
    Rot2::from_cos_sin_unchecked(r.c, r.s)
}

/// One primitive at `position` (already relative to the frame's origin) with the body
/// rotation `rot` and angle `angle`: its parry pose and local parry shape.
fn primitive(
    p: &Primitive,
    position: Vec2,
    rot: Rot,
    angle: f64,
) -> Result<(PPose, SharedShape), OracleError> {
    Ok(match p {
        Primitive::Circle(c) => (
            PPose::from_translation(to_vector(position + rot.apply(c.center))),
            SharedShape::ball(c.radius),
        ),
        Primitive::Aabb(b) => (
            PPose::from_translation(to_vector(position + rot.apply(b.center))),
            SharedShape::cuboid(b.half_extents.x, b.half_extents.y),
        ),
        Primitive::Obb(b) => {
            let own = if b.angle == 0.0 {
                rot
            } else {
                Rot::from_angle(angle + b.angle)
            };
            (
                PPose::from_parts(to_vector(position + rot.apply(b.center)), to_rot(own)),
                SharedShape::cuboid(b.half_extents.x, b.half_extents.y),
            )
        }
        Primitive::Capsule(c) => (
            PPose::from_parts(to_vector(position), to_rot(rot)),
            SharedShape::capsule(to_vector(c.a), to_vector(c.b), c.radius),
        ),
        Primitive::Polygon(poly) => {
            let vs = poly.vertices().iter().map(|v| to_vector(*v)).collect();
            let shape = SharedShape::convex_polyline_unmodified(vs).ok_or(
                OracleError::Conversion("polygon rejected by parry (degenerate edge)"),
            )?;
            (PPose::from_parts(to_vector(position), to_rot(rot)), shape)
        }
        // One segment of a chain, without Ricochet's joint rule (parry has none).
        Primitive::Segment(g) => (
            PPose::from_parts(to_vector(position), to_rot(rot)),
            SharedShape::segment(to_vector(g.a), to_vector(g.b)),
        ),
    })
}

/// `shape` at `pose`, in a frame whose origin is the world point `origin`: the parry pose
/// and shape to hand to rapier. A compound becomes a parry compound at the frame's origin
/// whose parts carry their own poses.
pub(crate) fn place(
    shape: &Shape,
    pose: &Pose,
    origin: Vec2,
) -> Result<(PPose, SharedShape), OracleError> {
    let position = pose.position - origin;
    let rot = shape.rotation(pose.angle);
    match shape {
        Shape::Primitive(p) => primitive(p, position, rot, pose.angle),
        // A terrain chain is parry's polyline (a line strip, two-sided like Ricochet's).
        Shape::Compound(c) if shape.is_chain() => {
            let mut points = Vec::with_capacity(c.parts().len() + 1);
            for (i, p) in c.parts().iter().enumerate() {
                if let Primitive::Segment(g) = p {
                    if i == 0 {
                        points.push(to_vector(g.a));
                    }
                    points.push(to_vector(g.b));
                }
            }
            Ok((
                PPose::from_parts(to_vector(position), to_rot(rot)),
                SharedShape::polyline(points, None),
            ))
        }
        Shape::Compound(c) => {
            let parts = c
                .parts()
                .iter()
                .map(|p| primitive(p, position, rot, pose.angle))
                .collect::<Result<Vec<_>, _>>()?;
            Ok((PPose::IDENTITY, SharedShape::compound(parts)))
        }
    }
}

/// Rapier's (parry's) answer for a pair, in Ricochet's conventions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReferenceContact {
    /// Penetration depth: parry's `-dist` (`> 0` overlap, `< 0` minus the gap).
    pub depth: f64,
    /// Unit normal from `a` to `b`: parry's `normal1` (outward from the first shape).
    pub normal: Vec2,
}

/// Parry's answer for `a` at `pose_a` against `b` at `pose_b`, both placed as Ricochet places
/// them, in a frame centred on `pose_a` (as Ricochet computes a pair).
///
/// Every part of `a` is tested against every part of `b` with parry's `query::contact`, and
/// the deepest answer wins: parry's own compound query does the same (its composite contact
/// keeps the part pair with the smallest `dist`). A capsule part is queried as its core
/// segment and the two radii are added to the depth afterwards (exact: a capsule is its
/// segment swept by the radius, so its signed distance to anything convex is the segment's
/// minus the radius). Queried as a `Capsule`, parry runs GJK/EPA on a curved support
/// function, which stops within about `1e-7` of the depth and `1e-5` rad of the normal; on the
/// segment it runs the same algorithms on a polytope, which are exact to rounding.
///
/// `prediction` is how far apart the shapes may be and still get an answer: `Ok(None)`
/// means they are further apart than that.
pub fn reference_contact(
    a: &Shape,
    pose_a: &Pose,
    b: &Shape,
    pose_b: &Pose,
    prediction: f64,
) -> Result<Option<ReferenceContact>, OracleError> {
    let mut best: Option<ReferenceContact> = None;
    for pa in a.primitives() {
        for pb in b.primitives() {
            let c = part_contact(a, pa, pose_a, b, pb, pose_b, prediction)?;
            if let Some(c) = c
                && best.is_none_or(|best| c.depth > best.depth)
            {
                best = Some(c);
            }
        }
    }
    Ok(best)
}

/// A primitive as parry queries it: the shape itself, or for a capsule its core segment
/// and the radius to add back.
fn core(
    p: &Primitive,
    position: Vec2,
    rot: Rot,
    angle: f64,
) -> Result<(PPose, SharedShape, f64), OracleError> {
    if let Primitive::Capsule(c) = p {
        return Ok((
            PPose::from_parts(to_vector(position), to_rot(rot)),
            SharedShape::segment(to_vector(c.a), to_vector(c.b)),
            c.radius,
        ));
    }
    let (pose, shape) = primitive(p, position, rot, angle)?;
    Ok((pose, shape, 0.0))
}

/// One part of `a` (body shape `sa`) against one part of `b` (body shape `sb`): the body
/// rotation comes from the whole body shape, as in Ricochet.
fn part_contact(
    sa: &Shape,
    pa: &Primitive,
    pose_a: &Pose,
    sb: &Shape,
    pb: &Primitive,
    pose_b: &Pose,
    prediction: f64,
) -> Result<Option<ReferenceContact>, OracleError> {
    let origin = pose_a.position;
    let (qa, ha, ra) = core(pa, Vec2::ZERO, sa.rotation(pose_a.angle), pose_a.angle)?;
    let (qb, hb, rb) = core(
        pb,
        pose_b.position - origin,
        sb.rotation(pose_b.angle),
        pose_b.angle,
    )?;
    let c = query::contact(&qa, &*ha, &qb, &*hb, prediction + ra + rb)
        .map_err(|_| OracleError::Unsupported(ricochet_geom::pair_name(pa.kind(), pb.kind())))?;
    Ok(c.map(|c| ReferenceContact {
        depth: -c.dist + ra + rb,
        normal: from_vector(c.normal1),
    }))
}

/// The name of a body's shape for pairing tables: the primitive kind, or `compound`.
pub(crate) fn shape_name(s: &Shape) -> &'static str {
    match s {
        Shape::Primitive(p) => p.kind().name(),
        Shape::Compound(_) => "compound",
    }
}

/// Half the diagonal of the shape's local bounding box: the size tolerances scale with (for
/// a compound, the box around all its parts).
pub(crate) fn size(s: &Shape) -> f64 {
    s.bounds(&Pose::default()).half_extents().length()
}

/// The pairing name of two shapes, in a fixed order (`circle-obb`, `aabb-compound`).
pub(crate) fn pairing(a: &Shape, b: &Shape) -> String {
    const ORDER: [&str; 6] = ["circle", "aabb", "obb", "capsule", "polygon", "compound"];
    let rank = |n: &str| ORDER.iter().position(|x| *x == n).unwrap_or(ORDER.len());
    let (x, y) = (shape_name(a), shape_name(b));
    if rank(x) <= rank(y) {
        format!("{x}-{y}")
    } else {
        format!("{y}-{x}")
    }
}

/// How far two shapes overlap along the direction `n` (from `a` to `b`): the length of the
/// projection interval they share, `max(a·n) - min(b·n)`, from parry's support functions.
/// For convex shapes this is never less than the penetration depth, and equals it exactly
/// when `n` is a minimum-translation direction.
pub(crate) fn overlap_along(
    a: &Primitive,
    pose_a: &Pose,
    b: &Primitive,
    pose_b: &Pose,
    n: Vec2,
) -> Result<f64, OracleError> {
    let origin = pose_a.position;
    let sa = Shape::Primitive(*a);
    let sb = Shape::Primitive(*b);
    let (pa, ha) = place(&sa, pose_a, origin)?;
    let (pb, hb) = place(&sb, pose_b, origin)?;
    let dir = to_vector(n);
    let (Some(ma), Some(mb)) = (ha.as_support_map(), hb.as_support_map()) else {
        return Err(OracleError::Conversion("shape without a support map"));
    };
    let top_a = ma.support_point(&pa, dir).dot(dir);
    let bottom_b = mb.support_point(&pb, -dir).dot(dir);
    Ok(top_a - bottom_b)
}

/// Parry's first time `t` in `[0, 1]` at which `a`, moving from `pose_a` by `t * da`, and
/// `b`, moving from `pose_b` by `t * db` (angles fixed), come within `target` of each other
/// (`Some(0.0)` when they already are). Part by part, capsules as their core segments with
/// the radii added to the target distance, the earliest part pair winning.
pub(crate) fn first_touch(
    a: &Shape,
    pose_a: &Pose,
    da: Vec2,
    b: &Shape,
    pose_b: &Pose,
    db: Vec2,
    target: f64,
) -> Result<Option<f64>, OracleError> {
    let origin = pose_a.position;
    let mut best: Option<f64> = None;
    for pa in a.primitives() {
        let (qa, ha, ra) = core(pa, Vec2::ZERO, a.rotation(pose_a.angle), pose_a.angle)?;
        for pb in b.primitives() {
            let (qb, hb, rb) = core(
                pb,
                pose_b.position - origin,
                b.rotation(pose_b.angle),
                pose_b.angle,
            )?;
            let options = ShapeCastOptions {
                max_time_of_impact: 1.0,
                target_distance: target + ra + rb,
                stop_at_penetration: true,
                compute_impact_geometry_on_penetration: false,
            };
            let hit =
                query::cast_shapes(&qa, to_vector(da), &*ha, &qb, to_vector(db), &*hb, options)
                    .map_err(|_| {
                        OracleError::Unsupported(ricochet_geom::pair_name(pa.kind(), pb.kind()))
                    })?;
            if let Some(hit) = hit
                && best.is_none_or(|t| hit.time_of_impact < t)
            {
                best = Some(hit.time_of_impact);
            }
        }
    }
    Ok(best)
}

/// Parry's depth of the pair at these poses (`-inf` when further apart than `prediction`).
pub(crate) fn depth(
    a: &Shape,
    pa: &Pose,
    b: &Shape,
    pb: &Pose,
    prediction: f64,
) -> Result<f64, OracleError> {
    Ok(reference_contact(a, pa, b, pb, prediction)?.map_or(f64::NEG_INFINITY, |r| r.depth))
}
