//! Compounds (issue 20): at most `MAX_COMPOUND_PARTS` parts, and the part pairs culled by
//! their bounds give exactly the answer of testing every pair.

use proptest::prelude::*;
use ricochet_geom::{
    Contact, MAX_COMPOUND_PARTS, Pose, Primitive, Shape, ShapeDef, Sweep, Vec2, contact, overlaps,
    time_of_impact,
};

fn v(x: f64, y: f64) -> Vec2 {
    Vec2::new(x, y)
}

/// Every part of `a` against every part of `b`, each pair through the one-primitive path,
/// the deepest kept (the first among equals): what `contact` did before culling.
fn every_pair(a: &Shape, pa: &Pose, b: &Shape, pb: &Pose) -> Contact {
    let mut best: Option<Contact> = None;
    for x in a.primitives() {
        for y in b.primitives() {
            let c = contact(&Shape::Primitive(*x), pa, &Shape::Primitive(*y), pb);
            if best.is_none_or(|best| c.depth > best.depth) {
                best = Some(c);
            }
        }
    }
    best.unwrap()
}

fn any_pair(a: &Shape, pa: &Pose, b: &Shape, pb: &Pose) -> bool {
    a.primitives().iter().any(|x| {
        b.primitives()
            .iter()
            .any(|y| overlaps(&Shape::Primitive(*x), pa, &Shape::Primitive(*y), pb))
    })
}

fn part() -> impl Strategy<Value = Primitive> {
    let size = 0.05f64..1.5;
    let at = (-6.0f64..6.0, -6.0f64..6.0);
    prop_oneof![
        (size.clone(), at.clone()).prop_map(|(r, (x, y))| Primitive::circle(v(x, y), r).unwrap()),
        (size.clone(), size.clone(), at.clone()).prop_map(|(w, h, (x, y))| Primitive::aabb(
            v(x, y),
            v(w, h)
        )
        .unwrap()),
        (size.clone(), size.clone(), at.clone(), -3.2f64..3.2)
            .prop_map(|(w, h, (x, y), a)| Primitive::obb(v(x, y), v(w, h), a).unwrap()),
        (at.clone(), size).prop_map(|((x, y), r)| {
            Primitive::capsule(v(x, y), v(x + 1.0, y - 0.5), r).unwrap()
        }),
        at.prop_map(|(x, y)| {
            Primitive::polygon(&[v(x, y), v(x + 1.0, y), v(x + 0.3, y + 0.8)]).unwrap()
        }),
    ]
}

/// A compound large enough to be culled (more than 64 part pairs against another).
fn compound() -> impl Strategy<Value = Shape> {
    proptest::collection::vec(part(), 9..60).prop_map(|parts| Shape::compound(parts).unwrap())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn culled_part_pairs_give_every_pairs_answer_bit_for_bit(
        a in compound(),
        b in compound(),
        (ax, ay, aa) in (-3.0f64..3.0, -3.0f64..3.0, -3.2f64..3.2),
        // Overlapping, near and far apart (up to 1e4, where a lone part pair is nearest).
        (bx, by, ba) in (-1e4f64..1e4, -30.0f64..30.0, -3.2f64..3.2),
        near in any::<bool>(),
    ) {
        let pa = Pose::new(v(ax, ay), aa);
        let pb = Pose::new(if near { v(bx * 1e-3, by) } else { v(bx, by) }, ba);
        let (got, want) = (contact(&a, &pa, &b, &pb), every_pair(&a, &pa, &b, &pb));
        prop_assert_eq!(got.depth.to_bits(), want.depth.to_bits());
        prop_assert_eq!(got.normal, want.normal);
        prop_assert_eq!(got.point, want.point);
        prop_assert_eq!(overlaps(&a, &pa, &b, &pb), any_pair(&a, &pa, &b, &pb));
    }
}

#[test]
fn many_touching_parts_tie_as_every_pair_does() {
    // Two rows of equal boxes, every part pair at the same depth: the first pair in part
    // order is the answer, as when every pair was tested in order.
    let row = |dy: f64| {
        Shape::compound(
            (0..40)
                .map(|i| Primitive::aabb(v(f64::from(i) * 2.0, dy), v(1.0, 1.0)).unwrap())
                .collect(),
        )
        .unwrap()
    };
    let (a, b) = (row(0.0), row(0.0));
    let (pa, pb) = (Pose::at(0.0, 0.0), Pose::at(0.0, 1.5));
    let (got, want) = (contact(&a, &pa, &b, &pb), every_pair(&a, &pa, &b, &pb));
    assert_eq!(
        (got.depth, got.normal, got.point),
        (want.depth, want.normal, want.point)
    );
    assert_eq!(got.depth, 0.5);
}

#[test]
fn a_compound_of_more_than_the_limit_is_refused_naming_the_limit() {
    let circles = |n: usize| vec![Primitive::circle(Vec2::ZERO, 1.0).unwrap(); n];
    assert!(Shape::compound(circles(MAX_COMPOUND_PARTS)).is_ok());
    let e = Shape::compound(circles(MAX_COMPOUND_PARTS + 1)).unwrap_err();
    assert_eq!(e.field, "parts");
    assert!(
        e.problem
            .contains(&format!("at most {MAX_COMPOUND_PARTS} parts")),
        "{e}"
    );
    // From a description, before any part is checked (the parts here are all invalid).
    let def = ShapeDef::Compound {
        parts: vec![
            ShapeDef::Circle {
                radius: -1.0,
                center: [0.0, 0.0],
            };
            200_000
        ],
    };
    let e = def.to_shape().unwrap_err();
    assert_eq!(e.field, "parts");
    assert!(e.problem.contains("this one has 200000"), "{e}");
}

#[test]
fn a_circle_swept_into_a_large_compound_touches_its_nearest_part_first() {
    // 10 x 10 unit circles 3 apart; a unit circle from x = 50 to x = 0 along y = 0 first
    // touches the part at (27, 0) with its centre at 29: t = 21 / 50.
    let grid = Shape::compound(
        (0..100)
            .map(|k| {
                let (i, j) = (f64::from(k % 10), f64::from(k / 10));
                Primitive::circle(v(3.0 * i, 3.0 * j), 1.0).unwrap()
            })
            .collect(),
    )
    .unwrap();
    let ball = Shape::circle(1.0).unwrap();
    let still = Sweep {
        start: Vec2::ZERO,
        end: Vec2::ZERO,
        angle: 0.0,
    };
    let shot = Sweep {
        start: v(50.0, 0.0),
        end: Vec2::ZERO,
        angle: 0.0,
    };
    let hit = time_of_impact(&grid, &still, &ball, &shot).expect("it hits");
    assert!((hit.t - 0.42).abs() < 1e-9, "{}", hit.t);
    assert!(hit.contact.depth.abs() < 1e-8, "{:?}", hit.contact);
    assert_eq!(hit.contact.normal, Vec2::X);
    // Shot along y = 1.5, between two rows of parts: it passes them all.
    let between = Sweep {
        start: v(50.0, 1.5),
        end: v(-10.0, 1.5),
        angle: 0.0,
    };
    let miss = Sweep {
        start: v(50.0, 1.5),
        end: v(40.0, 1.5),
        angle: 0.0,
    };
    let small = Shape::circle(0.4).unwrap();
    assert!(time_of_impact(&grid, &still, &small, &between).is_none());
    assert!(time_of_impact(&grid, &still, &small, &miss).is_none());
}
