//! Axis-aligned bounding boxes of placed shapes, for the broad phase.

use crate::math::Vec2;

/// An axis-aligned bounding box in world coordinates (Box2D's `b2AABB`). Named `Bounds` so it
/// is never confused with the [`crate::Aabb`] shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// Lower-left corner.
    pub min: Vec2,
    /// Upper-right corner.
    pub max: Vec2,
}

impl Bounds {
    /// The box around `center` with the given half extents.
    #[must_use]
    pub fn around(center: Vec2, half_extents: Vec2) -> Bounds {
        Bounds {
            min: center - half_extents,
            max: center + half_extents,
        }
    }

    /// The smallest box holding every point of `points` (which must not be empty).
    #[must_use]
    pub fn of_points(points: &[Vec2]) -> Bounds {
        let mut b = Bounds {
            min: points[0],
            max: points[0],
        };
        for p in &points[1..] {
            b.min = b.min.min(*p);
            b.max = b.max.max(*p);
        }
        b
    }

    /// The smallest box holding both.
    #[must_use]
    pub fn union(self, other: Bounds) -> Bounds {
        Bounds {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// The same box moved by `offset`.
    #[must_use]
    pub fn translated(self, offset: Vec2) -> Bounds {
        Bounds {
            min: self.min + offset,
            max: self.max + offset,
        }
    }

    /// Half the width and half the height.
    #[must_use]
    pub fn half_extents(&self) -> Vec2 {
        (self.max - self.min) * 0.5
    }

    /// The centre.
    #[must_use]
    pub fn center(&self) -> Vec2 {
        (self.min + self.max) * 0.5
    }

    /// Whether the two boxes share any point (touching counts).
    #[must_use]
    pub fn overlaps(&self, other: &Bounds) -> bool {
        self.min.x <= other.max.x
            && other.min.x <= self.max.x
            && self.min.y <= other.max.y
            && other.min.y <= self.max.y
    }

    /// Whether `p` is inside or on the box.
    #[must_use]
    pub fn contains(&self, p: Vec2) -> bool {
        self.min.x <= p.x && p.x <= self.max.x && self.min.y <= p.y && p.y <= self.max.y
    }
}
