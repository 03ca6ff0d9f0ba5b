//! Circle against oriented box: the circle centre in the box's frame, then as an AABB.

use crate::contact::Contact;
use crate::placed::{PlacedCircle, PlacedObb};

use super::circle_aabb::circle_in_box_frame;

/// Contact of a circle (`a`) and an oriented box (`b`).
#[must_use]
pub fn collide_circle_obb(a: &PlacedCircle, b: &PlacedObb) -> Contact {
    let local = b.rot.apply_inverse(a.center - b.center);
    let c = circle_in_box_frame(local, a.radius, b.half);
    Contact {
        depth: c.depth,
        normal: b.rot.apply(c.normal),
        point: b.center + b.rot.apply(c.point),
    }
}

/// Whether a circle and an oriented box overlap.
#[must_use]
pub fn overlaps_circle_obb(a: &PlacedCircle, b: &PlacedObb) -> bool {
    let c = b.rot.apply_inverse(a.center - b.center);
    let q = c.clamp(-b.half, b.half);
    (q - c).length_squared() < a.radius * a.radius
}
