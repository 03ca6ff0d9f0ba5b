//! Circle against capsule: the circle centre against the capsule's segment.

use crate::contact::Contact;
use crate::cores::collide_cores;
use crate::placed::{PlacedCapsule, PlacedCircle};

/// Contact of a circle (`a`) and a capsule (`b`): a point core against a segment core.
#[must_use]
pub fn collide_circle_capsule(a: &PlacedCircle, b: &PlacedCapsule) -> Contact {
    collide_cores(&a.core(), &b.core())
}

/// Whether a circle and a capsule overlap: squared distance from the centre to the segment.
#[must_use]
pub fn overlaps_circle_capsule(a: &PlacedCircle, b: &PlacedCapsule) -> bool {
    let r = a.radius + b.radius;
    segment_distance_squared(a.center, b.a, b.b) < r * r
}

/// Squared distance from `p` to the segment `s0`–`s1`.
pub(crate) fn segment_distance_squared(p: crate::Vec2, s0: crate::Vec2, s1: crate::Vec2) -> f64 {
    let e = s1 - s0;
    let ee = e.dot(e);
    let t = if ee > 0.0 {
        ((p - s0).dot(e) / ee).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (s0 + e * t)).length_squared()
}
