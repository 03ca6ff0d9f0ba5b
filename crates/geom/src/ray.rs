//! Rays against shapes: where a half-line first enters a shape, and whether a point is
//! inside one. Exact, like the narrow phase, and computed in a frame centred on the body
//! (the ray's origin minus the body's position), so a ray at `1e6` is answered as well as
//! the same ray at the origin.
//!
//! # Conventions (rapier's `cast_ray` with `solid = true`)
//! - Shapes are solid: a ray whose origin is strictly inside a shape hits it at distance 0,
//!   with a zero normal (there is no surface there to point out of; rapier gives
//!   `Vector::zeros()` too), and the point is the origin.
//! - Otherwise the hit is where the ray first reaches the shape's boundary (a ray that only
//!   grazes it, tangent to a circle or along a face, hits where it touches), the normal is
//!   the shape's outward unit normal there (against the ray), and the distance is measured
//!   along the unit direction: `point = origin + direction * distance`.
//! - "Inside" is strict, as [`crate::overlaps`] counts overlap (`depth > 0`): a point on the
//!   boundary is not contained ([`contains_point`]), and a ray starting on the boundary and
//!   heading in hits at 0 with the face's normal.

use crate::math::{Pose, Rot, Vec2};
use crate::placed::{
    PlacedAabb, PlacedCapsule, PlacedCircle, PlacedObb, PlacedPolygon, PlacedPrimitive,
    PlacedSegment, place,
};
use crate::shape::Shape;

/// A half-line: an origin and a unit direction. Built by [`Ray::new`], which normalises.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    origin: Vec2,
    direction: Vec2,
}

impl Ray {
    /// The ray from `origin` along `direction` (any length, normalised here). `None` when
    /// either is not finite or the direction is zero (or too small to normalise).
    #[must_use]
    pub fn new(origin: Vec2, direction: Vec2) -> Option<Ray> {
        if !origin.is_finite() || !direction.is_finite() {
            return None;
        }
        // Scaled first so that a tiny or huge direction normalises without under/overflow.
        let m = direction.abs().max_element();
        if m == 0.0 {
            return None;
        }
        let d = (direction / m).normalize();
        d.is_finite().then_some(Ray {
            origin,
            direction: d,
        })
    }

    /// The origin.
    #[must_use]
    pub fn origin(&self) -> Vec2 {
        self.origin
    }

    /// The unit direction.
    #[must_use]
    pub fn direction(&self) -> Vec2 {
        self.direction
    }

    /// The point at `distance` along the ray.
    #[must_use]
    pub fn point_at(&self, distance: f64) -> Vec2 {
        self.origin + self.direction * distance
    }

    /// The same ray with its origin moved by `offset`.
    #[must_use]
    pub fn translated(self, offset: Vec2) -> Ray {
        Ray {
            origin: self.origin + offset,
            ..self
        }
    }
}

/// Where a ray first meets a shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayIntersection {
    /// Distance along the ray's unit direction, in `[0, max_distance]`.
    pub distance: f64,
    /// The point hit, world coordinates (the origin for a ray starting inside).
    pub point: Vec2,
    /// The outward unit normal there, or zero for a ray starting inside the shape.
    pub normal: Vec2,
}

/// Where `ray` first meets `shape` placed at `pose`, if within `max_distance` (see the
/// module's conventions). For a compound, the earliest part hit (the first part on a tie).
/// `None` for a miss, or a `max_distance` that is negative or NaN.
#[must_use]
pub fn cast_ray(
    shape: &Shape,
    pose: &Pose,
    ray: &Ray,
    max_distance: f64,
) -> Option<RayIntersection> {
    if max_distance.is_nan() || max_distance < 0.0 || !pose.position.is_finite() {
        return None;
    }
    let origin = ray.origin - pose.position;
    let d = ray.direction;
    let mut best: Option<(f64, Vec2)> = None;
    for p in shape.primitives() {
        let placed = place(p, pose, pose.position);
        if let Some((t, n)) = cast_placed(&placed, origin, d, max_distance)
            && best.is_none_or(|(b, _)| t < b)
        {
            best = Some((t, n));
            if t == 0.0 {
                break;
            }
        }
    }
    best.map(|(t, normal)| RayIntersection {
        distance: t,
        point: if t == 0.0 {
            ray.origin
        } else {
            ray.point_at(t)
        },
        normal,
    })
}

/// Whether `point` is strictly inside `shape` at `pose` (a point on the boundary is not).
#[must_use]
pub fn contains_point(shape: &Shape, pose: &Pose, point: Vec2) -> bool {
    let p = point - pose.position;
    shape
        .primitives()
        .iter()
        .any(|prim| contains_placed(&place(prim, pose, pose.position), p))
}

/// Whether `p` is strictly inside the primitive, both in one frame.
#[must_use]
pub fn contains_placed(prim: &PlacedPrimitive, p: Vec2) -> bool {
    match prim {
        PlacedPrimitive::Circle(c) => (p - c.center).length_squared() < c.radius * c.radius,
        PlacedPrimitive::Aabb(b) => inside_box(p - b.center, b.half),
        PlacedPrimitive::Obb(b) => inside_box(b.rot.apply_inverse(p - b.center), b.half),
        PlacedPrimitive::Capsule(c) => segment_distance_squared(p, c.a, c.b) < c.radius * c.radius,
        // Zero thickness: no point is inside.
        PlacedPrimitive::Segment(_) => false,
        PlacedPrimitive::Polygon(g) => {
            (0..g.count).all(|i| g.normals[i].dot(p - g.vertices[i]) < 0.0)
        }
    }
}

fn inside_box(p: Vec2, half: Vec2) -> bool {
    p.x.abs() < half.x && p.y.abs() < half.y
}

/// The squared distance from `p` to the segment `a`–`b`.
fn segment_distance_squared(p: Vec2, a: Vec2, b: Vec2) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * t)).length_squared()
}

/// The ray `o + t d` (`d` unit) against one primitive in the same frame: the entry
/// distance in `[0, max]` and the normal there (zero when `o` is inside). What [`cast_ray`]
/// does for each part, for a caller that keeps its parts placed.
#[must_use]
pub fn cast_placed(prim: &PlacedPrimitive, o: Vec2, d: Vec2, max: f64) -> Option<(f64, Vec2)> {
    if contains_placed(prim, o) {
        return Some((0.0, Vec2::ZERO));
    }
    let hit = match prim {
        PlacedPrimitive::Circle(c) => ray_circle(c, o, d),
        PlacedPrimitive::Aabb(b) => ray_aabb(b, o, d),
        PlacedPrimitive::Obb(b) => ray_obb(b, o, d),
        PlacedPrimitive::Capsule(c) => ray_capsule(c, o, d),
        PlacedPrimitive::Polygon(g) => ray_polygon(g, o, d),
        PlacedPrimitive::Segment(s) => ray_segment(s, o, d),
    };
    hit.filter(|&(t, _)| t <= max)
}

/// Outside the disc: the nearer root, from the closest approach (no cancellation between
/// `|m|²` and `r²` when the ray starts far away).
fn ray_circle(c: &PlacedCircle, o: Vec2, d: Vec2) -> Option<(f64, Vec2)> {
    let m = o - c.center;
    let tc = -m.dot(d);
    if tc < 0.0 {
        // Heading away from the centre, from outside (or the boundary): it only gets
        // further.
        return None;
    }
    let q = m + d * tc;
    let h2 = c.radius * c.radius - q.length_squared();
    if h2 < 0.0 {
        return None;
    }
    let t = (tc - h2.sqrt()).max(0.0);
    let n = (m + d * t).normalize_or_zero();
    Some((t, n))
}

/// The slab test against the box of half extents `half` centred on the origin of `o`'s
/// frame: the entry distance and the face's outward normal.
fn slab(o: Vec2, d: Vec2, half: Vec2) -> Option<(f64, Vec2)> {
    let mut enter = f64::NEG_INFINITY;
    let mut exit = f64::INFINITY;
    let mut normal = Vec2::ZERO;
    for axis in 0..2 {
        let (ok, dk, hk) = (o[axis], d[axis], half[axis]);
        if dk == 0.0 {
            if ok.abs() > hk {
                return None;
            }
            continue;
        }
        let t1 = (-hk - ok) / dk;
        let t2 = (hk - ok) / dk;
        let (near, far) = if t1 < t2 { (t1, t2) } else { (t2, t1) };
        if near > enter {
            enter = near;
            normal = Vec2::ZERO;
            normal[axis] = -dk.signum();
        }
        exit = exit.min(far);
    }
    (enter >= 0.0 && enter <= exit).then_some((enter, normal))
}

fn ray_aabb(b: &PlacedAabb, o: Vec2, d: Vec2) -> Option<(f64, Vec2)> {
    slab(o - b.center, d, b.half)
}

fn ray_obb(b: &PlacedObb, o: Vec2, d: Vec2) -> Option<(f64, Vec2)> {
    let (lo, ld) = (b.rot.apply_inverse(o - b.center), b.rot.apply_inverse(d));
    slab(lo, ld, b.half).map(|(t, n)| (t, b.rot.apply(n)))
}

/// The capsule is the union of its two end discs and the rectangle between them: the first
/// entry into a union is the earliest entry into a part (a disc on a tie).
fn ray_capsule(c: &PlacedCapsule, o: Vec2, d: Vec2) -> Option<(f64, Vec2)> {
    let disc = |center| {
        ray_circle(
            &PlacedCircle {
                center,
                radius: c.radius,
            },
            o,
            d,
        )
    };
    let mut best = disc(c.a);
    if let Some(h) = disc(c.b)
        && best.is_none_or(|(t, _)| h.0 < t)
    {
        best = Some(h);
    }
    let ab = c.b - c.a;
    let len = ab.length();
    if len > 0.0 {
        let u = ab / len;
        let rect = PlacedObb {
            center: (c.a + c.b) * 0.5,
            rot: Rot { c: u.x, s: u.y },
            half: Vec2::new(len * 0.5, c.radius),
        };
        if let Some(h) = ray_obb(&rect, o, d)
            && best.is_none_or(|(t, _)| h.0 < t)
        {
            best = Some(h);
        }
    }
    best
}

/// Where the ray crosses the segment (a ray along it misses: zero thickness), with the
/// segment's normal facing the ray.
fn ray_segment(s: &PlacedSegment, o: Vec2, d: Vec2) -> Option<(f64, Vec2)> {
    let e = s.b - s.a;
    let den = crate::math::cross(d, e);
    if den == 0.0 {
        return None;
    }
    let ao = s.a - o;
    let t = crate::math::cross(ao, e) / den;
    let along = crate::math::cross(ao, d) / den;
    if t < 0.0 || !(0.0..=1.0).contains(&along) {
        return None;
    }
    let n = Vec2::new(e.y, -e.x).normalize();
    Some((t, if n.dot(d) > 0.0 { -n } else { n }))
}

/// Cyrus–Beck: the ray clipped by each edge's half-plane.
fn ray_polygon(g: &PlacedPolygon, o: Vec2, d: Vec2) -> Option<(f64, Vec2)> {
    let mut enter = f64::NEG_INFINITY;
    let mut exit = f64::INFINITY;
    let mut normal = Vec2::ZERO;
    for i in 0..g.count {
        let n = g.normals[i];
        // `o + t d` is inside edge `i`'s half-plane while `num - t den >= 0`.
        let num = n.dot(g.vertices[i] - o);
        let den = n.dot(d);
        if den == 0.0 {
            if num < 0.0 {
                return None;
            }
        } else if den < 0.0 {
            let t = num / den;
            if t > enter {
                enter = t;
                normal = n;
            }
        } else {
            exit = exit.min(num / den);
        }
        if exit < enter {
            return None;
        }
    }
    (enter >= 0.0).then_some((enter, normal))
}
