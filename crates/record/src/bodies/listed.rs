//! The list of bodies of a `/bodies` message, encoded as the tracker lists them.
//!
//! A keyframe lists 10,000 bodies of a big scene whole. Built as prost messages first, each
//! was a dozen allocations (its name, layer, shape, position and velocity) in a list of
//! 2.5 MB touched for the first time, measured whole to pace the keyframes, then encoded on
//! the writer thread (BENCHMARKS.md, "the drawing and the keyframe encoded as they are
//! made"). A body listed whole is written here from the world's values (a compound's or a
//! chain's shape still built as a message first), each field as prost encodes it, in the
//! order and with the presence rules of prost's derived code for `ricochet.Body` and
//! `ricochet.Shape`; any other body is built and encoded by prost. The tests compare the
//! bytes with prost's encoding of the same messages.

use prost::Message;
use prost::encoding::{
    WireType, bool as pbool, double, encode_key, encode_varint, encoded_len_varint, key_len,
    message as pmessage, uint32,
};
use ricochet_geom::{Primitive, Shape, ShapeDef, Vec2};
use ricochet_log::messages::ricochet as pb;
use ricochet_sim::Entity;

use super::shape_message;

/// About what a body listed whole takes, encoded (a hexagon's is 160 bytes, a circle's 110):
/// the room a keyframe reserves for each. Better a little over: the 10,000-asteroid level
/// averages 149, and 144 made its first keyframe's list grow once at the end, a copy of
/// 1.4 MB (0.9 of the frame's 2.6 ms).
pub(super) const BODY_BYTES: usize = 160;

/// The field number of `ricochet.Bodies.bodies`.
const BODIES: u32 = 4;

/// A body listed with every field (in a keyframe, or new), as `ricochet.Body` holds it.
pub(super) struct Whole<'a> {
    pub entity: Entity,
    pub name: &'a str,
    pub layer: &'a str,
    /// The shape, encoded as a `ricochet.Shape` message's fields ([`shape`]).
    pub shape: &'a [u8],
    pub is_static: bool,
    pub position: Vec2,
    pub angle: f64,
    pub velocity: Vec2,
    pub angular_velocity: f64,
    pub falling: Option<bool>,
}

/// A string field's key, length and bytes.
fn string(tag: u32, s: &str, out: &mut Vec<u8>) {
    encode_key(tag, WireType::LengthDelimited, out);
    encode_varint(s.len() as u64, out);
    out.extend_from_slice(s.as_bytes());
}

fn string_len(tag: u32, s: &str) -> usize {
    key_len(tag) + encoded_len_varint(s.len() as u64) + s.len()
}

impl Whole<'_> {
    /// Appends the body to `out` as a `bodies` field of `ricochet.Bodies`.
    pub(super) fn encode(&self, out: &mut Vec<u8>) {
        let Entity { index, generation } = self.entity;
        let (position, velocity) = (self.position.to_array(), self.velocity.to_array());
        let len = if index != 0 {
            uint32::encoded_len(1, &index)
        } else {
            0
        } + if generation != 0 {
            uint32::encoded_len(2, &generation)
        } else {
            0
        } + string_len(3, self.name)
            + string_len(4, self.layer)
            + key_len(5)
            + encoded_len_varint(self.shape.len() as u64)
            + self.shape.len()
            + pbool::encoded_len(6, &self.is_static)
            + double::encoded_len_packed(7, &position)
            + double::encoded_len(8, &self.angle)
            + double::encoded_len_packed(9, &velocity)
            + double::encoded_len(10, &self.angular_velocity)
            + self.falling.map_or(0, |f| pbool::encoded_len(12, &f));
        encode_key(BODIES, WireType::LengthDelimited, out);
        encode_varint(len as u64, out);
        if index != 0 {
            uint32::encode(1, &index, out);
        }
        if generation != 0 {
            uint32::encode(2, &generation, out);
        }
        string(3, self.name, out);
        string(4, self.layer, out);
        encode_key(5, WireType::LengthDelimited, out);
        encode_varint(self.shape.len() as u64, out);
        out.extend_from_slice(self.shape);
        pbool::encode(6, &self.is_static, out);
        double::encode_packed(7, &position, out);
        double::encode(8, &self.angle, out);
        double::encode_packed(9, &velocity, out);
        double::encode(10, &self.angular_velocity, out);
        // `still` (11) is false for a body listed whole: left out.
        if let Some(f) = self.falling {
            pbool::encode(12, &f, out);
        }
    }
}

/// Appends `shape` to `out` as the fields of the `ricochet.Shape` message `/bodies` writes
/// for it (`super::shape_message`): a primitive written from its values, a compound or a
/// chain built as that message first.
pub(super) fn shape(shape: &Shape, out: &mut Vec<u8>) {
    // The kind's field number in `Shape`, and the kind's message's length.
    let (kind, len) = match shape {
        Shape::Primitive(Primitive::Circle(c)) => (1, nonzero(c.radius) + PAIR),
        Shape::Primitive(Primitive::Aabb(_)) => (2, 2 * PAIR),
        Shape::Primitive(Primitive::Obb(b)) => (3, 2 * PAIR + nonzero(b.angle)),
        Shape::Primitive(Primitive::Capsule(c)) => (4, 2 * PAIR + nonzero(c.radius)),
        Shape::Primitive(Primitive::Polygon(p)) => (5, packed_len(p.vertices().len())),
        _ => {
            shape_message(&ShapeDef::from_shape(shape)).encode_raw(out);
            return;
        }
    };
    encode_key(kind, WireType::LengthDelimited, out);
    encode_varint(len as u64, out);
    // `shape_message` adds a capsule's and a polygon's centre, zero, to their points: so
    // does this (it turns -0.0 into 0.0).
    let centred = |v: Vec2| Vec2::new(v.x + 0.0, v.y + 0.0);
    match shape {
        Shape::Primitive(Primitive::Circle(c)) => {
            double_unless_zero(1, c.radius, out);
            packed(2, &[c.center], out);
        }
        Shape::Primitive(Primitive::Aabb(b)) => {
            packed(1, &[b.half_extents], out);
            packed(2, &[b.center], out);
        }
        Shape::Primitive(Primitive::Obb(b)) => {
            packed(1, &[b.half_extents], out);
            packed(2, &[b.center], out);
            double_unless_zero(3, b.angle, out);
        }
        Shape::Primitive(Primitive::Capsule(c)) => {
            packed(1, &[centred(c.a)], out);
            packed(2, &[centred(c.b)], out);
            double_unless_zero(3, c.radius, out);
        }
        Shape::Primitive(Primitive::Polygon(p)) => {
            encode_key(1, WireType::LengthDelimited, out);
            encode_varint(16 * p.vertices().len() as u64, out);
            for v in p.vertices() {
                let v = centred(*v);
                out.extend_from_slice(&v.x.to_le_bytes());
                out.extend_from_slice(&v.y.to_le_bytes());
            }
        }
        _ => unreachable!("every other shape returned above"),
    }
}

/// The bytes of a field of one point, packed (`[x, y]`: key, length, 16 bytes).
const PAIR: usize = 18;

/// The bytes of a double field, left out when it is zero (either sign).
fn nonzero(v: f64) -> usize {
    if v != 0.0 { 9 } else { 0 }
}

/// The bytes of a field of `n` points, packed.
fn packed_len(n: usize) -> usize {
    let len = 16 * n as u64;
    1 + encoded_len_varint(len) + len as usize
}

/// A double field, left out when it is zero (either sign), as prost writes a proto3 double.
fn double_unless_zero(tag: u32, v: f64, out: &mut Vec<u8>) {
    if v != 0.0 {
        double::encode(tag, &v, out);
    }
}

/// A field of points, packed as `[x0, y0, x1, y1, ...]`.
fn packed(tag: u32, points: &[Vec2], out: &mut Vec<u8>) {
    encode_key(tag, WireType::LengthDelimited, out);
    encode_varint(16 * points.len() as u64, out);
    for v in points {
        out.extend_from_slice(&v.x.to_le_bytes());
        out.extend_from_slice(&v.y.to_le_bytes());
    }
}

/// Appends `body` to `out` as a `bodies` field of `ricochet.Bodies`.
pub(super) fn encode(body: &pb::Body, out: &mut Vec<u8>) {
    pmessage::encode(BODIES, body, out);
}

/// The encoding of `bodies` (whose own list is empty) with `listed` as its list of bodies:
/// fields are written in the order of their numbers, and the list's (4) is between
/// `keyframe` (3) and `removed` (5). The list's bytes move along in place to make room for
/// the fields before it, rather than being copied into a new allocation (a keyframe's is
/// 1.4 MB, its pages then touched for the first time).
pub(super) fn message(bodies: &pb::Bodies, mut listed: Vec<u8>) -> Vec<u8> {
    debug_assert!(bodies.bodies.is_empty(), "the list is `listed`");
    let head = pb::Bodies {
        frame: bodies.frame,
        time: bodies.time,
        keyframe: bodies.keyframe,
        ..pb::Bodies::default()
    };
    let tail = pb::Bodies {
        frame: 0,
        time: 0.0,
        keyframe: false,
        bodies: Vec::new(),
        removed: bodies.removed.clone(),
        dt: bodies.dt,
        gravity: bodies.gravity.clone(),
    };
    listed.reserve(head.encoded_len() + tail.encoded_len());
    listed.splice(0..0, head.encode_to_vec());
    tail.encode_raw(&mut listed);
    listed
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The `Body` prost would encode for `w` of shape `shape`: how the tracker built a body
    /// listed whole.
    fn built(w: &Whole, shape: &pb::Shape) -> pb::Body {
        pb::Body {
            id: w.entity.index,
            generation: w.entity.generation,
            name: Some(w.name.to_owned()),
            layer: Some(w.layer.to_owned()),
            shape: Some(shape.clone()),
            r#static: Some(w.is_static),
            position: w.position.to_array().to_vec(),
            angle: Some(w.angle),
            velocity: w.velocity.to_array().to_vec(),
            angular_velocity: Some(w.angular_velocity),
            still: false,
            falling: w.falling,
        }
    }

    fn number() -> impl Strategy<Value = f64> {
        prop_oneof![
            Just(0.0),
            Just(-0.0),
            Just(f64::NAN),
            Just(f64::NEG_INFINITY),
            any::<f64>(),
        ]
    }

    fn pb_shape() -> impl Strategy<Value = pb::Shape> {
        use pb::shape::Kind;
        prop_oneof![
            (number(), number()).prop_map(|(r, c)| Kind::Circle(pb::Circle {
                radius: r,
                center: vec![c, 0.5],
            })),
            proptest::collection::vec(number(), 0..40)
                .prop_map(|vertices| Kind::Polygon(pb::Polygon { vertices })),
        ]
        .prop_map(|kind| pb::Shape { kind: Some(kind) })
    }

    proptest! {
        #[test]
        fn a_body_listed_whole_is_prosts_encoding_of_it(
            index in prop_oneof![Just(0u32), any::<u32>()],
            generation in prop_oneof![Just(0u32), any::<u32>()],
            name in ".{0,200}", layer in "[a-z]{0,12}", shape in pb_shape(),
            is_static: bool,
            (px, py, angle, vx, vy, spin) in
                (number(), number(), number(), number(), number(), number()),
            falling in proptest::option::of(any::<bool>()),
        ) {
            let encoded = shape.encode_to_vec();
            let w = Whole {
                entity: Entity { index, generation },
                name: &name,
                layer: &layer,
                shape: &encoded,
                is_static,
                position: Vec2::new(px, py),
                angle,
                velocity: Vec2::new(vx, vy),
                angular_velocity: spin,
                falling,
            };
            let mut out = vec![9];
            w.encode(&mut out);
            let mut want = vec![9];
            pmessage::encode(BODIES, &built(&w, &shape), &mut want);
            prop_assert_eq!(out, want);
        }
    }

    /// Points as a shape has them, zeros of both signs among them.
    fn point() -> impl Strategy<Value = Vec2> {
        let c = prop_oneof![Just(0.0), Just(-0.0), -50.0..50.0f64];
        (c.clone(), c).prop_map(|(x, y)| Vec2::new(x, y))
    }

    /// A shape of every kind `/bodies` writes: each primitive, a compound, a chain.
    fn any_shape() -> impl Strategy<Value = Shape> {
        let r = prop_oneof![Just(0.0), 0.01..5.0f64];
        let primitive = prop_oneof![
            (point(), r.clone()).prop_map(|(c, r)| Primitive::circle(c, r.max(0.01))),
            (point(), point()).prop_map(|(c, h)| Primitive::aabb(c, h.abs() + Vec2::splat(0.1))),
            (
                point(),
                point(),
                prop_oneof![Just(0.0), Just(-0.0), -3.0..3.0f64]
            )
                .prop_map(|(c, h, a)| Primitive::obb(c, h.abs() + Vec2::splat(0.1), a)),
            (point(), point(), r).prop_map(|(a, b, r)| Primitive::capsule(
                a,
                b + Vec2::new(0.5, 0.0),
                r
            )),
            (point(), 3usize..9).prop_map(|(c, n)| {
                let v: Vec<Vec2> = (0..n)
                    .map(|k| {
                        let t = k as f64 / n as f64 * std::f64::consts::TAU;
                        c + Vec2::new(libm::cos(t), libm::sin(t))
                    })
                    .collect();
                Primitive::polygon(&v)
            }),
        ]
        .prop_filter_map("a valid primitive", Result::ok);
        prop_oneof![
            4 => primitive.clone().prop_map(Shape::Primitive),
            1 => proptest::collection::vec(primitive, 2..4)
                .prop_filter_map("a valid compound", |p| Shape::compound(p).ok()),
            1 => Just(
                Shape::chain(&[Vec2::new(-0.0, 0.0), Vec2::new(1.0, 2.0), Vec2::new(3.0, -0.0)], None, None)
                    .expect("a valid chain")
            ),
        ]
    }

    proptest! {
        #[test]
        fn a_shape_is_prosts_encoding_of_its_message(s in any_shape()) {
            let mut out = vec![1];
            shape(&s, &mut out);
            let mut want = vec![1];
            shape_message(&ShapeDef::from_shape(&s)).encode_raw(&mut want);
            prop_assert_eq!(out, want);
        }
    }

    #[test]
    fn the_message_is_prosts_encoding_of_it_with_its_list() {
        let body = |index| pb::Body {
            id: index,
            generation: 1,
            position: vec![1.0, -2.0],
            still: index % 2 == 0,
            ..pb::Body::default()
        };
        let whole = pb::Bodies {
            frame: 420,
            time: 7.0,
            keyframe: true,
            bodies: (0..5).map(body).collect(),
            removed: vec![body(9)],
            dt: 1.0 / 60.0,
            gravity: vec![0.0, -9.8],
        };
        let mut listed = Vec::new();
        whole.bodies.iter().for_each(|b| encode(b, &mut listed));
        let rest = pb::Bodies {
            bodies: Vec::new(),
            ..whole.clone()
        };
        assert_eq!(message(&rest, listed), whole.encode_to_vec());
        let empty = pb::Bodies::default();
        assert_eq!(message(&empty, Vec::new()), empty.encode_to_vec());
    }
}
