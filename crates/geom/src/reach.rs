//! How far a shape reaches from its body's origin at any angle ([`Shape::reach`]), and the
//! test it gives two bodies before the narrow phase places their shapes ([`beyond_reach`]).
//!
//! A broad phase pairs bodies whose boxes overlap; a turned body's box is the square around
//! the disc that holds its shape at every angle, so a pair can be in each other's boxes and
//! yet too far apart for their discs to meet. Those pairs are ruled out by their centres'
//! distance alone: no sine or cosine, no placed vertex.

use crate::math::Vec2;
use crate::shape::{Primitive, Shape};

impl Shape {
    /// The largest distance from the body origin of any point of the shape, at any angle of
    /// the body (an AABB's centre turns with it, its box does not): a circle's or capsule's
    /// ends plus its radius, a box's centre plus its half diagonal, a polygon's or segment's
    /// farthest vertex; a compound's farthest part. Computed, so within a few units in the
    /// last place of the exact distance: [`beyond_reach`] leaves a margin far above that.
    #[must_use]
    pub fn reach(&self) -> f64 {
        let far = |points: &[Vec2]| points.iter().fold(0.0, |r: f64, p| r.max(p.length()));
        self.primitives()
            .iter()
            .map(|p| match p {
                Primitive::Circle(c) => c.center.length() + c.radius,
                Primitive::Aabb(b) => b.center.length() + b.half_extents.length(),
                Primitive::Obb(b) => b.center.length() + b.half_extents.length(),
                Primitive::Capsule(c) => far(&[c.a, c.b]) + c.radius,
                Primitive::Segment(s) => far(&[s.a, s.b]),
                Primitive::Polygon(g) => far(g.vertices()),
            })
            .fold(0.0, f64::max)
    }
}

/// Whether two bodies whose positions differ by `d` (`b`'s minus `a`'s, as the narrow phase
/// subtracts them) and whose shapes reach `reach` together ([`Shape::reach`] of each, added)
/// are apart by more than any rounding: their discs do not meet, with a relative margin of
/// `1e-9`. Then their contact's depth is below 0, and `contact_deeper_than(.., t)` is `None`
/// for every `t >= 0`. False with a NaN or an infinity anywhere: the narrow phase decides.
#[must_use]
#[inline]
pub fn beyond_reach(d: Vec2, reach: f64) -> bool {
    let r = reach * (1.0 + 1e-9);
    d.dot(d) > r * r
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use crate::{Pose, Shape, Vec2, contact};

    use super::beyond_reach;

    /// A shape of every kind, off the body origin or not.
    fn shape() -> impl Strategy<Value = Shape> {
        let v = || (-2.0..2.0f64, -2.0..2.0f64).prop_map(|(x, y)| Vec2::new(x, y));
        let size = || 0.05..1.5f64;
        prop_oneof![
            (v(), size()).prop_map(|(c, r)| Shape::Primitive(
                crate::Primitive::circle(c, r).expect("a circle")
            )),
            (v(), size(), size()).prop_map(|(c, w, h)| Shape::Primitive(
                crate::Primitive::aabb(c, Vec2::new(w, h)).expect("a box")
            )),
            (v(), size(), size(), -3.0..3.0f64).prop_map(|(c, w, h, a)| Shape::Primitive(
                crate::Primitive::obb(c, Vec2::new(w, h), a).expect("a box")
            )),
            (v(), v(), size())
                .prop_filter_map("a capsule", |(a, b, r)| Shape::capsule(a, b, r).ok()),
            (3..9usize, size(), v()).prop_filter_map("a polygon", |(n, r, c)| {
                let vertices: Vec<Vec2> = (0..n)
                    .map(|k| {
                        let t = std::f64::consts::TAU * k as f64 / n as f64;
                        c + Vec2::new(r * libm::cos(t), r * (0.5 + 0.5 * libm::sin(t)))
                    })
                    .collect();
                Shape::polygon(&vertices).ok()
            }),
        ]
    }

    proptest! {
        /// Every point of a shape placed at any angle is within its reach: the placed
        /// shape's box is, corner by corner's coordinates (a point's coordinate is at most
        /// its distance).
        #[test]
        fn a_shape_at_any_angle_is_within_its_reach(s in shape(), angle in -10.0..10.0f64) {
            let b = s.bounds(&Pose::new(Vec2::ZERO, angle));
            let r = s.reach();
            for v in [b.min.x, b.min.y, b.max.x, b.max.y] {
                prop_assert!(v.abs() <= r * (1.0 + 1e-12), "{} past {}", v, r);
            }
        }

        /// Two bodies whose discs just miss (by the margin, and a little more) never have a
        /// contact deeper than 0, at any angles, in any direction, far from the origin or
        /// not: what lets the narrow phase skip them.
        #[test]
        fn bodies_beyond_reach_have_no_contact(
            a in shape(),
            b in shape(),
            (ta, tb, dir) in (-10.0..10.0f64, -10.0..10.0f64, -4.0..4.0f64),
            gap in prop_oneof![Just(0.0), 0.0..1e-6f64, 0.0..1.0f64],
            origin in prop_oneof![Just(Vec2::ZERO), Just(Vec2::new(1e6, -3e5))],
        ) {
            let reach = a.reach() + b.reach();
            let d = Vec2::new(libm::cos(dir), libm::sin(dir)) * (reach * (1.0 + 2e-9) + gap);
            let (pa, pb) = (Pose::new(origin, ta), Pose::new(origin + d, tb));
            let d = pb.position - pa.position;
            if beyond_reach(d, reach) {
                let c = contact(&a, &pa, &b, &pb);
                prop_assert!(c.depth < 0.0, "depth {} at {} apart", c.depth, d.length());
            }
        }
    }

    /// The margin: discs that meet, or miss by less than it, are left to the narrow phase;
    /// a NaN or an infinity too.
    #[test]
    fn discs_that_meet_or_nearly_are_not_beyond_reach() {
        let x = Vec2::new(1.0, 0.0);
        assert!(!beyond_reach(x * 2.0, 2.0));
        assert!(!beyond_reach(x * (2.0 + 1e-10), 2.0));
        assert!(beyond_reach(x * (2.0 + 1e-8), 2.0));
        assert!(!beyond_reach(Vec2::new(f64::NAN, 0.0), 1.0));
        assert!(!beyond_reach(x * 3.0, f64::INFINITY));
        assert!(!beyond_reach(x * 3.0, f64::NAN));
    }

    /// Each kind's reach, against its farthest point worked out by hand.
    #[test]
    fn reach_of_each_kind() {
        let v = Vec2::new;
        let circle = Shape::Primitive(crate::Primitive::circle(v(3.0, 4.0), 1.0).unwrap());
        assert_eq!(circle.reach(), 6.0);
        let aabb = Shape::Primitive(crate::Primitive::aabb(v(0.0, 5.0), v(3.0, 4.0)).unwrap());
        assert_eq!(aabb.reach(), 10.0);
        let capsule = Shape::capsule(v(-3.0, 0.0), v(0.0, 4.0), 0.5).unwrap();
        assert_eq!(capsule.reach(), 4.5);
        let triangle = Shape::polygon(&[v(0.0, 0.0), v(6.0, 8.0), v(-1.0, 1.0)]).unwrap();
        assert_eq!(triangle.reach(), 10.0);
    }
}
