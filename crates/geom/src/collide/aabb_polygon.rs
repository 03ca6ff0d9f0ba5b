//! Axis-aligned box against polygon: separating axes over both shapes' normals.

use crate::contact::Contact;
use crate::cores::{collide_cores, overlaps_cores};
use crate::placed::{PlacedAabb, PlacedPolygon};

/// Contact of the pair, by the exact core algorithm (see `crate::cores`).
#[must_use]
pub fn collide_aabb_polygon(a: &PlacedAabb, b: &PlacedPolygon) -> Contact {
    collide_cores(&a.core(), &b.core())
}

/// Whether the pair overlaps: separating axes, stopping at the first that separates.
#[must_use]
pub fn overlaps_aabb_polygon(a: &PlacedAabb, b: &PlacedPolygon) -> bool {
    overlaps_cores(&a.core(), &b.core())
}
