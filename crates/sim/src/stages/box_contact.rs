//! The contact the per-axis passes log for a pair of boxes: [`ricochet_geom::contact`] bit
//! for bit, without its general path.
//!
//! `contact` places every part of both shapes in the frame of the first body, finds the
//! deepest pair of parts and moves the answer back to the world: for two single boxes that
//! is one call of the box–box function between the same placed boxes, and the general
//! path's bookkeeping (the parts, the rotations, the choice of the deepest) costs several
//! times the call. Here the two boxes are placed with the same arithmetic, operation for
//! operation, so the contact is the same to the bit; any other pair of shapes goes the
//! general way.

use ricochet_geom::pairs::collide_aabb_aabb;
use ricochet_geom::{Contact, PlacedAabb, Pose, Primitive, Shape, Vec2, contact};

/// The contact of `a` at `pose_a` with `b` at `pose_b`, exactly as [`contact`] gives it.
pub(crate) fn box_contact(a: &Shape, pose_a: &Pose, b: &Shape, pose_b: &Pose) -> Contact {
    let (Shape::Primitive(Primitive::Aabb(ba)), Shape::Primitive(Primitive::Aabb(bb))) = (a, b)
    else {
        return contact(a, pose_a, b, pose_b);
    };
    // The pair's frame is centred on `a`'s position; each box's centre is its body's
    // position in that frame plus its own centre turned with the body (not at all, for a
    // box on the body origin).
    let origin = pose_a.position;
    let placed_a = PlacedAabb {
        center: Vec2::ZERO + a.rotation(pose_a.angle).apply(ba.center),
        half: ba.half_extents,
    };
    let placed_b = PlacedAabb {
        center: (pose_b.position - origin) + b.rotation(pose_b.angle).apply(bb.center),
        half: bb.half_extents,
    };
    collide_aabb_aabb(&placed_a, &placed_b).translated(origin)
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    /// A coordinate: small, large, on a half, or a signed zero.
    fn coordinate() -> impl Strategy<Value = f64> {
        prop_oneof![
            Just(0.0),
            Just(-0.0),
            Just(0.5),
            -20.0..20.0f64,
            -1e7..1e7f64,
        ]
    }

    fn aabb() -> impl Strategy<Value = Shape> {
        (
            0.05..3.0f64,
            0.05..3.0f64,
            coordinate(),
            coordinate(),
            any::<bool>(),
        )
            .prop_map(|(hx, hy, cx, cy, offset)| {
                let half = Vec2::new(hx, hy);
                if offset {
                    let centre = Vec2::new(cx * 1e-3, cy * 1e-3);
                    Shape::Primitive(Primitive::aabb(centre, half).expect("positive half extents"))
                } else {
                    Shape::aabb(half).expect("positive half extents")
                }
            })
    }

    fn pose() -> impl Strategy<Value = Pose> {
        (
            coordinate(),
            coordinate(),
            prop_oneof![Just(0.0), -3.0..3.0f64],
        )
            .prop_map(|(x, y, angle)| Pose::new(Vec2::new(x, y), angle))
    }

    fn bits(c: &Contact) -> [u64; 5] {
        [
            c.depth.to_bits(),
            c.normal.x.to_bits(),
            c.normal.y.to_bits(),
            c.point.x.to_bits(),
            c.point.y.to_bits(),
        ]
    }

    proptest! {
        #[test]
        fn a_box_pair_contact_is_the_general_contact_to_the_bit(
            a in aabb(),
            pose_a in pose(),
            b in aabb(),
            near in (-2.0..2.0f64, -2.0..2.0f64),
            far in pose(),
            use_far in any::<bool>(),
        ) {
            // Near `a` (overlapping or touching, the per-axis passes' case), or anywhere.
            let pose_b = if use_far {
                far
            } else {
                Pose::new(pose_a.position + Vec2::new(near.0, near.1), far.angle)
            };
            let general = contact(&a, &pose_a, &b, &pose_b);
            prop_assert_eq!(bits(&box_contact(&a, &pose_a, &b, &pose_b)), bits(&general));
        }
    }

    #[test]
    fn other_shapes_take_the_general_path() {
        let ball = Shape::circle(0.5).expect("a positive radius");
        let tile = Shape::aabb(Vec2::splat(0.5)).expect("positive half extents");
        let (p, q) = (
            Pose::new(Vec2::ZERO, 0.0),
            Pose::new(Vec2::new(0.7, 0.2), 0.0),
        );
        let general = contact(&ball, &p, &tile, &q);
        assert_eq!(bits(&box_contact(&ball, &p, &tile, &q)), bits(&general));
        assert!((general.depth - 0.3).abs() < 1e-12);
    }
}
