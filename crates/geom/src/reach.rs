//! How far a shape reaches from its body's origin at any angle ([`Shape::reach`]), and the
//! test it gives two bodies before the narrow phase places their shapes ([`beyond_reach`]).
//!
//! A broad phase pairs bodies whose boxes overlap; a turned body's box is the square around
//! the disc that holds its shape at every angle, so a pair can be in each other's boxes and
//! yet too far apart for their discs to meet. Those pairs are ruled out by their centres'
//! distance alone: no sine or cosine, no placed vertex.

use crate::math::Vec2;
use crate::shape::{Primitive, Shape};
use crate::toi::Sweep;

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

/// Whether shapes `a` and `b`, moving on their sweeps (straight lines at fixed angles), keep
/// their discs apart by more than `tol` for the whole step: the closest approach of their
/// positions (`b`'s minus `a`'s, a point on a line, exactly the nearest point of a segment
/// to the origin) beyond their reaches plus `tol`, with a margin far above the rounding of
/// that approach and of the time of impact's poses (`1e-8` of the reaches, `1e-12` of the
/// coordinates). Then the shapes never come within `tol` of touching.
pub(crate) fn paths_beyond_reach(
    (a, sweep_a): (&Shape, &Sweep),
    (b, sweep_b): (&Shape, &Sweep),
    tol: f64,
) -> bool {
    let d0 = sweep_b.start - sweep_a.start;
    let v = (sweep_b.end - sweep_b.start) - (sweep_a.end - sweep_a.start);
    let vv = v.dot(v);
    let t = if vv > 0.0 {
        (-d0.dot(v) / vv).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let reach = a.reach() + b.reach();
    let size = |p: Vec2| p.x.abs() + p.y.abs();
    let coordinates =
        size(sweep_a.start) + size(sweep_a.end) + size(sweep_b.start) + size(sweep_b.end);
    beyond_reach(d0 + v * t, reach + tol + 1e-8 * reach + 1e-12 * coordinates)
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use crate::{Pose, Shape, Sweep, Vec2, contact};

    use super::{beyond_reach, paths_beyond_reach};

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

    proptest! {
        /// Two shapes whose discs stay apart over their whole sweeps (passing as near as
        /// the margin allows, or further) are never found touching by the search itself, at
        /// any angles, near the origin and at 1e6: what lets `time_of_impact` skip it.
        #[test]
        fn paths_beyond_reach_never_touch(
            a in shape(),
            b in shape(),
            (ta, tb, dir, along) in (-10.0..10.0f64, -10.0..10.0f64, -4.0..4.0f64, -30.0..30.0f64),
            (t, gap) in (0.0..1.0f64, prop_oneof![Just(0.0), 0.0..1e-6f64, 0.0..1.0f64]),
            a_moves in (-20.0..20.0f64, -20.0..20.0f64),
            origin in prop_oneof![Just(Vec2::ZERO), Just(Vec2::new(1e6, -3e5))],
        ) {
            // `b`'s path relative to `a`'s passes nearest at `t`, `reach (1 + 2e-8) + gap`
            // away along `n`, moving along `n`'s perpendicular.
            let n = Vec2::new(libm::cos(dir), libm::sin(dir));
            let reach = a.reach() + b.reach();
            let near = n * (reach * (1.0 + 2e-8) + 1e-9 + gap);
            let rel = Vec2::new(-n.y, n.x) * along;
            let a_moves = Vec2::new(a_moves.0, a_moves.1);
            let sa = Sweep { start: origin, end: origin + a_moves, angle: ta };
            let start_b = origin + near - rel * t;
            let sb = Sweep { start: start_b, end: start_b + rel + a_moves, angle: tb };
            let tol = 1e-9 * reach;
            if paths_beyond_reach((&a, &sa), (&b, &sb), tol) {
                prop_assert!(crate::toi::searched(&a, &sa, &b, &sb, tol).is_none());
            }
        }
    }

    /// A head-on path is never beyond reach; one that passes wide always is.
    #[test]
    fn paths_that_meet_are_not_beyond_reach() {
        let c = Shape::circle(1.0).unwrap();
        let at = |x: f64, y: f64, to: f64| Sweep {
            start: Vec2::new(x, y),
            end: Vec2::new(to, y),
            angle: 0.0,
        };
        let still = at(0.0, 0.0, 0.0);
        assert!(!paths_beyond_reach(
            (&c, &still),
            (&c, &at(10.0, 0.0, -10.0)),
            0.0
        ));
        assert!(!paths_beyond_reach(
            (&c, &still),
            (&c, &at(10.0, 1.99, -10.0)),
            0.0
        ));
        assert!(paths_beyond_reach(
            (&c, &still),
            (&c, &at(10.0, 2.01, -10.0)),
            0.0
        ));
        // Stopping short of the other: the nearest point is the path's end.
        assert!(paths_beyond_reach(
            (&c, &still),
            (&c, &at(10.0, 0.0, 2.01)),
            0.0
        ));
        assert!(!paths_beyond_reach(
            (&c, &still),
            (&c, &at(10.0, 0.0, 1.99)),
            0.0
        ));
        let nan = at(f64::NAN, 0.0, 0.0);
        assert!(!paths_beyond_reach((&c, &still), (&c, &nan), 0.0));
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
