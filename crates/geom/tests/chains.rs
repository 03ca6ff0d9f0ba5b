//! Terrain chains: the joint rule (a segment's contact takes a normal its neighbours also
//! allow, so a body never catches on an inner joint), corner normals, and validation.
//! Expected values are worked out by hand from the shapes' numbers (in the comments).

use ricochet_geom::{Pose, Shape, Vec2, contact};

fn v(x: f64, y: f64) -> Vec2 {
    Vec2::new(x, y)
}

fn chain(points: &[(f64, f64)]) -> Shape {
    let ps: Vec<Vec2> = points.iter().map(|&(x, y)| v(x, y)).collect();
    Shape::chain(&ps, None, None).unwrap()
}

/// Segment `k` of `shape` (a chain) as a shape of its own, its neighbours still known.
fn part(shape: &Shape, k: usize) -> Shape {
    Shape::Primitive(shape.primitives()[k])
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12
}

fn assert_contact(c: ricochet_geom::Contact, depth: f64, normal: Vec2, what: &str) {
    assert!(
        close(c.depth, depth) && close(c.normal.x, normal.x) && close(c.normal.y, normal.y),
        "{what}: got depth {} normal {:?}, want {depth} {normal:?}",
        c.depth,
        c.normal
    );
}

/// A unit box whose x range is [-0.001, 0.999] and whose bottom is 0.01 below y = 0: it
/// reaches only 0.001 over a joint at x = 0 and sits 0.01 deep.
fn straddling_box() -> (Shape, Pose) {
    (Shape::aabb(v(0.5, 0.5)).unwrap(), Pose::at(0.499, 0.49))
}

#[test]
fn a_lone_segment_catches_a_box_at_its_end_a_chain_segment_does_not() {
    let (b, at) = straddling_box();
    // A segment alone, (-2, 0)-(0, 0): the box overlaps it by 0.001 along x and 0.01 along
    // y, so the least push is 0.001 sideways: the ghost collision (normal from the box to
    // the segment: -x).
    let lone = chain(&[(-2.0, 0.0), (0.0, 0.0)]);
    let c = contact(&b, &at, &lone, &Pose::default());
    assert_contact(c, 0.001, v(-1.0, 0.0), "lone segment");
    // The same segment in a flat chain that goes on to (2, 0): the joint is straight, so
    // no normal tilted towards it is the segment's; the push is straight up by 0.01.
    let flat = chain(&[(-2.0, 0.0), (0.0, 0.0), (2.0, 0.0)]);
    let c = contact(&b, &at, &part(&flat, 0), &Pose::default());
    assert_contact(c, 0.01, v(0.0, -1.0), "first segment of a flat chain");
    let c = contact(&b, &at, &flat, &Pose::default());
    assert_contact(c, 0.01, v(0.0, -1.0), "flat chain");
}

#[test]
fn at_a_convex_crest_the_box_is_pushed_along_the_slope_normal() {
    // Flat to (0, 0), then down at 45° to (2, -2): the joint turns away from the box
    // (convex). The first segment's end-cap push (0.001 along +x) points past the slope's
    // normal (1, 1)/√2: the box is over the slope, so the flat segment leaves it to the
    // slope (no contact from it), and the slope's is along its normal: the box's lowest
    // corner (-0.001, -0.01) is (0.001 + 0.01)/√2 below the slope's line.
    let (b, at) = straddling_box();
    let crest = chain(&[(-2.0, 0.0), (0.0, 0.0), (2.0, -2.0)]);
    let c = contact(&b, &at, &part(&crest, 0), &Pose::default());
    assert_eq!(
        c.depth,
        f64::NEG_INFINITY,
        "flat segment at the crest: {c:?}"
    );
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let c = contact(&b, &at, &crest, &Pose::default());
    assert_contact(c, 0.011 * h, v(-h, -h), "whole crest");
}

#[test]
fn a_circle_on_a_convex_corner_is_pushed_from_the_corner() {
    // Floor to (0, 0), then a cliff down to (0, -2). A circle of radius 1 at (0.6, 0.3) is
    // nearest the corner: distance √(0.36 + 0.09) = √0.45, normal from the circle to the
    // corner (-0.6, -0.3)/√0.45. Both segments allow it (it lies between their normals).
    let cliff = chain(&[(-2.0, 0.0), (0.0, 0.0), (0.0, -2.0)]);
    let ball = Shape::circle(1.0).unwrap();
    let d = 0.45_f64.sqrt();
    let c = contact(&ball, &Pose::at(0.6, 0.3), &cliff, &Pose::default());
    assert_contact(c, 1.0 - d, v(-0.6 / d, -0.3 / d), "circle on the corner");
    // A box resting on the corner, x range [-0.2, 0.8], bottom 0.01 below the floor: up.
    let b = Shape::aabb(v(0.5, 0.5)).unwrap();
    let c = contact(&b, &Pose::at(0.3, 0.49), &cliff, &Pose::default());
    assert_contact(c, 0.01, v(0.0, -1.0), "box on the corner");
}

#[test]
fn a_body_in_a_concave_corner_is_pushed_out_of_the_deeper_face() {
    // Floor to (0, 0), then a wall up to (0, 2). A circle of radius 0.5 at (-0.45, 0.48)
    // is 0.02 into the floor and 0.05 into the wall: out of the wall, normal +x.
    let corner = chain(&[(-2.0, 0.0), (0.0, 0.0), (0.0, 2.0)]);
    let ball = Shape::circle(0.5).unwrap();
    let c = contact(&ball, &Pose::at(-0.45, 0.48), &corner, &Pose::default());
    assert_contact(c, 0.05, v(1.0, 0.0), "circle in the corner");
    // A box pushed into the corner: 0.01 into the wall, 0.05 into the floor: up.
    let b = Shape::aabb(v(0.5, 0.5)).unwrap();
    let c = contact(&b, &Pose::at(-0.49, 0.45), &corner, &Pose::default());
    assert_contact(c, 0.05, v(0.0, -1.0), "box in the corner");
}

#[test]
fn chains_are_two_sided() {
    // The flat chain from below: a circle of radius 0.5 at (0.3, -0.45) is 0.05 into it
    // and pushed down (normal from the circle to the chain: +y).
    let flat = chain(&[(-2.0, 0.0), (0.0, 0.0), (2.0, 0.0)]);
    let ball = Shape::circle(0.5).unwrap();
    let c = contact(&ball, &Pose::at(0.3, -0.45), &flat, &Pose::default());
    assert_contact(c, 0.05, v(0.0, 1.0), "from below");
}

#[test]
fn bad_chains_are_refused_with_the_field() {
    let err = |points: &[(f64, f64)]| {
        let ps: Vec<Vec2> = points.iter().map(|&(x, y)| v(x, y)).collect();
        Shape::chain(&ps, None, None).unwrap_err().to_string()
    };
    assert_eq!(
        err(&[(0.0, 0.0)]),
        "points: a chain needs 2 to 1025 points, got 1; split a longer line into several chains"
    );
    assert!(err(&[(0.0, 0.0), (0.0, 0.0)]).starts_with("points[1]: repeats the previous point"));
    assert!(err(&[(0.0, 0.0), (f64::NAN, 0.0)]).starts_with("points[1][0]: must be a finite"));
    let many = vec![(0.0, 0.0); 1026];
    assert!(err(&many).contains("got 1026"));
}
