//! Circle against circle: the distance between centres.

use crate::contact::Contact;
use crate::math::Vec2;
use crate::placed::PlacedCircle;

/// Contact of two circles.
#[must_use]
pub fn collide_circle_circle(a: &PlacedCircle, b: &PlacedCircle) -> Contact {
    let d = b.center - a.center;
    let distance = d.length();
    // Concentric circles: every direction is equally short; +y as in `collide_cores`.
    let normal = if distance > 0.0 {
        d / distance
    } else {
        Vec2::Y
    };
    let sa = a.center + normal * a.radius;
    let sb = b.center - normal * b.radius;
    Contact {
        depth: a.radius + b.radius - distance,
        normal,
        point: 0.5 * (sa + sb),
    }
}

/// Whether two circles overlap, with squared distances only.
#[must_use]
pub fn overlaps_circle_circle(a: &PlacedCircle, b: &PlacedCircle) -> bool {
    let r = a.radius + b.radius;
    (b.center - a.center).length_squared() < r * r
}
