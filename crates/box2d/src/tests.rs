//! The Box2D scene and the contact comparison: small scenes whose contacts are known by exact
//! math, and a few frames of each bench scene.

use std::collections::BTreeMap;

use ricochet_geom::{Pose, Primitive, Rot, Shape, Vec2};
use ricochet_scenes::bench::Scene;
use ricochet_sim::{
    BodyDef, BodyKind, Entity, FrameOutput, Response, Scenario, Simulation, WorldDef,
};

use super::*;

/// How closely Box2D's `f32` geometry must give an exact depth on these unit-sized shapes.
const F32_DEPTH: f64 = 1e-6;

/// A body of `shape` on `layer` at `(x, y)` turned by `angle`, at rest.
fn body(layer: u8, kind: BodyKind, shape: Shape, x: f64, y: f64, angle: f64) -> BodyDef {
    BodyDef {
        layer,
        kind,
        shape,
        position: Vec2::new(x, y),
        angle,
        ..BodyDef::default()
    }
}

/// A scene without gravity in which the listed layer pairs have the listed responses.
fn scene(names: &[&str], pairs: &[(u8, u8, Response)], bodies: Vec<BodyDef>) -> Scenario {
    let world = WorldDef {
        layers: ricochet_scenes::layers(names, pairs),
        gravity: Vec2::ZERO,
        ..WorldDef::default()
    };
    ricochet_scenes::scenario("t", world, bodies, 600)
}

/// Frame 0 of `scenario` in Ricochet, Box2D's world built at its poses and stepped once:
/// the simulation, its frame, and the pairs Box2D reports touching.
fn frame0(scenario: &Scenario) -> (Simulation, FrameOutput, BTreeMap<(Entity, Entity), f64>) {
    let mut sim = Simulation::new(scenario);
    let out = sim.step();
    let mut b = Box2dScene::new(&sim).unwrap();
    b.step().unwrap();
    let touching = b.touching().unwrap();
    (sim, out, touching)
}

/// The penetrating pairs of Box2D's answer, with their depths.
fn penetrating(touching: &BTreeMap<(Entity, Entity), f64>) -> Vec<((Entity, Entity), f64)> {
    touching
        .iter()
        .filter(|&(_, &s)| s < -BOX2D_CONTACT_TOLERANCE)
        .map(|(&k, &s)| (k, -s))
        .collect()
}

fn circle(r: f64) -> Shape {
    Shape::circle(r).unwrap()
}

/// Every kind of primitive at an awkward pose lands where Ricochet places it: the position
/// exactly (Box2D's large-world mode keeps it in `f64`), the angle within `f32` rounding, and
/// an AABB unrotated whatever the body's angle.
#[test]
fn box2d_bodies_sit_at_ricochets_placement() {
    let pose = Pose::new(Vec2::new(3.25, -7.5), 0.7);
    let offset_circle = Primitive::circle(Vec2::new(0.3, -0.2), 0.5).unwrap();
    let offset_aabb = Primitive::aabb(Vec2::new(0.1, 0.4), Vec2::new(0.5, 0.25)).unwrap();
    let offset_obb = Primitive::obb(Vec2::new(0.2, 0.1), Vec2::new(0.5, 0.25), 0.3).unwrap();
    let r = Rot::from_angle(0.7);
    // (shape, its centre offset turned by the body, the Box2D body's angle)
    let cases = [
        (Shape::Primitive(offset_circle), Vec2::new(0.3, -0.2), 0.0),
        (Shape::Primitive(offset_aabb), Vec2::new(0.1, 0.4), 0.0),
        (Shape::Primitive(offset_obb), Vec2::new(0.2, 0.1), 1.0),
        (
            Shape::capsule(Vec2::new(-0.5, 0.0), Vec2::new(0.5, 0.1), 0.2).unwrap(),
            Vec2::ZERO,
            0.7,
        ),
        (
            Shape::polygon(&[Vec2::ZERO, Vec2::X, Vec2::new(0.4, 0.9)]).unwrap(),
            Vec2::ZERO,
            0.7,
        ),
    ];
    let bodies = cases
        .iter()
        .map(|(s, _, _)| body(0, BodyKind::Dynamic, s.clone(), 3.25, -7.5, 0.7))
        .collect();
    let sim = Simulation::new(&scene(&["a"], &[], bodies));
    let mut b = Box2dScene::new(&sim).unwrap();
    for (i, (_, center, angle)) in cases.iter().enumerate() {
        let t = b.body_transform(i);
        let expected = pose.position + r.apply(*center);
        let p = t.position();
        assert_eq!((p.x, p.y), (expected.x, expected.y), "case {i}");
        let q = t.rotation();
        let (s, c) = libm::sincos(*angle);
        assert!(
            (f64::from(q.cosine()) - c).abs() < 2e-7 && (f64::from(q.sine()) - s).abs() < 2e-7,
            "case {i}: {q:?}"
        );
    }
}

/// Two unit circles 0.8 apart overlap by exactly 0.2; a third far away touches nothing.
/// Box2D reports exactly that pair, 0.2 deep, and the comparison counts it as in both.
#[test]
fn two_overlapping_circles_are_the_one_pair() {
    let s = scene(
        &["a"],
        &[(0, 0, Response::Report)],
        vec![
            body(0, BodyKind::Dynamic, circle(0.5), 0.0, 0.0, 0.0),
            body(0, BodyKind::Dynamic, circle(0.5), 0.8, 0.0, 0.0),
            body(0, BodyKind::Dynamic, circle(0.5), 10.0, 0.0, 0.0),
        ],
    );
    let (sim, out, touching) = frame0(&s);
    let e = |i: usize| sim.world().entity[i];
    let pairs = penetrating(&touching);
    assert_eq!(pairs.len(), 1, "{touching:?}");
    assert_eq!(pairs[0].0, (e(0), e(1)));
    assert!((pairs[0].1 - 0.2).abs() < F32_DEPTH, "{pairs:?}");
    let a = compare_box2d(&sim, &out, &touching, BOX2D_CONTACT_TOLERANCE);
    assert!(a.all_agree(), "{a:?}");
    assert_eq!((a.compared, a.both), (1, 1), "{a:?}");
}

/// Shapes whose depth depends on the body's angle, each against a circle of radius 0.5
/// (exact depths: the penetration of a circle is its radius minus its centre's distance to
/// the other shape):
/// - an OBB of half extents (0.5, 0.25) turned a quarter turn, circle centre 0.6 to its right:
///   its half width along x is 0.25, so the depth is 0.25 + 0.5 - 0.6 = 0.15 (0.4 unturned);
/// - an AABB of the same size on a body turned by 0.7 (an AABB ignores it), circle centre 0.6
///   above: 0.25 + 0.5 - 0.6 = 0.15;
/// - a capsule of core (-0.5, 0)–(0.5, 0) and radius 0.2 turned a quarter turn (its core now
///   vertical), circle of radius 0.3 centred 0.4 to its right: 0.2 + 0.3 - 0.4 = 0.1 (0.5
///   unturned);
/// - a triangle (0, 0), (1, 0), (0, 1) turned a quarter turn counter-clockwise (now (0, 0),
///   (0, 1), (-1, 0)), circle centred at (0.3, 0.5): 0.3 from the edge on x = 0, so
///   0.5 - 0.3 = 0.2 (turned clockwise, the nearest point would be (0.3, 0), 0.5 away: a
///   touch; unturned, the centre would be inside).
#[test]
fn turned_shapes_overlap_circles_by_the_exact_depth() {
    let quarter = std::f64::consts::FRAC_PI_2;
    let cases: [(Shape, f64, Vec2, f64, f64); 4] = [
        (
            Shape::obb(Vec2::new(0.5, 0.25)).unwrap(),
            quarter,
            Vec2::new(0.6, 0.0),
            0.5,
            0.15,
        ),
        (
            Shape::aabb(Vec2::new(0.5, 0.25)).unwrap(),
            0.7,
            Vec2::new(0.0, 0.6),
            0.5,
            0.15,
        ),
        (
            Shape::capsule(Vec2::new(-0.5, 0.0), Vec2::new(0.5, 0.0), 0.2).unwrap(),
            quarter,
            Vec2::new(0.4, 0.0),
            0.3,
            0.1,
        ),
        (
            Shape::polygon(&[Vec2::ZERO, Vec2::X, Vec2::Y]).unwrap(),
            quarter,
            Vec2::new(0.3, 0.5),
            0.5,
            0.2,
        ),
    ];
    let mut bodies = Vec::new();
    for (k, (shape, angle, at, r, _)) in cases.iter().enumerate() {
        let x0 = 10.0 * k as f64;
        bodies.push(body(0, BodyKind::Dynamic, shape.clone(), x0, 0.0, *angle));
        bodies.push(body(1, BodyKind::Static, circle(*r), x0 + at.x, at.y, 0.0));
    }
    let s = scene(&["shape", "ball"], &[(0, 1, Response::Report)], bodies);
    let (sim, out, touching) = frame0(&s);
    let e = |i: usize| sim.world().entity[i];
    let pairs = penetrating(&touching);
    assert_eq!(pairs.len(), cases.len(), "{touching:?}");
    for (k, (_, _, _, _, depth)) in cases.iter().enumerate() {
        assert_eq!(pairs[k].0, (e(2 * k), e(2 * k + 1)), "case {k}");
        assert!(
            (pairs[k].1 - depth).abs() < F32_DEPTH,
            "case {k}: {} instead of {depth}",
            pairs[k].1
        );
    }
    let a = compare_box2d(&sim, &out, &touching, BOX2D_CONTACT_TOLERANCE);
    assert!(a.all_agree(), "{a:?}");
    assert_eq!(a.both, 4, "{a:?}");
}

/// A 0.8 box standing flush on a unit tile (`separate`, under gravity: the per-axis pass
/// keeps it there) touches it at separation exactly 0, a touch that agrees; a second box sunk
/// 0.1 into its tile (`report`: nothing pushes it out) is 0.1 deep in both engines. Ricochet
/// logs the first only at the pass's poses, the second at the end of the frame.
#[test]
fn a_box_resting_on_a_tile_touches_and_a_sunk_box_penetrates() {
    let tile = || Shape::aabb(Vec2::splat(0.5)).unwrap();
    let crate_ = || Shape::aabb(Vec2::splat(0.4)).unwrap();
    let world = WorldDef {
        layers: ricochet_scenes::layers(
            &["tile", "box", "sunk"],
            &[(0, 1, Response::Separate), (0, 2, Response::Report)],
        ),
        gravity: Vec2::new(0.0, -20.0),
        ..WorldDef::default()
    };
    let bodies = vec![
        body(0, BodyKind::Static, tile(), 0.5, 0.0, 0.0),
        body(1, BodyKind::Dynamic, crate_(), 0.5, 0.9, 0.0),
        body(0, BodyKind::Static, tile(), 10.5, 0.0, 0.0),
        BodyDef {
            gravity_scale: 0.0,
            ..body(2, BodyKind::Dynamic, crate_(), 10.5, 0.8, 0.0)
        },
    ];
    let s = ricochet_scenes::scenario("t", world, bodies, 600);
    let mut sim = Simulation::new(&s);
    sim.step();
    let mut b = Box2dScene::new(&sim).unwrap();
    b.step().unwrap();
    let e = |sim: &Simulation, i: usize| sim.world().entity[i];
    for _ in 0..5 {
        let out = sim.step();
        assert_eq!(
            sim.world().position[1],
            Vec2::new(0.5, 0.9),
            "the box rests"
        );
        b.sync(&sim).unwrap();
        b.step().unwrap();
        let touching = b.touching().unwrap();
        let flush = touching[&(e(&sim, 0), e(&sim, 1))];
        assert!(flush.abs() < F32_DEPTH, "{touching:?}");
        let sunk = touching[&(e(&sim, 2), e(&sim, 3))];
        assert!((sunk + 0.1).abs() < F32_DEPTH, "{touching:?}");
        let a = compare_box2d(&sim, &out, &touching, BOX2D_CONTACT_TOLERANCE);
        assert!(a.all_agree(), "{a:?}");
        assert_eq!(a.both, 1, "{a:?}");
    }
}

/// Layers that ignore each other are never paired by Box2D (its filter bits), and neither are
/// two bodies that are not dynamic (Box2D's rule and Ricochet's): every one of these pairs
/// overlaps by 0.2, and only the `report` pair with a dynamic body is reported.
#[test]
fn ignored_layers_and_pairs_without_a_dynamic_body_are_never_paired() {
    let pair = |k: usize, a: (u8, BodyKind), b: (u8, BodyKind)| {
        let x = 10.0 * k as f64;
        [
            body(a.0, a.1, circle(0.5), x, 0.0, 0.0),
            body(b.0, b.1, circle(0.5), x + 0.8, 0.0, 0.0),
        ]
    };
    use BodyKind::{Dynamic, Kinematic, Static};
    let bodies = [
        pair(0, (0, Dynamic), (1, Static)),
        pair(1, (0, Dynamic), (2, Dynamic)),
        pair(2, (0, Kinematic), (1, Static)),
        pair(3, (0, Kinematic), (0, Kinematic)),
    ]
    .concat();
    let s = scene(
        &["a", "b", "c"],
        &[
            (0, 0, Response::Report),
            (0, 1, Response::Report),
            (0, 2, Response::Ignore),
        ],
        bodies,
    );
    let (sim, out, touching) = frame0(&s);
    let e = |i: usize| sim.world().entity[i];
    assert_eq!(touching.keys().copied().collect::<Vec<_>>(), [(e(0), e(1))]);
    let a = compare_box2d(&sim, &out, &touching, BOX2D_CONTACT_TOLERANCE);
    assert!(a.all_agree(), "{a:?}");
    assert_eq!(a.both, 1, "{a:?}");
}

/// Locked motion: Box2D's solver pushes on two overlapping dynamic circles every step, and
/// neither moves a bit.
#[test]
fn box2d_never_moves_a_body() {
    let s = scene(
        &["a"],
        &[(0, 0, Response::Report)],
        vec![
            body(0, BodyKind::Dynamic, circle(0.5), 0.0, 0.0, 0.0),
            body(0, BodyKind::Dynamic, circle(0.5), 0.8, 0.0, 0.0),
        ],
    );
    let sim = Simulation::new(&s);
    let mut b = Box2dScene::new(&sim).unwrap();
    for _ in 0..30 {
        b.step().unwrap();
    }
    let (p0, p1) = (
        b.body_transform(0).position(),
        b.body_transform(1).position(),
    );
    assert_eq!((p0.x, p0.y, p1.x, p1.y), (0.0, 0.0, 0.8, 0.0));
}

/// The comparison catches a Ricochet that misses a contact or invents one.
#[test]
fn a_missing_or_invented_contact_is_a_disagreement() {
    let s = scene(
        &["a"],
        &[(0, 0, Response::Report)],
        vec![
            body(0, BodyKind::Dynamic, circle(0.5), 0.0, 0.0, 0.0),
            body(0, BodyKind::Dynamic, circle(0.5), 0.8, 0.0, 0.0),
            body(0, BodyKind::Dynamic, circle(0.5), 10.0, 0.0, 0.0),
        ],
    );
    let (sim, out, touching) = frame0(&s);
    assert_eq!(out.contacts.len(), 1);

    let mut missing = out.clone();
    missing.contacts.clear();
    let a = compare_box2d(&sim, &missing, &touching, BOX2D_CONTACT_TOLERANCE);
    assert_eq!((a.compared, a.box2d_only), (1, 1), "{a:?}");
    assert!(a.details[0].contains("Ricochet logged no contact"), "{a:?}");

    let mut invented = out.clone();
    let mut fake = invented.contacts[0].clone();
    fake.b = sim.world().entity[2];
    fake.pose_b = sim.world().pose(2);
    invented.contacts.push(fake);
    let a = compare_box2d(&sim, &invented, &touching, BOX2D_CONTACT_TOLERANCE);
    assert_eq!((a.compared, a.ricochet_only, a.agreed), (2, 1, 1), "{a:?}");
    assert!(a.details[0].contains("no touching contact"), "{a:?}");
}

/// What Box2D cannot hold is refused, not approximated: a compound shape, a polygon whose
/// corner Box2D's hull would weld (two vertices 0.0007 apart, under its 0.005 linear slop),
/// and more than 64 layers.
#[test]
fn shapes_and_layers_box2d_cannot_hold_are_errors() {
    let compound = Shape::compound(vec![
        Primitive::circle(Vec2::ZERO, 0.5).unwrap(),
        Primitive::circle(Vec2::X, 0.5).unwrap(),
    ])
    .unwrap();
    let welded = Shape::polygon(&[
        Vec2::ZERO,
        Vec2::X,
        Vec2::new(1.0, 1.0),
        Vec2::new(0.0005, 1.0),
        Vec2::new(0.0, 0.9995),
    ])
    .unwrap();
    for shape in [compound, welded] {
        let s = scene(
            &["a"],
            &[],
            vec![body(0, BodyKind::Dynamic, shape, 0.0, 0.0, 0.0)],
        );
        let e = Box2dScene::new(&Simulation::new(&s)).err();
        assert!(matches!(e, Some(Box2dError::Conversion(_))), "{e:?}");
    }
    let names: Vec<String> = (0..=BOX2D_LAYERS).map(|k| format!("l{k}")).collect();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    let s = scene(
        &names,
        &[],
        vec![body(0, BodyKind::Dynamic, circle(0.5), 0.0, 0.0, 0.0)],
    );
    let e = Box2dScene::new(&Simulation::new(&s)).err();
    assert!(matches!(e, Some(Box2dError::Conversion(_))), "{e:?}");
}

/// Each bench scene, small, for a few frames: Box2D holds every body, and every compared
/// pair agrees. Each scene has pairs to compare, and Box2D finds some penetrating.
#[test]
fn bench_scenes_agree_with_box2d() {
    for name in ["asteroids-200", "platformer-500-20", "rain-300"] {
        let frames = 10;
        let mut sim = Simulation::from_scenario(Scene::parse(name).unwrap().build(frames));
        let out = sim.step();
        let mut b = Box2dScene::new(&sim).unwrap();
        assert_eq!(b.len(), sim.world().len(), "{name}");
        b.step().unwrap();
        let mut total = compare_box2d(&sim, &out, &b.touching().unwrap(), BOX2D_CONTACT_TOLERANCE);
        for _ in 0..frames {
            let out = sim.step();
            b.sync(&sim).unwrap();
            b.step().unwrap();
            let touching = b.touching().unwrap();
            total.add(&compare_box2d(
                &sim,
                &out,
                &touching,
                BOX2D_CONTACT_TOLERANCE,
            ));
        }
        assert!(total.all_agree(), "{name}: {total:?}");
        assert!(
            total.compared > 0 && total.both + total.swept > 0,
            "{name}: {total:?}"
        );
    }
}
