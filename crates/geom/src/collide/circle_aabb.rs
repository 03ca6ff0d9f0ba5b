//! Circle against axis-aligned box: clamp the centre into the box.

use crate::contact::Contact;
use crate::math::Vec2;
use crate::placed::{PlacedAabb, PlacedCircle};

/// Contact of a circle (`a`) and an axis-aligned box (`b`), both in one frame.
#[must_use]
pub fn collide_circle_aabb(a: &PlacedCircle, b: &PlacedAabb) -> Contact {
    // Work around the box centre so both boxes' local and world frames coincide.
    circle_in_box_frame(a.center - b.center, a.radius, b.half).translated(b.center)
}

/// Contact of a circle centred at `c` (box frame) with the box `[-half, half]`.
pub(crate) fn circle_in_box_frame(c: Vec2, radius: f64, half: Vec2) -> Contact {
    let q = c.clamp(-half, half);
    if q != c {
        // Centre outside: the closest box point is the clamp.
        let d = q - c;
        let distance = d.length();
        let normal = d / distance;
        let sa = c + normal * radius;
        return Contact {
            depth: radius - distance,
            normal,
            point: 0.5 * (sa + q),
        };
    }
    // Centre inside: leave through the nearest face. Ties go to x first (like the separating
    // axis order of the general algorithm: the box's -y, +x, +y, -x faces).
    let faces = [
        (c.y + half.y, Vec2::Y),  // nearest to the bottom face: push the box up
        (half.x - c.x, -Vec2::X), // right face: push the box left
        (half.y - c.y, -Vec2::Y), // top face: push the box down
        (c.x + half.x, Vec2::X),  // left face: push the box right
    ];
    let mut best = faces[0];
    for f in &faces[1..] {
        if f.0 < best.0 {
            best = *f;
        }
    }
    let (gap, normal) = best;
    let depth = gap + radius;
    // Midway between the circle's far side and the face it leaves by.
    Contact {
        depth,
        normal,
        point: c + normal * (0.5 * (radius - gap)),
    }
}

/// Whether a circle and an axis-aligned box overlap: squared distance to the clamped centre.
#[must_use]
pub fn overlaps_circle_aabb(a: &PlacedCircle, b: &PlacedAabb) -> bool {
    let c = a.center - b.center;
    let q = c.clamp(-b.half, b.half);
    (q - c).length_squared() < a.radius * a.radius
}
