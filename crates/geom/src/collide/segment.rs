//! A body against one segment of a terrain chain: the exact contact of the two cores (the
//! segment has zero thickness), then the joint rule that keeps a body sliding along a chain
//! from catching on the joints between its segments ("ghost collisions").
//!
//! The idea is Box2D's chain shape with ghost vertices (Erin Catto, "Ghost Collisions"):
//! each segment knows its neighbours' far points, so it knows which normals belong to it.
//! Seen from the side of the chain the body's centre is on (chains are two-sided), with
//! `up` the segment's normal on that side, a contact's normal `m` (from the segment to the
//! body) is measured as an angle from `up`, positive towards `b`:
//! - at an open end the segment's rounded end is real: every angle up to ±π is allowed;
//! - at a joint that turns away from the body (convex from its side), the joint's corner
//!   is shared: angles up to the neighbour's own `up` are allowed (both segments give the
//!   same corner contact there), beyond it the region is the neighbour's face;
//! - at a joint that is straight or turns towards the body (concave), no angle beyond `up`
//!   is the segment's: the body is over the neighbour, or in the corner.
//!
//! A normal within [`ANGLE_TOLERANCE`] of `up` is the face's, computed from the projections
//! (exactly `up`). A contact outside the allowed range is not this segment's. Past a convex
//! joint it is dropped (depth `-∞`): the body is over the neighbour, whose own contact
//! answers for it (apart, the neighbour holds the joint's point, so it is at most as far).
//! Past a straight or concave joint it is replaced by the push along the segment's `up`, as
//! deep as the body reaches below the segment's line (a body flush on a flat chain at a
//! joint touches the face, not an end); but a body apart from the segment that reaches
//! below its line is beside the neighbour, and that contact is dropped. A box on a flat chain is pushed straight up at every joint, never sideways.

use crate::contact::Contact;
use crate::cores::{Core, collide_cores};
use crate::math::{Vec2, cross};
use crate::placed::PlacedSegment;

/// How far past an allowed direction a normal may point and still count as allowed, and
/// how close to the face normal one is taken as the face, radians: a face contact's
/// normal is perpendicular to the segment up to rounding (about `1e-16` times the
/// coordinates over the distance), far below this; a real ghost normal is off by far more.
const ANGLE_TOLERANCE: f64 = 1e-9;

/// The contact of `body` (as `a`) with the chain segment `s` (as `b`): normal from the body
/// to the segment, filtered by the joint rule (module docs).
pub(crate) fn collide_segment(body: &Core, s: &PlacedSegment) -> Contact {
    let c = collide_cores(body, &s.core());
    admit(c, body, s)
}

/// The unit left normal of `e` (`e` turned a quarter counter-clockwise).
fn left(e: Vec2) -> Vec2 {
    let u = e.normalize();
    Vec2::new(-u.y, u.x)
}

fn admit(c: Contact, body: &Core, s: &PlacedSegment) -> Contact {
    let e = s.b - s.a;
    let t = e.normalize();
    let points = &body.points[..body.count];
    let m = -c.normal;
    // The side the body is on: +1 left of `a -> b`, -1 right. The side of the chain its
    // centre is on: of this segment's line where the centre is beside the segment, of the
    // neighbour's where it is past an end that has one (on a crest, a body beside the
    // slope's start is above the chain though below the slope's line).
    let centre = points.iter().fold(Vec2::ZERO, |sum, p| sum + *p) / points.len() as f64;
    let along_e = (centre - s.a).dot(t);
    let (from, dir) = match (s.prev, s.next) {
        (Some(p), _) if along_e < 0.0 => (p, s.a - p),
        (_, Some(n)) if along_e > e.length() => (s.b, n - s.b),
        _ => (s.a, e),
    };
    let side = if cross(dir, centre - from) >= 0.0 {
        1.0
    } else {
        -1.0
    };
    let up = left(e) * side;
    let angle = |v: Vec2| libm::atan2(v.dot(t), v.dot(up));
    // A joint turns away from the body (convex from its side) when the chain turns to the
    // other side there: `side * cross(in, out) < 0`.
    let hi = match s.next {
        None => std::f64::consts::PI,
        Some(n) if side * cross(e, n - s.b) < 0.0 => angle(left(n - s.b) * side),
        Some(_) => 0.0,
    };
    let lo = match s.prev {
        None => -std::f64::consts::PI,
        Some(p) if side * cross(s.a - p, e) < 0.0 => angle(left(s.a - p) * side),
        Some(_) => 0.0,
    };
    let theta = angle(m);
    // The push along allowed direction `bound`, as deep as the body reaches past the
    // segment along it (minus the gap when apart).
    let along = |bound: f64| {
        let u = up * libm::cos(bound) + t * libm::sin(bound);
        let top = s.a.dot(u).max(s.b.dot(u));
        let bottom = points
            .iter()
            .map(|p| p.dot(u))
            .fold(f64::INFINITY, f64::min)
            - body.radius;
        Contact {
            depth: top - bottom,
            normal: -u,
            point: c.point,
        }
    };
    if theta.abs() <= ANGLE_TOLERANCE {
        // The face, exactly: a normal off `up` by rounding (or by a tilt this small at a
        // joint) would give a body sliding along the chain a sliver of vertical speed.
        return along(0.0);
    }
    if (lo - ANGLE_TOLERANCE..=hi + ANGLE_TOLERANCE).contains(&theta) {
        return c;
    }
    // Past a convex joint the body is over the neighbour, whose own contact answers (the
    // neighbour's line through the joint is not this segment's to push along); apart, the
    // neighbour holds the joint's point, so it is at most as far.
    let bound = if theta > hi { hi } else { lo };
    let dropped = Contact {
        depth: f64::NEG_INFINITY,
        ..c
    };
    if bound != 0.0 {
        return dropped;
    }
    let face = along(0.0);
    // Apart or touching, the face's answer only where the body is not below the line (a
    // body flush on the chain at a joint touches the face; one past a concave joint and
    // below this segment's line is beside the neighbour, which answers for it).
    if c.depth <= 0.0 && face.depth > 0.0 {
        return dropped;
    }
    face
}
