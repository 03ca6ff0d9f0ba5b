//! Circle against polygon: the centre against the polygon's edges and normals.

use crate::contact::Contact;
use crate::cores::{collide_cores, overlaps_cores};
use crate::placed::{PlacedCircle, PlacedPolygon};

/// Contact of the pair, by the exact core algorithm (see `crate::cores`).
#[must_use]
pub fn collide_circle_polygon(a: &PlacedCircle, b: &PlacedPolygon) -> Contact {
    collide_cores(&a.core(), &b.core())
}

/// Whether the pair overlaps: separating axes, stopping at the first that separates.
#[must_use]
pub fn overlaps_circle_polygon(a: &PlacedCircle, b: &PlacedPolygon) -> bool {
    overlaps_cores(&a.core(), &b.core())
}
