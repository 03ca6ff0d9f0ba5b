//! The rapier scene and the contact comparison on small scenes.

use ricochet_geom::{Pose, Primitive, Shape, Vec2};
use ricochet_sim::{BodyDef, BodyKind, Entity, Response, Scenario, Simulation, WorldDef};

use super::scene::collider_pose;
use super::{CONTACT_TOLERANCE, RapierScene, compare_contacts};
use crate::convert::place;

fn shapes() -> Vec<Shape> {
    vec![
        Shape::chain(
            &[
                Vec2::new(-1.0, 0.0),
                Vec2::new(0.5, 0.2),
                Vec2::new(1.0, -0.3),
            ],
            None,
            None,
        )
        .unwrap(),
        Shape::circle(0.5).unwrap(),
        Shape::Primitive(Primitive::circle(Vec2::new(0.3, -0.2), 0.5).unwrap()),
        Shape::aabb(Vec2::new(0.5, 0.25)).unwrap(),
        Shape::Primitive(Primitive::aabb(Vec2::new(0.1, 0.4), Vec2::new(0.5, 0.25)).unwrap()),
        Shape::obb(Vec2::new(0.5, 0.25)).unwrap(),
        Shape::Primitive(Primitive::obb(Vec2::new(0.2, 0.1), Vec2::new(0.5, 0.25), 0.3).unwrap()),
        Shape::capsule(Vec2::new(-0.5, 0.0), Vec2::new(0.5, 0.1), 0.2).unwrap(),
        Shape::polygon(&[
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.1),
            Vec2::new(0.4, 0.9),
        ])
        .unwrap(),
    ]
}

#[test]
fn collider_poses_are_the_referees_placement() {
    let pose = Pose::new(Vec2::new(3.25, -7.5), 0.7);
    for s in shapes() {
        let (expected, _) = place(&s, &pose, Vec2::ZERO).unwrap();
        assert_eq!(collider_pose(&s, &pose).unwrap(), expected, "{s:?}");
    }
}

/// A body of `shape` at `(x, 0)` moving at `(vx, 0)`.
fn body(layer: u8, kind: BodyKind, shape: Shape, x: f64, vx: f64) -> BodyDef {
    BodyDef {
        layer,
        kind,
        shape,
        position: Vec2::new(x, 0.0),
        velocity: Vec2::new(vx, 0.0),
        ..BodyDef::default()
    }
}

/// A scene of `bodies` in which the listed layer pairs `report`.
fn scene(names: &[&str], reports: &[(u8, u8)], bodies: Vec<BodyDef>) -> Scenario {
    let pairs: Vec<_> = reports
        .iter()
        .map(|&(a, b)| (a, b, Response::Report))
        .collect();
    let world = WorldDef {
        layers: ricochet_scenes::layers(names, &pairs),
        ..WorldDef::default()
    };
    ricochet_scenes::scenario("t", world, bodies, 600)
}

/// A moving ball overlapping a static box by 0.2 along x, and a triangle far away.
fn small_scene() -> Scenario {
    let triangle = Shape::polygon(&[Vec2::ZERO, Vec2::X, Vec2::Y]).unwrap();
    scene(
        &["a", "b"],
        &[(0, 1)],
        vec![
            body(0, BodyKind::Dynamic, Shape::circle(0.5).unwrap(), 0.0, 1.0),
            body(
                1,
                BodyKind::Static,
                Shape::aabb(Vec2::splat(0.5)).unwrap(),
                0.8,
                0.0,
            ),
            body(1, BodyKind::Dynamic, triangle, 10.0, 0.0),
        ],
    )
}

/// Issue 36: the bench's rapier scene takes a terrain chain as one polyline collider. A ball
/// (radius 0.5) moving right over a flat chain's joints, 0.2 into it (its centre at height
/// 0.3), and a static box far away: every frame both find exactly the ball-chain pair, and
/// its depth and normal agree.
#[test]
fn rapier_and_ricochet_agree_on_a_chain() {
    let points: Vec<Vec2> = (0..8).map(|k| Vec2::new(f64::from(k) - 4.0, 0.0)).collect();
    let chain = Shape::chain(&points, None, None).unwrap();
    let mut ball = body(0, BodyKind::Dynamic, Shape::circle(0.5).unwrap(), -2.0, 1.0);
    ball.position.y = 0.3;
    let scenario = scene(
        &["a", "b"],
        &[(0, 1)],
        vec![
            body(1, BodyKind::Static, chain, 0.0, 0.0),
            ball,
            body(
                1,
                BodyKind::Static,
                Shape::aabb(Vec2::splat(0.5)).unwrap(),
                50.0,
                0.0,
            ),
        ],
    );
    step_together(&scenario, 90, 1);
}

/// Two bodies overlapping by 0.2 along x and a third far away: rapier finds exactly the
/// overlapping pair, and the comparison agrees with Ricochet's frame.
#[test]
fn rapier_and_ricochet_agree_on_a_small_scene() {
    let scenario = small_scene();
    step_together(&scenario, 3, 1);
}

/// Steps Ricochet and rapier together for `frames` frames: every frame rapier finds `both`
/// penetrating pairs, Ricochet the same, and the comparison agrees. Returns the simulation
/// and rapier's pairs of the last frame.
fn step_together(
    scenario: &Scenario,
    frames: usize,
    both: u64,
) -> (Simulation, Vec<(Entity, Entity)>) {
    let mut sim = Simulation::new(scenario);
    let mut rapier = RapierScene::new(&sim).unwrap();
    let mut last = Vec::new();
    for _ in 0..frames {
        let out = sim.step();
        rapier.sync(&sim).unwrap();
        rapier.step();
        let pairs = rapier.penetrating();
        assert_eq!(pairs.len() as u64, both, "{pairs:?}");
        let agreement = compare_contacts(&sim, &out, &pairs, CONTACT_TOLERANCE);
        assert!(agreement.all_agree(), "{agreement:?}");
        assert_eq!(agreement.both, both);
        last = pairs.into_keys().collect();
    }
    (sim, last)
}

/// The comparison catches a Ricochet that misses a contact, invents one, or logs a wrong
/// depth at other poses.
#[test]
fn a_missing_invented_or_wrong_contact_is_a_disagreement() {
    let scenario = small_scene();
    let mut sim = Simulation::new(&scenario);
    let mut rapier = RapierScene::new(&sim).unwrap();
    let out = sim.step();
    rapier.sync(&sim).unwrap();
    rapier.step();
    let pairs = rapier.penetrating();
    assert_eq!(out.contacts.len(), 1);

    let mut missing = out.clone();
    missing.contacts.clear();
    let a = compare_contacts(&sim, &missing, &pairs, CONTACT_TOLERANCE);
    assert_eq!((a.compared, a.rapier_only), (1, 1), "{a:?}");
    assert!(a.details[0].contains("Ricochet logged no contact"), "{a:?}");

    let mut invented = out.clone();
    let mut fake = invented.contacts[0].clone();
    fake.b = sim.world().entity[2];
    fake.pose_b = sim.world().pose(2);
    invented.contacts.push(fake);
    let a = compare_contacts(&sim, &invented, &pairs, CONTACT_TOLERANCE);
    assert_eq!((a.compared, a.ricochet_only, a.agreed), (2, 1, 1), "{a:?}");

    let mut wrong = out.clone();
    wrong.contacts[0].pose_a.position.x -= 0.05;
    let a = compare_contacts(&sim, &wrong, &pairs, CONTACT_TOLERANCE);
    // The record no longer sits at the end-of-frame poses: checked at its own poses
    // (wrong depth there), and rapier's end-of-frame pair is then missing from Ricochet.
    assert_eq!((a.ricochet_only, a.rapier_only), (1, 1), "{a:?}");
}

/// Kinematic and static bodies never collide with each other in Ricochet; rapier is set
/// up the same way (only dynamic bodies' colliders enable fixed–fixed pairs).
#[test]
fn pairs_without_a_dynamic_body_are_not_tested_by_either_engine() {
    let mut ball = body(
        0,
        BodyKind::Kinematic,
        Shape::circle(0.5).unwrap(),
        0.0,
        1.0,
    );
    ball.position = Vec2::ZERO;
    let mut peg = body(0, BodyKind::Static, Shape::circle(0.5).unwrap(), 0.5, 0.0);
    peg.position.y = 0.5;
    let block = body(
        0,
        BodyKind::Static,
        Shape::aabb(Vec2::splat(0.5)).unwrap(),
        0.5,
        0.0,
    );
    let scenario = scene(&["a"], &[(0, 0)], vec![ball, block, peg]);
    let (sim, _) = step_together(&scenario, 2, 0);
    assert_eq!(sim.world().len(), 3);
}

/// A scene of 40 layers: rapier's 32 collision groups cannot name them, so the layer filter
/// asks the matrix through the pair hook. Bodies sit on layers past 32: the `report` pair
/// (35, 36) is found, the overlapping `ignore` pair (37, 38) is not, and (1, 33) — whose
/// bits would alias (33 mod 32 = 1) if groups were used — only when its response says so.
#[test]
fn more_than_32_layers_filter_by_the_matrix() {
    use crate::pairs::LayerFilter;

    let names: Vec<String> = (0..40).map(|k| format!("l{k}")).collect();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    // Pairs 0.2 deep, 10 apart: (35, 36) report, (37, 38) ignore, (1, 33) report, (1, 1)
    // ignore; the first body of each pair is dynamic, the second static.
    let pairs = [(35, 36), (37, 38), (1, 33), (1, 1)];
    let circle = || Shape::circle(0.5).unwrap();
    let bodies = pairs
        .iter()
        .enumerate()
        .flat_map(|(k, &(a, b))| {
            let x = 10.0 * k as f64;
            [
                body(a, BodyKind::Dynamic, circle(), x, 0.0),
                body(b, BodyKind::Static, circle(), x + 0.8, 0.0),
            ]
        })
        .collect();
    let scenario = scene(&names, &[(35, 36), (1, 33)], bodies);
    assert!(!LayerFilter::new(&scenario.world.layers).uses_groups());
    let (sim, last) = step_together(&scenario, 3, 2);
    let e = |i: usize| sim.world().entity[i];
    assert_eq!(last, [(e(0), e(1)), (e(4), e(5))]);
    // The referee filters its own pipeline the same way.
    let summary = crate::validate(&scenario, 3, crate::Tolerances::default());
    assert!(summary.passed(), "{}", crate::summary_table(&summary));
}
