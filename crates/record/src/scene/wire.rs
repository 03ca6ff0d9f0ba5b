//! The protobuf encoding of a drawing's primitives, byte for byte as prost writes them, in
//! one pass.
//!
//! prost encodes a nested message by measuring it first, and every message below it again
//! for each level above: a cylinder's vectors are measured three times before they are
//! written, each field through a call of its own. That was three quarters of a 10,000-body
//! drawing's cost (0.95 of 1.28 ms). These messages hold only doubles and other such
//! messages, so each is written once, its length patched in behind it. The encoding is
//! proto3's, as prost's derived code writes it: fields in the order of their numbers, a
//! double left out when it equals zero (either sign), a message field whenever it is set.
//! The tests compare every function with prost's encoding.

use ricochet_log::messages::fox::{
    Color, CubePrimitive, CylinderPrimitive, Point3, Pose, Quaternion, Vector3,
};

/// Wire type of a 64-bit fixed-width field.
const FIXED64: u8 = 1;
/// Wire type of a length-delimited field.
const LENGTH_DELIMITED: u8 = 2;

/// Appends field `tag` (at most 15: one byte of key) holding a double, unless it is zero.
fn double(out: &mut Vec<u8>, tag: u8, v: f64) {
    debug_assert!(tag < 16);
    if v != 0.0 {
        out.push(tag << 3 | FIXED64);
        out.extend_from_slice(&v.to_le_bytes());
    }
}

/// Appends field `tag` (at most 15) holding the message `body` writes: its length is
/// patched in after it is written.
fn nested(out: &mut Vec<u8>, tag: u8, body: impl FnOnce(&mut Vec<u8>)) {
    debug_assert!(tag < 16);
    out.push(tag << 3 | LENGTH_DELIMITED);
    let at = out.len();
    out.push(0);
    body(out);
    let len = out.len() - at - 1;
    if len < 0x80 {
        out[at] = len as u8;
    } else {
        // A length of two bytes or more (only a whole primitive's can be): the body moves
        // along to make room.
        let mut varint = Vec::with_capacity(10);
        prost::encoding::encode_varint(len as u64, &mut varint);
        out.splice(at..=at, varint);
    }
}

/// Field `tag` holding a `foxglove.Vector3`.
fn vector3(out: &mut Vec<u8>, tag: u8, v: &Vector3) {
    nested(out, tag, |out| {
        double(out, 1, v.x);
        double(out, 2, v.y);
        double(out, 3, v.z);
    });
}

/// Field `tag` holding a `foxglove.Quaternion`.
fn quaternion(out: &mut Vec<u8>, tag: u8, q: &Quaternion) {
    nested(out, tag, |out| {
        double(out, 1, q.x);
        double(out, 2, q.y);
        double(out, 3, q.z);
        double(out, 4, q.w);
    });
}

/// Field `tag` holding a `foxglove.Pose`.
fn pose(out: &mut Vec<u8>, tag: u8, p: &Pose) {
    nested(out, tag, |out| {
        if let Some(v) = &p.position {
            vector3(out, 1, v);
        }
        if let Some(q) = &p.orientation {
            quaternion(out, 2, q);
        }
    });
}

/// Field `tag` holding a `foxglove.Color`.
fn color(out: &mut Vec<u8>, tag: u8, c: &Color) {
    nested(out, tag, |out| {
        double(out, 1, c.r);
        double(out, 2, c.g);
        double(out, 3, c.b);
        double(out, 4, c.a);
    });
}

/// Field `tag` (at most 15) holding a `foxglove.Point3`.
pub(super) fn point3(out: &mut Vec<u8>, tag: u8, p: &Point3) {
    if p.x != 0.0 && p.y != 0.0 && p.z == 0.0 {
        // A drawing's usual point, in one piece.
        let mut field = [
            tag << 3 | LENGTH_DELIMITED,
            18,
            1 << 3 | FIXED64,
            0,
            0,
            0,
            0,
            0,
            0,
            0,
            0,
            2 << 3 | FIXED64,
            0,
            0,
            0,
            0,
            0,
            0,
            0,
            0,
        ];
        field[3..11].copy_from_slice(&p.x.to_le_bytes());
        field[12..20].copy_from_slice(&p.y.to_le_bytes());
        out.extend_from_slice(&field);
        return;
    }
    nested(out, tag, |out| {
        double(out, 1, p.x);
        double(out, 2, p.y);
        double(out, 3, p.z);
    });
}

/// A cube's or a cylinder's first two fields: its `pose` (1) and `size` (2), when set.
fn placed(out: &mut Vec<u8>, at: Option<&Pose>, size: Option<&Vector3>) {
    if let Some(p) = at {
        pose(out, 1, p);
    }
    if let Some(s) = size {
        vector3(out, 2, s);
    }
}

/// Field `tag` holding a `foxglove.CubePrimitive`.
pub(super) fn cube(out: &mut Vec<u8>, tag: u8, c: &CubePrimitive) {
    nested(out, tag, |out| {
        placed(out, c.pose.as_ref(), c.size.as_ref());
        if let Some(k) = &c.color {
            color(out, 3, k);
        }
    });
}

/// Field `tag` holding a `foxglove.CylinderPrimitive`.
pub(super) fn cylinder(out: &mut Vec<u8>, tag: u8, c: &CylinderPrimitive) {
    nested(out, tag, |out| {
        placed(out, c.pose.as_ref(), c.size.as_ref());
        double(out, 3, c.bottom_scale);
        double(out, 4, c.top_scale);
        if let Some(k) = &c.color {
            color(out, 5, k);
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// prost's encoding of `m` as field `tag`.
    fn prost_field(tag: u8, m: &impl prost::Message) -> Vec<u8> {
        let mut out = Vec::new();
        prost::encoding::message::encode(u32::from(tag), m, &mut out);
        out
    }

    /// Doubles as a drawing has them, and the ones it must leave out or keep.
    fn number() -> impl Strategy<Value = f64> {
        prop_oneof![
            Just(0.0),
            Just(-0.0),
            Just(1.0),
            Just(f64::NAN),
            Just(f64::INFINITY),
            Just(-f64::MIN_POSITIVE),
            any::<f64>(),
            (-1e4f32..1e4f32).prop_map(f64::from),
        ]
    }

    fn vec3() -> impl Strategy<Value = Option<Vector3>> {
        proptest::option::of(
            (number(), number(), number()).prop_map(|(x, y, z)| Vector3 { x, y, z }),
        )
    }

    fn rgba() -> impl Strategy<Value = Option<Color>> {
        proptest::option::of(
            (number(), number(), number(), number()).prop_map(|(r, g, b, a)| Color { r, g, b, a }),
        )
    }

    fn placed() -> impl Strategy<Value = Option<Pose>> {
        let q = proptest::option::of(
            (number(), number(), number(), number()).prop_map(|(x, y, z, w)| Quaternion {
                x,
                y,
                z,
                w,
            }),
        );
        proptest::option::of((vec3(), q).prop_map(|(position, orientation)| Pose {
            position,
            orientation,
        }))
    }

    proptest! {
        #[test]
        fn a_cylinder_is_prosts_bytes(
            pose in placed(), size in vec3(), bottom in number(), top in number(),
            color in rgba(), tag in 1u8..16,
        ) {
            let c = CylinderPrimitive { pose, size, bottom_scale: bottom, top_scale: top, color };
            let mut out = vec![7];
            cylinder(&mut out, tag, &c);
            prop_assert_eq!(&out[1..], prost_field(tag, &c));
        }

        #[test]
        fn a_cube_is_prosts_bytes(pose in placed(), size in vec3(), color in rgba()) {
            let c = CubePrimitive { pose, size, color };
            let mut out = Vec::new();
            cube(&mut out, 8, &c);
            prop_assert_eq!(out, prost_field(8, &c));
        }

        #[test]
        fn a_point_a_pose_and_a_colour_are_prosts_bytes(
            (x, y, z) in (number(), number(), number()), p in placed(), k in rgba(),
        ) {
            let point = Point3 { x, y, z };
            let mut out = Vec::new();
            point3(&mut out, 2, &point);
            prop_assert_eq!(out, prost_field(2, &point));
            if let Some(p) = p {
                let mut out = Vec::new();
                pose(&mut out, 1, &p);
                prop_assert_eq!(out, prost_field(1, &p));
            }
            if let Some(k) = k {
                let mut out = Vec::new();
                color(&mut out, 3, &k);
                prop_assert_eq!(out, prost_field(3, &k));
            }
        }
    }

    #[test]
    fn a_message_of_128_bytes_or_more_has_a_two_byte_length() {
        // Every field set and none zero: 3 + 4 doubles in the pose, 3 in the size, 2 scales,
        // 4 in the colour. 148 bytes of body.
        let v = Vector3 {
            x: 1.5,
            y: 2.5,
            z: 3.5,
        };
        let c = CylinderPrimitive {
            pose: Some(Pose {
                position: Some(v),
                orientation: Some(Quaternion {
                    x: 0.5,
                    y: 0.5,
                    z: 0.5,
                    w: 0.5,
                }),
            }),
            size: Some(v),
            bottom_scale: 1.0,
            top_scale: 2.0,
            color: Some(Color {
                r: 0.1,
                g: 0.2,
                b: 0.3,
                a: 0.4,
            }),
        };
        let mut out = Vec::new();
        cylinder(&mut out, 10, &c);
        assert!(out[1] & 0x80 != 0, "a two-byte length");
        assert_eq!(out, prost_field(10, &c));
    }
}
