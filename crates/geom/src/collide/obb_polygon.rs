//! Oriented box against polygon: separating axes over both shapes' normals.

use crate::contact::Contact;
use crate::cores::{collide_cores, overlaps_cores};
use crate::placed::{PlacedObb, PlacedPolygon};

/// Contact of the pair, by the exact core algorithm (see `crate::cores`).
#[must_use]
pub fn collide_obb_polygon(a: &PlacedObb, b: &PlacedPolygon) -> Contact {
    collide_cores(&a.core(), &b.core())
}

/// Whether the pair overlaps: separating axes, stopping at the first that separates.
#[must_use]
pub fn overlaps_obb_polygon(a: &PlacedObb, b: &PlacedPolygon) -> bool {
    overlaps_cores(&a.core(), &b.core())
}
