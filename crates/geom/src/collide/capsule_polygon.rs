//! Capsule against polygon: the capsule's segment against the polygon, then the radius.

use crate::contact::Contact;
use crate::cores::{collide_cores, overlaps_cores};
use crate::placed::{PlacedCapsule, PlacedPolygon};

/// Contact of the pair, by the exact core algorithm (see `crate::cores`).
#[must_use]
pub fn collide_capsule_polygon(a: &PlacedCapsule, b: &PlacedPolygon) -> Contact {
    collide_cores(&a.core(), &b.core())
}

/// Whether the pair overlaps: separating axes, stopping at the first that separates.
#[must_use]
pub fn overlaps_capsule_polygon(a: &PlacedCapsule, b: &PlacedPolygon) -> bool {
    overlaps_cores(&a.core(), &b.core())
}
