//! Ricochet shapes as Box2D shapes, placed the way `ricochet_geom` places them.
//!
//! Every Ricochet body becomes one Box2D body with one shape. The Box2D body's transform is
//! the pose at which Ricochet places the primitive, and the shape is the primitive in its own
//! frame, so an AABB stays unrotated whatever the Ricochet body's angle:
//!
//! | Ricochet | Box2D shape (local, `f32`) | Box2D body transform |
//! |---|---|---|
//! | circle | `b2Circle` (centre 0, radius) | `p + R(θ)·center`, angle 0 |
//! | aabb | `b2MakeBox(hx, hy)` | `p + R(θ)·center`, **angle 0** (an AABB ignores the body angle) |
//! | obb | `b2MakeBox(hx, hy)` | `p + R(θ)·center`, angle `θ + angle` |
//! | capsule | `b2Capsule(a, b, radius)` (local ends) | `p`, angle `θ` |
//! | polygon | `b2MakePolygon(b2ComputeHull(vertices), 0)` | `p`, angle `θ` |
//! | compound | not supported (the bench scenes have none) | |
//!
//! `R(θ)` is `ricochet_geom::Rot::from_angle` (libm) and the position is computed in `f64`,
//! exactly as Ricochet computes it; Box2D's large-world mode keeps it in `f64`. What Box2D
//! holds in `f32` is the shape itself and the body's rotation: the angle handed to it is first
//! reduced to `[-π, π]` (so its `f32` rounding is at most `1.2e-7` rad), and boxdd turns it
//! into a cosine and sine (`b2Body_SetTransform`).

use boxdd::shapes::{Capsule, Circle, Polygon};
use ricochet_geom::{Pose, Primitive, Shape, Vec2};

use crate::Box2dError;

/// A Box2D shape in its body's frame.
#[derive(Clone, Copy, Debug)]
pub(crate) enum LocalShape {
    /// A circle centred on the body origin.
    Circle(Circle),
    /// A capsule in the body's frame.
    Capsule(Capsule),
    /// A box or convex polygon in the body's frame.
    Polygon(Polygon),
}

/// Where the Box2D body of a Ricochet body goes: a world position (`f64`) and an angle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Placement {
    /// The world position of the Box2D body's origin.
    pub position: Vec2,
    /// Its angle, reduced to `[-π, π]` and rounded to `f32` as Box2D stores it.
    pub angle: f32,
}

/// The only primitive of `shape`, or the error the bench reports for a compound.
fn primitive(shape: &Shape) -> Result<&Primitive, Box2dError> {
    match shape {
        Shape::Primitive(p) => Ok(p),
        Shape::Compound(_) => Err(Box2dError::Conversion(
            "compound shapes are not supported by the benchmark's Box2D scene".to_owned(),
        )),
    }
}

/// An angle reduced to `[-π, π]` (libm's IEEE remainder: exact), rounded to `f32`.
fn box2d_angle(angle: f64) -> f32 {
    libm::remainder(angle, std::f64::consts::TAU) as f32
}

/// The Box2D body transform of `shape` at `pose` (see the module docs).
pub(crate) fn placement(shape: &Shape, pose: &Pose) -> Result<Placement, Box2dError> {
    let p = primitive(shape)?;
    let rot = shape.rotation(pose.angle);
    let p0 = pose.position;
    let (position, angle) = match p {
        Primitive::Circle(c) => (p0 + rot.apply(c.center), 0.0),
        Primitive::Aabb(b) => (p0 + rot.apply(b.center), 0.0),
        Primitive::Obb(b) => (p0 + rot.apply(b.center), pose.angle + b.angle),
        Primitive::Capsule(_) | Primitive::Polygon(_) | Primitive::Segment(_) => (p0, pose.angle),
    };
    Ok(Placement {
        position,
        angle: box2d_angle(angle),
    })
}

/// A Ricochet length or coordinate as Box2D's local `f32`.
fn local(v: Vec2) -> [f32; 2] {
    [v.x as f32, v.y as f32]
}

/// The Box2D shape of `shape`, in the frame [`placement`] gives its body.
///
/// A polygon goes through Box2D's hull (`b2ComputeHull`), which welds vertices closer than the
/// linear slop and drops nearly collinear ones; when it keeps fewer vertices than Ricochet has,
/// the shapes would differ, so that is an error rather than a silent approximation.
pub(crate) fn local_shape(shape: &Shape) -> Result<LocalShape, Box2dError> {
    let box2d = |e: boxdd::Error| Box2dError::Box2d(e.to_string());
    Ok(match primitive(shape)? {
        Primitive::Circle(c) => {
            LocalShape::Circle(Circle::new([0.0, 0.0], c.radius as f32).map_err(box2d)?)
        }
        Primitive::Aabb(b) => LocalShape::Polygon(
            Polygon::box_polygon(b.half_extents.x as f32, b.half_extents.y as f32)
                .map_err(box2d)?,
        ),
        Primitive::Obb(b) => LocalShape::Polygon(
            Polygon::box_polygon(b.half_extents.x as f32, b.half_extents.y as f32)
                .map_err(box2d)?,
        ),
        Primitive::Capsule(c) => LocalShape::Capsule(
            Capsule::new(local(c.a), local(c.b), c.radius as f32).map_err(box2d)?,
        ),
        Primitive::Polygon(poly) => {
            let vertices = poly.vertices();
            let hull =
                Polygon::from_points(vertices.iter().map(|v| local(*v)), 0.0).map_err(box2d)?;
            if hull.count() != vertices.len() {
                return Err(Box2dError::Conversion(format!(
                    "Box2D's hull keeps {} of the polygon's {} vertices (closer than its linear \
                     slop, or nearly collinear)",
                    hull.count(),
                    vertices.len()
                )));
            }
            LocalShape::Polygon(hull)
        }
        // Only a chain holds segments, and a chain is a compound (refused above).
        Primitive::Segment(_) => {
            return Err(Box2dError::Conversion(
                "terrain chains are not supported by the benchmark's Box2D scene".to_owned(),
            ));
        }
    })
}
