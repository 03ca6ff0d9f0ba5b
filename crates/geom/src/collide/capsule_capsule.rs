//! Capsule against capsule: the distance between the two core segments.

use crate::contact::Contact;
use crate::cores::collide_cores;
use crate::math::Vec2;
use crate::placed::PlacedCapsule;

/// Contact of two capsules, by the exact core algorithm (see `crate::cores`): it handles
/// crossing segments, where the closest-points formula has no answer.
#[must_use]
pub fn collide_capsule_capsule(a: &PlacedCapsule, b: &PlacedCapsule) -> Contact {
    collide_cores(&a.core(), &b.core())
}

/// Whether two capsules overlap: the squared distance between their segments.
#[must_use]
pub fn overlaps_capsule_capsule(a: &PlacedCapsule, b: &PlacedCapsule) -> bool {
    let r = a.radius + b.radius;
    segment_segment_distance_squared(a.a, a.b, b.a, b.b) < r * r
}

/// Squared distance between the segments `p0`–`p1` and `q0`–`q1` (Ericson, Real-Time
/// Collision Detection, 5.1.9); in 2D it is zero when they cross.
fn segment_segment_distance_squared(p0: Vec2, p1: Vec2, q0: Vec2, q1: Vec2) -> f64 {
    let d1 = p1 - p0;
    let d2 = q1 - q0;
    let r = p0 - q0;
    let a = d1.dot(d1);
    let e = d2.dot(d2);
    let f = d2.dot(r);
    let (s, t);
    if a == 0.0 && e == 0.0 {
        return r.length_squared();
    }
    if a == 0.0 {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = d1.dot(r);
        if e == 0.0 {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            let s0 = if denom > 0.0 {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let t0 = (b * s0 + f) / e;
            if t0 < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t0 > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            } else {
                t = t0;
                s = s0;
            }
        }
    }
    ((p0 + d1 * s) - (q0 + d2 * t)).length_squared()
}
