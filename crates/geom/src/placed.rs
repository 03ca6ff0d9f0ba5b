//! Primitives placed in a frame: everything the narrow phase needs, with rotations applied.

use crate::bounds::Bounds;
use crate::cores::Core;
use crate::math::{Pose, Rot, Vec2};
use crate::shape::{Aabb, MAX_POLYGON_VERTICES, Primitive, Shape};

/// A circle in a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlacedCircle {
    /// Centre.
    pub center: Vec2,
    /// Radius.
    pub radius: f64,
}

/// An axis-aligned box in a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlacedAabb {
    /// Centre.
    pub center: Vec2,
    /// Half width and half height.
    pub half: Vec2,
}

/// An oriented box in a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlacedObb {
    /// Centre.
    pub center: Vec2,
    /// The box's rotation (body angle plus its own).
    pub rot: Rot,
    /// Half width and half height along the box's own axes.
    pub half: Vec2,
}

/// A capsule in a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlacedCapsule {
    /// First end of the core segment.
    pub a: Vec2,
    /// Second end of the core segment.
    pub b: Vec2,
    /// Radius.
    pub radius: f64,
}

/// A convex polygon in a frame, with its outward unit edge normals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlacedPolygon {
    /// Vertices, counter-clockwise; only the first `count` are used.
    pub vertices: [Vec2; MAX_POLYGON_VERTICES],
    /// `normals[i]` is the outward unit normal of the edge `vertices[i]`–`vertices[i + 1]`.
    pub normals: [Vec2; MAX_POLYGON_VERTICES],
    /// How many vertices.
    pub count: usize,
}

/// A chain segment in a frame, with its neighbours' far points (see [`crate::Segment`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlacedSegment {
    /// First end.
    pub a: Vec2,
    /// Second end.
    pub b: Vec2,
    /// The previous segment's first end, if any.
    pub prev: Option<Vec2>,
    /// The next segment's second end, if any.
    pub next: Option<Vec2>,
}

/// A primitive placed in a frame (world coordinates, or coordinates relative to an origin).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PlacedPrimitive {
    /// A placed circle.
    Circle(PlacedCircle),
    /// A placed axis-aligned box.
    Aabb(PlacedAabb),
    /// A placed oriented box.
    Obb(PlacedObb),
    /// A placed capsule.
    Capsule(PlacedCapsule),
    /// A placed polygon.
    Polygon(PlacedPolygon),
    /// A placed chain segment.
    Segment(PlacedSegment),
}

/// Places `primitive` at `pose`, in a frame whose origin is the world point `origin`.
///
/// Passing the position of one body of a pair as `origin` keeps every coordinate small, so a
/// pair far from the world origin is computed as accurately as the same pair near it.
#[must_use]
pub fn place(primitive: &Primitive, pose: &Pose, origin: Vec2) -> PlacedPrimitive {
    place_with(
        primitive,
        pose.position - origin,
        Rot::from_angle(pose.angle),
        pose.angle,
    )
}

/// [`place`] with the body rotation already computed (`rot`: `Rot::from_angle(angle)`, or
/// [`Shape::rotation`] for a shape's parts), the body at `position` in the frame: for a
/// caller that keeps each body's rotation ready (the scene queries) instead of computing its
/// sine and cosine again for every test. The same bits as [`place`] given the same rotation.
#[must_use]
#[inline]
pub fn place_rotated(
    primitive: &Primitive,
    position: Vec2,
    rot: Rot,
    angle: f64,
) -> PlacedPrimitive {
    place_with(primitive, position, rot, angle)
}

/// The box of `primitive` placed as [`place_rotated`] places it: the same arithmetic for
/// every point, so the same bits as `place_rotated(..).bounds()`, without placing the part
/// (a polygon's vertices are rotated, not its normals: a refit of 10,000 turned bodies spent
/// half its time placing them, issue #37).
#[must_use]
#[inline]
pub fn placed_bounds(primitive: &Primitive, position: Vec2, rot: Rot, angle: f64) -> Bounds {
    match primitive {
        Primitive::Polygon(p) => {
            let local = p.vertices();
            let mut vertices = [Vec2::ZERO; MAX_POLYGON_VERTICES];
            for (out, v) in vertices.iter_mut().zip(local) {
                *out = position + rot.apply(*v);
            }
            Bounds::of_points(&vertices[..local.len()])
        }
        _ => place_with(primitive, position, rot, angle).bounds(),
    }
}

/// An axis-aligned box part placed as [`place_with`] places it (its centre turns, its
/// sides stay on the axes).
#[inline]
pub(crate) fn place_aabb(b: &Aabb, position: Vec2, rot: Rot) -> PlacedAabb {
    PlacedAabb {
        center: position + rot.apply(b.center),
        half: b.half_extents,
    }
}

/// [`place`] with the body rotation already computed.
#[must_use]
pub(crate) fn place_with(
    primitive: &Primitive,
    position: Vec2,
    rot: Rot,
    angle: f64,
) -> PlacedPrimitive {
    match primitive {
        Primitive::Circle(c) => PlacedPrimitive::Circle(PlacedCircle {
            center: position + rot.apply(c.center),
            radius: c.radius,
        }),
        Primitive::Aabb(b) => PlacedPrimitive::Aabb(place_aabb(b, position, rot)),
        Primitive::Obb(b) => PlacedPrimitive::Obb(PlacedObb {
            center: position + rot.apply(b.center),
            rot: if b.angle == 0.0 {
                rot
            } else {
                Rot::from_angle(angle + b.angle)
            },
            half: b.half_extents,
        }),
        Primitive::Capsule(c) => PlacedPrimitive::Capsule(PlacedCapsule {
            a: position + rot.apply(c.a),
            b: position + rot.apply(c.b),
            radius: c.radius,
        }),
        Primitive::Polygon(p) => {
            let local = p.vertices();
            let mut vertices = [Vec2::ZERO; MAX_POLYGON_VERTICES];
            for (out, v) in vertices.iter_mut().zip(local) {
                *out = position + rot.apply(*v);
            }
            // Normals are the local ones, rotated: rotating a unit vector keeps it unit and is
            // more accurate than normalising a difference of large coordinates.
            let mut normals = [Vec2::ZERO; MAX_POLYGON_VERTICES];
            let n = local.len();
            for (out, u) in normals.iter_mut().zip(p.normals()) {
                *out = rot.apply(*u);
            }
            PlacedPrimitive::Polygon(PlacedPolygon {
                vertices,
                normals,
                count: n,
            })
        }
        Primitive::Segment(s) => {
            let at = |v: Vec2| position + rot.apply(v);
            PlacedPrimitive::Segment(PlacedSegment {
                a: at(s.a),
                b: at(s.b),
                prev: s.prev.map(at),
                next: s.next.map(at),
            })
        }
    }
}

impl PlacedPrimitive {
    /// The bounding box in this frame.
    #[must_use]
    pub fn bounds(&self) -> Bounds {
        match self {
            PlacedPrimitive::Circle(c) => Bounds::around(c.center, Vec2::splat(c.radius)),
            PlacedPrimitive::Aabb(b) => Bounds::around(b.center, b.half),
            PlacedPrimitive::Obb(b) => {
                let ux = Vec2::new(b.rot.c, b.rot.s);
                let uy = Vec2::new(-b.rot.s, b.rot.c);
                let h = ux.abs() * b.half.x + uy.abs() * b.half.y;
                Bounds::around(b.center, h)
            }
            PlacedPrimitive::Capsule(c) => {
                let r = Vec2::splat(c.radius);
                Bounds {
                    min: c.a.min(c.b) - r,
                    max: c.a.max(c.b) + r,
                }
            }
            PlacedPrimitive::Polygon(p) => Bounds::of_points(&p.vertices[..p.count]),
            PlacedPrimitive::Segment(s) => Bounds {
                min: s.a.min(s.b),
                max: s.a.max(s.b),
            },
        }
    }

    /// The shape as a convex core swept by a radius, for the general algorithm
    /// ([`crate::pairs::collide_cores`]).
    #[must_use]
    pub fn core(&self) -> Core {
        match self {
            PlacedPrimitive::Circle(c) => c.core(),
            PlacedPrimitive::Aabb(b) => b.core(),
            PlacedPrimitive::Obb(b) => b.core(),
            PlacedPrimitive::Capsule(c) => c.core(),
            PlacedPrimitive::Polygon(p) => p.core(),
            PlacedPrimitive::Segment(s) => s.core(),
        }
    }
}

impl PlacedCircle {
    pub(crate) fn core(&self) -> Core {
        Core::point(self.center, self.radius)
    }
}

impl PlacedAabb {
    pub(crate) fn core(&self) -> Core {
        Core::quad(self.center, Vec2::X, Vec2::Y, self.half)
    }
}

impl PlacedObb {
    pub(crate) fn core(&self) -> Core {
        let ux = Vec2::new(self.rot.c, self.rot.s);
        let uy = Vec2::new(-self.rot.s, self.rot.c);
        Core::quad(self.center, ux, uy, self.half)
    }
}

impl PlacedCapsule {
    pub(crate) fn core(&self) -> Core {
        Core::segment(self.a, self.b, self.radius)
    }
}

impl PlacedSegment {
    pub(crate) fn core(&self) -> Core {
        Core::segment(self.a, self.b, 0.0)
    }
}

impl PlacedPolygon {
    pub(crate) fn core(&self) -> Core {
        Core {
            points: self.vertices,
            normals: self.normals,
            count: self.count,
            radius: 0.0,
        }
    }
}

impl Shape {
    /// The world bounding box of this shape at `pose`.
    #[must_use]
    pub fn bounds(&self, pose: &Pose) -> Bounds {
        let rot = self.rotation(pose.angle);
        let mut prims = self.primitives().iter();
        let first = prims
            .next()
            .map(|p| placed_bounds(p, pose.position, rot, pose.angle));
        let mut b = first.unwrap_or(Bounds::around(pose.position, Vec2::ZERO));
        for p in prims {
            b = b.union(placed_bounds(p, pose.position, rot, pose.angle));
        }
        b
    }
}
