//! The result of a narrow-phase query.

use crate::math::Vec2;

/// The exact minimum translation between two shapes, signed.
///
/// `normal` is a unit vector from `a` to `b`. When the shapes overlap, `depth > 0` and moving
/// `b` by `depth * normal` (or `a` by `-depth * normal`) separates them: no shorter move does.
/// When they are apart, `depth` is minus the distance between them and `normal` points from
/// `a`'s closest point to `b`'s. `point` lies midway between the two surfaces along the normal:
/// inside both shapes when they overlap, in the gap when they don't.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    /// Penetration depth (`> 0`), or minus the distance (`<= 0`).
    pub depth: f64,
    /// Unit normal from `a` to `b`.
    pub normal: Vec2,
    /// A contact point in world coordinates.
    pub point: Vec2,
}

impl Contact {
    /// Whether the shapes overlap (`depth > 0`). Touching is not overlapping.
    #[must_use]
    pub fn overlaps(&self) -> bool {
        self.depth > 0.0
    }

    /// The same contact seen from the other body: the normal reversed.
    #[must_use]
    pub fn flipped(self) -> Contact {
        Contact {
            normal: -self.normal,
            ..self
        }
    }

    /// The same contact with its point moved by `offset` (from a local frame to the world).
    #[must_use]
    pub fn translated(self, offset: Vec2) -> Contact {
        Contact {
            point: self.point + offset,
            ..self
        }
    }
}
