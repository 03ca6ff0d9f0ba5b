//! Oriented box against capsule: the box against the capsule's segment, then the radius.

use crate::contact::Contact;
use crate::cores::{collide_cores, overlaps_cores};
use crate::placed::{PlacedCapsule, PlacedObb};

/// Contact of the pair, by the exact core algorithm (see `crate::cores`).
#[must_use]
pub fn collide_obb_capsule(a: &PlacedObb, b: &PlacedCapsule) -> Contact {
    collide_cores(&a.core(), &b.core())
}

/// Whether the pair overlaps: separating axes, stopping at the first that separates.
#[must_use]
pub fn overlaps_obb_capsule(a: &PlacedObb, b: &PlacedCapsule) -> bool {
    overlaps_cores(&a.core(), &b.core())
}
