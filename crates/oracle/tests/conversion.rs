//! Shape conversion: rapier's (parry's) contact against `ricochet_geom::contact` for every
//! kind, on hand-made pairs whose answers are known, and on random poses of every pairing.

use std::f64::consts::FRAC_PI_2;
use std::f64::consts::FRAC_PI_4;

use ricochet_geom::{Pose, Primitive, Shape, Vec2, contact};
use ricochet_oracle::reference_contact;
use ricochet_scenes::Rng;

fn v(x: f64, y: f64) -> Vec2 {
    Vec2::new(x, y)
}

/// Both engines' answers for the pair, asserted equal to `depth` along `normal` (to 1e-12).
fn expect(a: &Shape, pa: Pose, b: &Shape, pb: Pose, depth: f64, normal: Vec2) {
    let ours = contact(a, &pa, b, &pb);
    let theirs = reference_contact(a, &pa, b, &pb, 10.0)
        .unwrap()
        .expect("within the prediction distance");
    for (who, d, n) in [
        ("ricochet", ours.depth, ours.normal),
        ("rapier", theirs.depth, theirs.normal),
    ] {
        assert!(
            (d - depth).abs() < 1e-12 && (n - normal).length() < 1e-12,
            "{who}: depth {d} normal {n}, expected {depth} along {normal}"
        );
    }
}

fn circle(r: f64) -> Shape {
    Shape::circle(r).unwrap()
}

#[test]
fn circle_is_a_ball_with_its_offset_turned_by_the_body() {
    let cam = Shape::Primitive(Primitive::circle(v(1.0, 0.0), 0.5).unwrap());
    // Body turned a quarter: the disc sits at (0, 1), 0.2 deep in a disc of 0.5 at (0, 2.2).
    expect(
        &cam,
        Pose::new(Vec2::ZERO, FRAC_PI_2),
        &circle(0.5),
        Pose::at(0.0, 1.8),
        0.2,
        Vec2::Y,
    );
}

#[test]
fn aabb_ignores_the_body_angle_but_turns_its_offset() {
    let plank = Shape::Primitive(Primitive::aabb(Vec2::ZERO, v(2.0, 0.5)).unwrap());
    // A quarter turn leaves the plank lying flat: the disc above is 0.2 clear, not deep in.
    expect(
        &plank,
        Pose::new(Vec2::ZERO, FRAC_PI_2),
        &circle(0.5),
        Pose::at(0.0, 1.2),
        -0.2,
        Vec2::Y,
    );
    // An offset box: its centre (1, 0) turns to (0, 1); the box stays axis-aligned.
    let offset = Shape::Primitive(Primitive::aabb(v(1.0, 0.0), v(0.5, 0.25)).unwrap());
    expect(
        &offset,
        Pose::new(Vec2::ZERO, FRAC_PI_2),
        &circle(0.5),
        Pose::at(0.0, 1.5),
        0.25,
        Vec2::Y,
    );
}

#[test]
fn obb_turns_by_the_body_angle_plus_its_own() {
    let stick = Shape::Primitive(Primitive::obb(Vec2::ZERO, v(1.0, 0.1), FRAC_PI_4).unwrap());
    // 45° + 45°: the stick stands upright, reaching y = 1.
    expect(
        &stick,
        Pose::new(Vec2::ZERO, FRAC_PI_4),
        &circle(0.5),
        Pose::at(0.0, 1.3),
        0.2,
        Vec2::Y,
    );
}

#[test]
fn capsule_turns_with_the_body() {
    let rod = Shape::capsule(v(-1.0, 0.0), v(1.0, 0.0), 0.25).unwrap();
    // Upright after a quarter turn: the tip's cap reaches y = 1.25.
    expect(
        &rod,
        Pose::new(v(3.0, -2.0), FRAC_PI_2),
        &circle(0.5),
        Pose::at(3.0, -0.5),
        0.25,
        Vec2::Y,
    );
    // Two crossed capsules: cores intersect, depth is the core penetration plus both radii.
    let other = Shape::capsule(v(0.0, -1.0), v(0.0, 1.0), 0.25).unwrap();
    let ours = contact(&rod, &Pose::at(0.0, 0.0), &other, &Pose::at(0.5, 0.0));
    let theirs = reference_contact(&rod, &Pose::at(0.0, 0.0), &other, &Pose::at(0.5, 0.0), 0.0)
        .unwrap()
        .unwrap();
    assert!(
        (ours.depth - theirs.depth).abs() < 1e-12,
        "{ours:?} {theirs:?}"
    );
    assert!(
        (ours.normal - theirs.normal).length() < 1e-12,
        "{ours:?} {theirs:?}"
    );
}

#[test]
fn polygon_turns_with_the_body() {
    let tri = Shape::polygon(&[v(1.0, 0.0), v(-0.5, 0.5), v(-0.5, -0.5)]).unwrap();
    // Pointing up after a quarter turn: the apex at (0, 1) is 0.25 deep in the box above.
    let lid = Shape::aabb(v(1.0, 0.25)).unwrap();
    expect(
        &tri,
        Pose::new(Vec2::ZERO, FRAC_PI_2),
        &lid,
        Pose::at(0.0, 1.0),
        0.25,
        Vec2::Y,
    );
}

#[test]
fn compound_is_its_deepest_part_pair() {
    // An L: a tall box at (-0.8, 0.3) and a wide one at (0, -0.8). Turned a quarter, the
    // boxes stay axis-aligned and their centres move to (-0.3, -0.8) and (0.8, 0).
    let l = Shape::compound(vec![
        Primitive::aabb(v(-0.8, 0.3), v(0.4, 1.5)).unwrap(),
        Primitive::aabb(v(0.0, -0.8), v(1.2, 0.4)).unwrap(),
    ])
    .unwrap();
    // The wide box spans x 0.8 - 1.2 .. 0.8 + 1.2 = 2.0: a disc at x = 2.3 is 0.2 deep.
    expect(
        &l,
        Pose::new(Vec2::ZERO, FRAC_PI_2),
        &circle(0.5),
        Pose::at(2.3, 0.0),
        0.2,
        Vec2::X,
    );
    // Against another compound holding an OBB and a capsule.
    let hammer = Shape::compound(vec![
        Primitive::capsule(v(-1.6, 0.0), v(0.8, 0.0), 0.2).unwrap(),
        Primitive::obb(v(1.1, 0.0), v(0.35, 0.8), 0.3).unwrap(),
    ])
    .unwrap();
    let (pa, pb) = (Pose::new(v(1.0, 2.0), 0.4), Pose::new(v(1.9, 1.2), -2.1));
    let ours = contact(&l, &pa, &hammer, &pb);
    let theirs = reference_contact(&l, &pa, &hammer, &pb, 0.0)
        .unwrap()
        .unwrap();
    assert!(ours.depth > 0.0);
    assert!(
        (ours.depth - theirs.depth).abs() < 1e-12,
        "{ours:?} {theirs:?}"
    );
    assert!(
        (ours.normal - theirs.normal).length() < 1e-12,
        "{ours:?} {theirs:?}"
    );
}

/// One shape of each kind with every option used (offsets, own angle, compound parts).
fn one_of_each(scale: f64) -> Vec<Shape> {
    let s = |x: f64, y: f64| v(x * scale, y * scale);
    vec![
        Shape::Primitive(Primitive::circle(s(0.3, 0.1), 0.8 * scale).unwrap()),
        Shape::Primitive(Primitive::aabb(s(0.2, -0.3), s(1.0, 0.5)).unwrap()),
        Shape::Primitive(Primitive::obb(s(0.1, 0.2), s(1.2, 0.4), 0.5).unwrap()),
        Shape::capsule(s(-1.0, 0.0), s(1.0, 0.3), 0.4 * scale).unwrap(),
        Shape::polygon(&[
            s(1.2, 0.0),
            s(0.6, 1.0),
            s(-0.6, 1.0),
            s(-1.2, 0.0),
            s(-0.6, -1.0),
            s(0.6, -1.0),
        ])
        .unwrap(),
        Shape::compound(vec![
            Primitive::capsule(s(-1.6, 0.0), s(0.8, 0.0), 0.2 * scale).unwrap(),
            Primitive::obb(s(1.1, 0.0), s(0.35, 0.8), 0.0).unwrap(),
            Primitive::aabb(s(-0.5, 0.5), s(0.3, 0.3)).unwrap(),
        ])
        .unwrap(),
    ]
}

/// Every pairing at random poses: near the origin, 1e6 away, and at size 1e-3. Depth must
/// agree to 1e-12 of the size, the normal to 1e-9 rad.
#[test]
fn every_pairing_agrees_on_random_poses() {
    let mut rng = Rng::new(0x9e37_79b9_7f4a_7c15);
    for (scale, far) in [(1.0, 0.0), (1.0, 1e6), (1e-3, 0.0)] {
        let shapes = one_of_each(scale);
        for a in &shapes {
            for b in &shapes {
                let mut overlapping = 0;
                for _ in 0..300 {
                    let pa = Pose::new(
                        v(far + rng.range(-40.0, 40.0), rng.range(-40.0, 40.0)),
                        rng.range(-7.0, 7.0),
                    );
                    let off = v(rng.range(-2.5, 2.5), rng.range(-2.5, 2.5)) * scale;
                    let pb = Pose::new(pa.position + off, rng.range(-7.0, 7.0));
                    let ours = contact(a, &pa, b, &pb);
                    if ours.depth <= 0.0 {
                        continue;
                    }
                    overlapping += 1;
                    let theirs = reference_contact(a, &pa, b, &pb, 0.0)
                        .unwrap()
                        .expect("overlapping shapes have a contact");
                    let angle = libm::atan2(
                        ours.normal.perp_dot(theirs.normal).abs(),
                        ours.normal.dot(theirs.normal),
                    );
                    assert!(
                        (ours.depth - theirs.depth).abs() <= 1e-12 * scale && angle <= 1e-9,
                        "{a:?} at {pa:?} / {b:?} at {pb:?}: {ours:?} vs {theirs:?}"
                    );
                }
                assert!(overlapping > 20, "too few overlapping samples");
            }
        }
    }
}
