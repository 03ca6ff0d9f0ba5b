//! Axis-aligned box against axis-aligned box: overlap along x and along y.

use crate::contact::Contact;
use crate::math::Vec2;
use crate::placed::PlacedAabb;

/// Contact of two axis-aligned boxes.
#[must_use]
pub fn collide_aabb_aabb(a: &PlacedAabb, b: &PlacedAabb) -> Contact {
    let d = b.center - a.center;
    let reach = a.half + b.half;
    // Overlap along each axis (negative: the gap), and the direction b leaves in.
    let px = reach.x - d.x.abs();
    let py = reach.y - d.y.abs();
    let sx = if d.x < 0.0 { -1.0 } else { 1.0 };
    let sy = if d.y < 0.0 { -1.0 } else { 1.0 };
    // Overlap interval of the two boxes on each axis: the contact point sits in its middle.
    let lo = (a.center - a.half).max(b.center - b.half);
    let hi = (a.center + a.half).min(b.center + b.half);
    let mid = 0.5 * (lo + hi);
    if px > 0.0 && py > 0.0 {
        // Ties go to y, like the face order of the general algorithm (-y, +x, +y, -x).
        let (depth, normal) = if px < py {
            (px, Vec2::new(sx, 0.0))
        } else {
            (py, Vec2::new(0.0, sy))
        };
        return Contact {
            depth,
            normal,
            point: mid,
        };
    }
    // Apart (or touching): the gap vector between the boxes.
    let gap = Vec2::new((-px).max(0.0) * sx, (-py).max(0.0) * sy);
    let distance = gap.length();
    let normal = if distance > 0.0 {
        gap / distance
    } else if px <= py {
        Vec2::new(sx, 0.0)
    } else {
        Vec2::new(0.0, sy)
    };
    Contact {
        depth: -distance,
        normal,
        point: mid,
    }
}

/// Whether two axis-aligned boxes overlap: the four separating tests.
#[must_use]
#[inline]
pub fn overlaps_aabb_aabb(a: &PlacedAabb, b: &PlacedAabb) -> bool {
    let (amin, amax) = (a.center - a.half, a.center + a.half);
    let (bmin, bmax) = (b.center - b.half, b.center + b.half);
    amin.x < bmax.x && bmin.x < amax.x && amin.y < bmax.y && bmin.y < amax.y
}
