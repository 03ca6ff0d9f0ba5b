//! The file description of a shape: the format of the shared collision cases, also used by
//! scenario files and logs. Deserialise a [`ShapeDef`], then [`ShapeDef::to_shape`] validates.

use serde::{Deserialize, Serialize};

use crate::math::Vec2;
use crate::shape::{Primitive, Shape, ShapeError};

fn is_origin(v: &[f64; 2]) -> bool {
    *v == [0.0, 0.0]
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

fn v2(v: [f64; 2]) -> Vec2 {
    Vec2::new(v[0], v[1])
}

/// A shape as written in a case file, a scenario or a log: local coordinates, radians.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum ShapeDef {
    /// `{"kind": "circle", "radius": r}`.
    Circle {
        /// Radius, `> 0`.
        radius: f64,
        /// Local offset (default `[0, 0]`).
        #[serde(default, skip_serializing_if = "is_origin")]
        center: [f64; 2],
    },
    /// `{"kind": "aabb", "half_extents": [hx, hy]}`: ignores the body angle.
    Aabb {
        /// Half width and half height, `> 0`.
        half_extents: [f64; 2],
        /// Local offset (default `[0, 0]`).
        #[serde(default, skip_serializing_if = "is_origin")]
        center: [f64; 2],
    },
    /// `{"kind": "obb", "half_extents": [hx, hy]}`: turned by the body angle plus `angle`.
    Obb {
        /// Half width and half height, `> 0`.
        half_extents: [f64; 2],
        /// Local offset (default `[0, 0]`).
        #[serde(default, skip_serializing_if = "is_origin")]
        center: [f64; 2],
        /// The box's own angle, radians (default 0).
        #[serde(default, skip_serializing_if = "is_zero")]
        angle: f64,
    },
    /// `{"kind": "capsule", "a": [x, y], "b": [x, y], "radius": r}`.
    Capsule {
        /// First end of the segment.
        a: [f64; 2],
        /// Second end of the segment.
        b: [f64; 2],
        /// Radius, `> 0`.
        radius: f64,
        /// Local offset added to both ends (default `[0, 0]`).
        #[serde(default, skip_serializing_if = "is_origin")]
        center: [f64; 2],
    },
    /// `{"kind": "polygon", "vertices": [[x, y], ...]}`: convex, counter-clockwise.
    Polygon {
        /// 3 to 8 vertices.
        vertices: Vec<[f64; 2]>,
        /// Local offset added to every vertex (default `[0, 0]`).
        #[serde(default, skip_serializing_if = "is_origin")]
        center: [f64; 2],
    },
    /// `{"kind": "chain", "points": [[x, y], ...]}`: a terrain chain of segments, two-sided,
    /// that bodies slide along without catching on its joints ([`Shape::chain`]).
    Chain {
        /// 2 to [`crate::MAX_CHAIN_POINTS`] points, no two in a row equal.
        points: Vec<[f64; 2]>,
        /// Where the terrain goes on before the first point (another chain's), if it does.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        prev: Option<[f64; 2]>,
        /// Where the terrain goes on after the last point, if it does.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        next: Option<[f64; 2]>,
    },
    /// `{"kind": "compound", "parts": [SHAPE, ...]}`: parts carry their own `center`.
    Compound {
        /// The parts; none may itself be a compound.
        parts: Vec<ShapeDef>,
    },
}

impl ShapeDef {
    /// Validates the description and builds the shape. Errors name the field path.
    pub fn to_shape(&self) -> Result<Shape, ShapeError> {
        match self {
            ShapeDef::Compound { parts } => {
                // Counted before any part is checked: a huge list is refused at once.
                if parts.len() > crate::MAX_COMPOUND_PARTS {
                    return Err(crate::shape::too_many_parts(parts.len()));
                }
                let mut out = Vec::with_capacity(parts.len());
                for (i, part) in parts.iter().enumerate() {
                    let p = part
                        .to_primitive()
                        .map_err(|e| e.within(&format!("parts[{i}]")))?;
                    out.push(p);
                }
                Shape::compound(out)
            }
            ShapeDef::Chain { points, prev, next } => {
                // Counted before any point is read: a huge list is refused at once.
                if points.len() > crate::MAX_CHAIN_POINTS {
                    return Shape::chain(&[Vec2::ZERO; crate::MAX_CHAIN_POINTS + 1], None, None);
                }
                let ps: Vec<Vec2> = points.iter().map(|p| v2(*p)).collect();
                Shape::chain(&ps, prev.map(v2), next.map(v2))
            }
            _ => self.to_primitive().map(Shape::Primitive),
        }
    }

    fn to_primitive(&self) -> Result<Primitive, ShapeError> {
        match self {
            ShapeDef::Circle { radius, center } => Primitive::circle(v2(*center), *radius),
            ShapeDef::Aabb {
                half_extents,
                center,
            } => Primitive::aabb(v2(*center), v2(*half_extents)),
            ShapeDef::Obb {
                half_extents,
                center,
                angle,
            } => Primitive::obb(v2(*center), v2(*half_extents), *angle),
            ShapeDef::Capsule {
                a,
                b,
                radius,
                center,
            } => {
                let c = v2(*center);
                if !c.is_finite() {
                    return Err(ShapeError::new("center", "must be finite numbers"));
                }
                Primitive::capsule(v2(*a) + c, v2(*b) + c, *radius)
            }
            ShapeDef::Polygon { vertices, center } => {
                let c = v2(*center);
                if !c.is_finite() {
                    return Err(ShapeError::new("center", "must be finite numbers"));
                }
                let vs: Vec<Vec2> = vertices.iter().map(|v| v2(*v) + c).collect();
                Primitive::polygon(&vs)
            }
            ShapeDef::Compound { .. } => Err(ShapeError::new(
                "kind",
                "a compound part cannot itself be a compound",
            )),
            ShapeDef::Chain { .. } => Err(ShapeError::new(
                "kind",
                "a compound part cannot be a chain (a chain is a body's whole shape)",
            )),
        }
    }

    /// The description of a shape (centre offsets of capsules and polygons are folded into
    /// their points).
    #[must_use]
    pub fn from_shape(shape: &Shape) -> ShapeDef {
        match shape {
            Shape::Primitive(p) => ShapeDef::from_primitive(p),
            Shape::Compound(c) => {
                if let Some(def) = chain_def(c.parts()) {
                    return def;
                }
                ShapeDef::Compound {
                    parts: c.parts().iter().map(ShapeDef::from_primitive).collect(),
                }
            }
        }
    }

    fn from_primitive(p: &Primitive) -> ShapeDef {
        let a = |v: Vec2| [v.x, v.y];
        match p {
            Primitive::Circle(c) => ShapeDef::Circle {
                radius: c.radius,
                center: a(c.center),
            },
            Primitive::Aabb(b) => ShapeDef::Aabb {
                half_extents: a(b.half_extents),
                center: a(b.center),
            },
            Primitive::Obb(b) => ShapeDef::Obb {
                half_extents: a(b.half_extents),
                center: a(b.center),
                angle: b.angle,
            },
            Primitive::Capsule(c) => ShapeDef::Capsule {
                a: a(c.a),
                b: a(c.b),
                radius: c.radius,
                center: [0.0, 0.0],
            },
            Primitive::Polygon(poly) => ShapeDef::Polygon {
                vertices: poly.vertices().iter().map(|v| a(*v)).collect(),
                center: [0.0, 0.0],
            },
            // Only a chain holds segments, and a chain is described whole (`chain_def`).
            Primitive::Segment(s) => ShapeDef::Chain {
                points: vec![a(s.a), a(s.b)],
                prev: s.prev.map(a),
                next: s.next.map(a),
            },
        }
    }
}

/// The description of a compound made by [`Shape::chain`]: its points and ghosts.
fn chain_def(parts: &[Primitive]) -> Option<ShapeDef> {
    let a = |v: Vec2| [v.x, v.y];
    let mut points = Vec::with_capacity(parts.len() + 1);
    let (mut prev, mut next) = (None, None);
    for (i, p) in parts.iter().enumerate() {
        let Primitive::Segment(s) = p else {
            return None;
        };
        if i == 0 {
            points.push(a(s.a));
            prev = s.prev.map(a);
        }
        points.push(a(s.b));
        next = s.next.map(a);
    }
    Some(ShapeDef::Chain { points, prev, next })
}
