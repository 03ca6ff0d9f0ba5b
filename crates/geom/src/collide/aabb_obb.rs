//! Axis-aligned box against oriented box: separating axes over both boxes' normals.

use crate::contact::Contact;
use crate::cores::{collide_cores, overlaps_cores};
use crate::placed::{PlacedAabb, PlacedObb};

/// Contact of the pair, by the exact core algorithm (see `crate::cores`).
#[must_use]
pub fn collide_aabb_obb(a: &PlacedAabb, b: &PlacedObb) -> Contact {
    collide_cores(&a.core(), &b.core())
}

/// Whether the pair overlaps: separating axes, stopping at the first that separates.
#[must_use]
pub fn overlaps_aabb_obb(a: &PlacedAabb, b: &PlacedObb) -> bool {
    overlaps_cores(&a.core(), &b.core())
}
