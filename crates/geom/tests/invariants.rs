//! Invariants of the narrow phase over random shapes and poses (proptest), and degenerate
//! inputs that must still give a finite unit normal.

use proptest::prelude::*;
use ricochet_geom::pairs::collide_cores;
use ricochet_geom::{
    Bounds, Contact, Pose, Primitive, Rot, Shape, Vec2, contact, contact_deeper_than,
    contact_placed, overlaps, overlaps_placed, overlaps_placing, place, place_rotated,
    placed_bounds,
};

const TAU: f64 = std::f64::consts::TAU;

fn v(x: f64, y: f64) -> Vec2 {
    Vec2::new(x, y)
}

fn primitive() -> impl Strategy<Value = Primitive> {
    let size = 0.05f64..3.0;
    let offset = (-1.0f64..1.0, -1.0f64..1.0);
    prop_oneof![
        (size.clone(), offset.clone())
            .prop_map(|(r, (x, y))| Primitive::circle(v(x, y), r).unwrap()),
        (size.clone(), size.clone(), offset.clone()).prop_map(|(w, h, (x, y))| Primitive::aabb(
            v(x, y),
            v(w, h)
        )
        .unwrap()),
        (size.clone(), size.clone(), offset.clone(), -3.2f64..3.2)
            .prop_map(|(w, h, (x, y), a)| Primitive::obb(v(x, y), v(w, h), a).unwrap()),
        (offset.clone(), offset.clone(), size.clone()).prop_map(|((ax, ay), (bx, by), r)| {
            Primitive::capsule(v(ax, ay), v(bx, by), r).unwrap()
        }),
        (
            proptest::collection::vec(0.0f64..1.0, 3..=8),
            size.clone(),
            size,
            offset
        )
            .prop_filter_map("a convex polygon", |(mut ts, sx, sy, (x, y))| {
                // Points on an ellipse in angular order are convex and counter-clockwise.
                ts.sort_by(f64::total_cmp);
                let pts: Vec<Vec2> = ts
                    .iter()
                    .map(|t| v(x + sx * libm::cos(t * TAU), y + sy * libm::sin(t * TAU)))
                    .collect();
                Primitive::polygon(&pts).ok()
            }),
    ]
}

fn shape() -> impl Strategy<Value = Shape> {
    prop_oneof![
        4 => primitive().prop_map(Shape::Primitive),
        1 => proptest::collection::vec(primitive(), 1..4)
            .prop_map(|parts| Shape::compound(parts).unwrap()),
    ]
}

fn pose() -> impl Strategy<Value = Pose> {
    (-4.0f64..4.0, -4.0f64..4.0, -3.2f64..3.2).prop_map(|(x, y, a)| Pose::new(v(x, y), a))
}

fn has_aabb(s: &Shape) -> bool {
    s.primitives()
        .iter()
        .any(|p| matches!(p, Primitive::Aabb(_)))
}

/// Rounding allowance: the inputs are O(1..10), so a few hundred ulps of 10.
const EPS: f64 = 1e-11;

/// Whether pushing `b` by `depth` along `n` separates the pair (up to rounding): what makes
/// `n` a valid minimum translation direction when several faces tie.
fn separates(a: &Shape, pa: &Pose, b: &Shape, pb: &Pose, n: Vec2, depth: f64) -> bool {
    let moved = Pose::new(pb.position + n * depth, pb.angle);
    contact(a, pa, b, &moved).depth <= 1e-9
}

/// Every bit of a contact: `-0.0` and `0.0` differ here.
fn bits(c: Contact) -> [u64; 5] {
    [c.depth, c.normal.x, c.normal.y, c.point.x, c.point.y].map(f64::to_bits)
}

fn assert_unit(c: &Contact) {
    assert!(
        c.depth.is_finite() && c.normal.is_finite() && c.point.is_finite(),
        "{c:?}"
    );
    assert!((c.normal.length() - 1.0).abs() < 1e-12, "{c:?}");
}

/// A box's four coordinates as bits: `-0.0` and `0.0` differ, a NaN is its own bits.
fn box_bits(b: Bounds) -> [u64; 4] {
    [b.min.x, b.min.y, b.max.x, b.max.y].map(f64::to_bits)
}

proptest! {
    /// `placed_bounds` is the box of the part `place_rotated` places, bit for bit, for every
    /// kind of part, angle and position (far ones too, where rounding shows).
    #[test]
    fn placed_bounds_is_the_placed_parts_box_bit_for_bit(
        p in primitive(),
        pose in pose(),
        far in prop_oneof![Just(1.0), Just(1e6), Just(1e-9)],
    ) {
        let (at, rot) = (pose.position * far, Rot::from_angle(pose.angle));
        prop_assert_eq!(
            box_bits(placed_bounds(&p, at, rot, pose.angle)),
            box_bits(place_rotated(&p, at, rot, pose.angle).bounds())
        );
    }

    /// `overlaps_placing` (a box against a box placed inline) answers as
    /// `overlaps_placed` of the part `place_rotated` places, for every kind of part, and
    /// for boxes on a half-unit lattice, edge to edge (touching: no overlap) often.
    #[test]
    fn overlaps_placing_is_overlaps_placed_of_the_placed_part(
        (a, b) in prop_oneof![
            (primitive(), primitive()),
            ((-6i32..6, -6i32..6, 1i32..4, 1i32..4), (-6i32..6, -6i32..6, 1i32..4, 1i32..4))
                .prop_map(|(a, b)| {
                    let boxed = |(x, y, w, h): (i32, i32, i32, i32)| {
                        let half = |k: i32| f64::from(k) * 0.5;
                        Primitive::aabb(v(half(x), half(y)), v(half(w), half(h))).unwrap()
                    };
                    (boxed(a), boxed(b))
                }),
        ],
        pa in pose(),
        (x, y) in (-8i32..8, -8i32..8),
        angle in prop_oneof![Just(0.0), -3.2f64..3.2],
    ) {
        let lattice = v(f64::from(x) * 0.5, f64::from(y) * 0.5);
        for (placed_a, at) in [
            (place(&a, &Pose::new(Vec2::ZERO, 0.0), Vec2::ZERO), lattice),
            (place(&a, &pa, Vec2::ZERO), pa.position + lattice * 0.37),
        ] {
            let rot = Rot::from_angle(angle);
            prop_assert_eq!(
                overlaps_placing(&placed_a, &b, at, rot, angle),
                overlaps_placed(&placed_a, &place_rotated(&b, at, rot, angle))
            );
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 2000,
        max_global_rejects: 1_000_000,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn swapping_a_and_b_flips_the_normal_and_keeps_the_depth(
        a in shape(), pa in pose(), b in shape(), pb in pose()
    ) {
        let ab = contact(&a, &pa, &b, &pb);
        let ba = contact(&b, &pb, &a, &pa);
        assert_unit(&ab);
        assert_unit(&ba);
        prop_assert!((ab.depth - ba.depth).abs() <= EPS, "{ab:?} vs {ba:?}");
        let flipped = ab.normal.dot(-ba.normal) > 1.0 - 1e-12;
        // Where two faces tie, either is a right answer: check it really separates.
        prop_assert!(
            flipped || ab.depth <= 0.0 || separates(&a, &pa, &b, &pb, -ba.normal, ab.depth + 1e-9),
            "{ab:?} vs {ba:?}"
        );
    }

    #[test]
    fn translating_both_shapes_changes_nothing(
        a in shape(), pa in pose(), b in shape(), pb in pose(),
        dx in -1e3f64..1e3, dy in -1e3f64..1e3,
    ) {
        let d = v(dx, dy);
        let before = contact(&a, &pa, &b, &pb);
        let after = contact(
            &a, &Pose::new(pa.position + d, pa.angle),
            &b, &Pose::new(pb.position + d, pb.angle),
        );
        // Positions are rounded to the new magnitude (1e3: ulp 1.1e-13) before the pair is
        // computed relative to a, so the comparison allows for that, no more.
        prop_assert!((before.depth - after.depth).abs() <= 1e-9, "{before:?} vs {after:?}");
        prop_assert!(
            before.normal.dot(after.normal) > 1.0 - 1e-9
                || before.depth <= 0.0
                || separates(&a, &pa, &b, &pb, after.normal, before.depth + 1e-8),
            "{before:?} vs {after:?}"
        );
        prop_assert!((after.point - d - before.point).length() <= 1e-9);
    }

    #[test]
    fn rotating_both_shapes_rotates_the_normal(
        a in shape(), pa in pose(), b in shape(), pb in pose(), turn in -3.2f64..3.2,
    ) {
        prop_assume!(!has_aabb(&a) && !has_aabb(&b));
        let rot = ricochet_geom::Rot::from_angle(turn);
        let ra = Pose::new(rot.apply(pa.position), pa.angle + turn);
        let rb = Pose::new(rot.apply(pb.position), pb.angle + turn);
        let before = contact(&a, &pa, &b, &pb);
        let after = contact(&a, &ra, &b, &rb);
        prop_assert!((before.depth - after.depth).abs() <= 1e-9, "{before:?} vs {after:?}");
        let expected = rot.apply(before.normal);
        prop_assert!(
            expected.dot(after.normal) > 1.0 - 1e-9
                || before.depth <= 0.0
                || separates(&a, &ra, &b, &rb, after.normal, before.depth + 1e-8),
            "{before:?} vs {after:?}"
        );
    }

    #[test]
    fn every_shape_lies_inside_its_bounds(s in shape(), p in pose(), t in 0.0f64..1.0, side in 0usize..4) {
        let b: Bounds = s.bounds(&p);
        // A speck just outside any side of the box never touches the shape.
        let gap = 1e-9;
        let probe = match side {
            0 => v(b.min.x - gap, b.min.y + t * (b.max.y - b.min.y)),
            1 => v(b.max.x + gap, b.min.y + t * (b.max.y - b.min.y)),
            2 => v(b.min.x + t * (b.max.x - b.min.x), b.min.y - gap),
            _ => v(b.min.x + t * (b.max.x - b.min.x), b.max.y + gap),
        };
        let speck = Shape::circle(1e-12).unwrap();
        let c = contact(&s, &p, &speck, &Pose::new(probe, 0.0));
        prop_assert!(c.depth < 0.0, "{probe} is in the shape: {c:?}, bounds {b:?}");
        // And the box is tight: the shape comes within rounding of every side.
        prop_assert!(!side_is_loose(&s, &p, &b, side), "side {side} of {b:?} is loose");
    }

    #[test]
    fn contact_deeper_than_is_the_exact_contact_above_the_threshold(
        a in shape(), pa in pose(), b in shape(), pb in pose(), t in -4.0f64..4.0
    ) {
        // The expected value is the exact algorithm without its early-out: `contact`. The
        // thresholds straddle the depth itself by one ulp, where a rounding slip would show.
        let c = contact(&a, &pa, &b, &pb);
        for threshold in [0.0, t, c.depth, c.depth.next_down(), c.depth - 1e-9, f64::NEG_INFINITY] {
            let want = (c.depth > threshold).then_some(c);
            let got = contact_deeper_than(&a, &pa, &b, &pb, threshold);
            prop_assert_eq!(got.map(bits), want.map(bits), "threshold {}", threshold);
        }
    }

    #[test]
    fn overlaps_agrees_with_contact(a in shape(), pa in pose(), b in shape(), pb in pose()) {
        let c = contact(&a, &pa, &b, &pb);
        let yes = overlaps(&a, &pa, &b, &pb);
        // Two different computations may round differently only when touching.
        prop_assert!(yes == c.overlaps() || c.depth.abs() <= EPS, "overlaps {yes}, {c:?}");
    }

    #[test]
    fn each_pair_function_agrees_with_the_general_core_algorithm(
        a in primitive(), pa in pose(), b in primitive(), pb in pose()
    ) {
        let (a, b) = (place(&a, &pa, pa.position), place(&b, &pb, pa.position));
        let special = contact_placed(&a, &b);
        let general = collide_cores(&a.core(), &b.core());
        prop_assert!((special.depth - general.depth).abs() <= EPS, "{special:?} vs {general:?}");
        prop_assert!(
            special.normal.dot(general.normal) > 1.0 - 1e-9 || special.depth <= 0.0
                || (special.depth - general.depth).abs() <= EPS,
            "{special:?} vs {general:?}"
        );
    }

    #[test]
    fn the_contact_point_lies_between_the_surfaces(a in shape(), pa in pose(), b in shape(), pb in pose()) {
        let c = contact(&a, &pa, &b, &pb);
        prop_assume!(c.depth > 0.0);
        // The point is inside both shapes grown by the depth: a speck there touches both.
        let speck = Shape::circle(c.depth + 1e-9).unwrap();
        let at = Pose::new(c.point, 0.0);
        prop_assert!(overlaps(&a, &pa, &speck, &at), "{c:?}");
        prop_assert!(overlaps(&b, &pb, &speck, &at), "{c:?}");
    }
}

/// Whether the shape stays clear of a whole side of its bounds: never, for a tight box.
/// Scanning 401 spots along the side, the nearest is within 1/800 of the side's length of
/// where the shape touches it. (An earlier bound of 1e-3 of the diagonal failed on a sharp
/// vertex touching a long side: the bound must follow from the spacing.)
fn side_is_loose(s: &Shape, p: &Pose, b: &Bounds, side: usize) -> bool {
    let speck = Shape::circle(1e-12).unwrap();
    (0..=400).all(|i| {
        let t = f64::from(i) / 400.0;
        let probe = match side {
            0 => v(b.min.x, b.min.y + t * (b.max.y - b.min.y)),
            1 => v(b.max.x, b.min.y + t * (b.max.y - b.min.y)),
            2 => v(b.min.x + t * (b.max.x - b.min.x), b.min.y),
            _ => v(b.min.x + t * (b.max.x - b.min.x), b.max.y),
        };
        // The shape touches the side somewhere; every point of the side is within half a
        // spacing of a spot, so some spot is within half a spacing of the shape.
        let side_length = if side < 2 {
            b.max.y - b.min.y
        } else {
            b.max.x - b.min.x
        };
        let half_spacing = side_length / 800.0;
        contact(s, p, &speck, &Pose::new(probe, 0.0)).depth < -(half_spacing + 1e-9)
    })
}

fn check(a: &Shape, pa: Pose, b: &Shape, pb: Pose) -> Contact {
    let c = contact(a, &pa, b, &pb);
    assert_unit(&c);
    c
}

#[test]
fn a_zero_length_capsule_is_a_circle() {
    let capsule = Shape::capsule(v(0.3, 0.3), v(0.3, 0.3), 0.5).unwrap();
    let circle = Shape::Primitive(Primitive::circle(v(0.3, 0.3), 0.5).unwrap());
    let other = Shape::polygon(&[v(0.0, 0.0), v(1.0, 0.0), v(0.0, 1.0)]).unwrap();
    let at = Pose::new(v(0.9, 0.2), 0.4);
    let c1 = check(&capsule, Pose::at(0.0, 0.0), &other, at);
    let c2 = check(&circle, Pose::at(0.0, 0.0), &other, at);
    assert!((c1.depth - c2.depth).abs() < 1e-15, "{c1:?} {c2:?}");
    assert!((c1.normal - c2.normal).length() < 1e-12, "{c1:?} {c2:?}");
}

#[test]
fn a_box_a_micrometre_thick_still_collides_exactly() {
    let sliver = Shape::obb(v(1.0, 1e-6)).unwrap();
    let ball = Shape::circle(0.5).unwrap();
    // Ball centre 0.4 above the sliver's centre line: 0.5 + 1e-6 - 0.4 deep, pushed up.
    let c = check(&sliver, Pose::at(0.0, 0.0), &ball, Pose::at(0.2, 0.4));
    assert!((c.depth - (0.1 + 1e-6)).abs() < 1e-15, "{c:?}");
    assert_eq!(c.normal, Vec2::Y);
}

#[test]
fn concentric_circles_get_a_finite_unit_normal() {
    let a = Shape::circle(1.0).unwrap();
    let b = Shape::circle(0.25).unwrap();
    let c = check(&a, Pose::at(3.0, 3.0), &b, Pose::at(3.0, 3.0));
    assert_eq!(c.depth, 1.25);
}

#[test]
fn coincident_boxes_get_a_finite_unit_normal_and_their_half_size() {
    for (a, b) in [
        (
            Shape::aabb(v(2.0, 1.0)).unwrap(),
            Shape::aabb(v(2.0, 1.0)).unwrap(),
        ),
        (
            Shape::obb(v(2.0, 1.0)).unwrap(),
            Shape::obb(v(2.0, 1.0)).unwrap(),
        ),
        (
            Shape::aabb(v(2.0, 1.0)).unwrap(),
            Shape::obb(v(2.0, 1.0)).unwrap(),
        ),
    ] {
        let c = check(&a, Pose::at(1.0, 1.0), &b, Pose::at(1.0, 1.0));
        // Leaving through the short side: 1 + 1.
        assert_eq!(c.depth, 2.0, "{c:?}");
        assert_eq!(c.normal.x, 0.0, "{c:?}");
    }
}

#[test]
fn coincident_capsules_and_polygons_get_finite_unit_normals() {
    let cap = Shape::capsule(v(-1.0, 0.0), v(1.0, 0.0), 0.5).unwrap();
    let c = check(&cap, Pose::at(0.0, 0.0), &cap, Pose::at(0.0, 0.0));
    assert_eq!(c.depth, 1.0, "{c:?}");
    let tri = Shape::polygon(&[v(0.0, 0.0), v(1.0, 0.0), v(0.0, 1.0)]).unwrap();
    check(&tri, Pose::at(0.0, 0.0), &tri, Pose::at(0.0, 0.0));
    let speck = Shape::circle(1e-9).unwrap();
    check(&speck, Pose::at(0.0, 0.0), &tri, Pose::at(0.0, 0.0));
}
