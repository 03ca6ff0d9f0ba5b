//! The calls a game server makes between steps, written with the prelude alone (no second
//! dependency on `ricochet-geom`): tiles spawned from code, a kinematic lift driven by target
//! poses with a rider on it, a shape changed at run time, the game's own data on a body, the
//! layer of a removed body, and the readers by entity.
//!
//! Expected values come from the stages' own `f64` operations (semi-implicit Euler,
//! `x += v * dt`; frame 0 moves nothing) and from exact geometry, never from a run.

use ricochet_sim::prelude::*;

/// Seconds per step (the default).
const DT: f64 = 1.0 / 60.0;

/// A world with gravity `g` and the layers `box` (0) and `tile` (1), boxes separated from
/// tiles and from each other.
fn platformer(g: f64) -> Simulation {
    let mut layers = Layers::new(vec!["box".into(), "tile".into()]);
    layers.set(0, 1, Response::Separate);
    layers.set(0, 0, Response::Separate);
    let world = WorldDef {
        gravity: Vec2::new(0.0, g),
        layers,
        ..WorldDef::default()
    };
    Simulation::from_def(world).expect("a valid world")
}

fn aabb(hx: f64, hy: f64) -> Shape {
    Shape::aabb(Vec2::new(hx, hy)).expect("positive half extents")
}

#[test]
fn tiles_spawned_from_code_are_scenery_in_id_order_and_hold_a_box_up() {
    let mut sim = platformer(-20.0);
    let early = sim.spawn(&BodyDef {
        name: "box".into(),
        shape: aabb(0.4, 0.4),
        position: Vec2::new(2.0, 1.0),
        ..BodyDef::default()
    });
    let floor = TileRows {
        name: "ground".into(),
        layer: 1,
        shape: aabb(0.5, 0.5),
        step: Vec2::new(1.0, 0.0),
        rows: vec![(Vec2::new(0.0, -0.5), 5), (Vec2::new(0.0, 3.5), 2)],
    };
    let ids = sim.spawn_tiles(&floor);
    assert_eq!(ids.len(), 7);
    assert!(ids.windows(2).all(|w| w[0] < w[1]), "{ids:?}");
    assert!(ids.iter().all(|&e| e > early));
    for (k, &e) in ids.iter().enumerate() {
        assert_eq!(sim.kind(e), Some(BodyKind::Static));
        assert_eq!(sim.name(e), Some("ground"));
        assert_eq!(sim.layer(e), Some(1));
        let x = if k < 5 { k as f64 } else { (k - 5) as f64 };
        let y = if k < 5 { -0.5 } else { 3.5 };
        assert_eq!(sim.position(e), Some(Vec2::new(x, y)));
        let i = sim.world().index_of(e).unwrap();
        assert!(sim.world().is_scenery(i));
    }
    // The box falls onto the row's top (y = 0) and stands there: its centre at 0.4.
    sim.step();
    for _ in 0..120 {
        sim.step();
    }
    let y = sim.position(early).unwrap().y;
    assert!((y - 0.4).abs() <= 1e-12, "{y}");
    assert_eq!(sim.grounded(early), Some(true));
    assert_eq!(sim.on_static(early), Some(true));
    assert_eq!(
        sim.carrier(early),
        Some(None),
        "a static floor carries nothing"
    );
}

/// A lift driven by target poses carries the box on it, lands on each target, and holds
/// still in a step that was given none.
#[test]
fn a_lift_driven_by_target_poses_carries_its_rider_and_stops_without_one() {
    let mut sim = platformer(-20.0);
    let lift = sim.spawn(&BodyDef {
        name: "lift".into(),
        layer: 1,
        kind: BodyKind::Kinematic,
        shape: aabb(1.5, 0.25),
        ..BodyDef::default()
    });
    // Standing on the lift's top (y = 0.25), 0.3 right of its centre.
    let rider = sim.spawn(&BodyDef {
        name: "box".into(),
        shape: aabb(0.4, 0.4),
        position: Vec2::new(0.3, 0.65),
        ..BodyDef::default()
    });
    sim.step(); // frame 0
    sim.step(); // frame 1: the box settles onto the lift and rides it from now on
    assert_eq!(sim.carrier(rider), Some(Some(lift)));
    let mut target = Pose::new(Vec2::ZERO, 0.0);
    for frame in 2..40u32 {
        let before = (sim.position(lift).unwrap(), sim.position(rider).unwrap());
        target.position += Vec2::new(0.05, 0.02 * f64::from(frame % 3));
        sim.set_target_pose(lift, target).unwrap();
        sim.step();
        let p = sim.position(lift).unwrap();
        // `x + ((t - x) / dt) * dt`: the target to rounding.
        assert!(
            (p - target.position).abs().max_element() <= 1e-13,
            "{frame}: {p} {target:?}"
        );
        let v = (target.position - before.0) / DT;
        assert_eq!(sim.velocity(lift), Some(v), "{frame}: the implied velocity");
        // The rider moved by the lift's `v * dt` along x (it carries it before its own
        // motion, and nothing else moves it along x).
        let rx = sim.position(rider).unwrap().x;
        assert_eq!(rx, before.1.x + v.x * DT, "{frame}");
        assert_eq!(sim.carrier(rider), Some(Some(lift)), "{frame}");
    }
    // No new target: the next step stops the lift where it is.
    let held = sim.position(lift).unwrap();
    for _ in 0..5 {
        sim.step();
        assert_eq!(sim.velocity(lift), Some(Vec2::ZERO));
        assert_eq!(sim.position(lift), Some(held));
    }
    // A turn: the implied angular velocity.
    sim.set_target_pose(lift, Pose::new(held, 0.25)).unwrap();
    sim.step();
    assert_eq!(sim.angular_velocity(lift), Some(0.25 / DT));
    assert!((sim.angle(lift).unwrap() - 0.25).abs() <= 1e-15);
    // Only kinematic bodies take a target.
    assert_eq!(
        sim.set_target_pose(rider, Pose::new(Vec2::ZERO, 0.0)),
        Err(ControlError::WrongKind {
            body: rider,
            is: "dynamic",
            needs: "kinematic"
        })
    );
    let nan = Pose::new(Vec2::new(f64::NAN, 0.0), 0.0);
    assert!(sim.set_target_pose(lift, nan).is_err());
}

#[test]
fn a_target_set_before_frame_zero_moves_the_body_in_frame_one() {
    let mut sim = platformer(0.0);
    let lift = sim.spawn(&BodyDef {
        kind: BodyKind::Kinematic,
        layer: 1,
        shape: aabb(1.0, 0.25),
        ..BodyDef::default()
    });
    sim.set_target_pose(lift, Pose::new(Vec2::new(0.5, 0.0), 0.0))
        .unwrap();
    sim.step(); // frame 0 moves nothing
    assert_eq!(sim.position(lift), Some(Vec2::ZERO));
    sim.step();
    assert_eq!(sim.position(lift), Some(Vec2::new((0.5 / DT) * DT, 0.0)));
}

/// A shape changed at run time is what the next step's contacts see, for a moving body and
/// for a static one (re-indexed by the broad phase).
#[test]
fn set_shape_changes_what_the_next_step_touches() {
    let mut layers = Layers::new(vec!["ball".into(), "wall".into()]);
    layers.set(0, 1, Response::Report);
    let mut sim = Simulation::from_def(WorldDef {
        layers,
        ..WorldDef::default()
    })
    .unwrap();
    let ball = sim.spawn(&BodyDef {
        shape: Shape::circle(0.5).unwrap(),
        ..BodyDef::default()
    });
    let wall = sim.spawn(&BodyDef {
        layer: 1,
        kind: BodyKind::Static,
        shape: aabb(0.5, 5.0),
        position: Vec2::new(2.0, 0.0), // its left face at 1.5
        ..BodyDef::default()
    });
    assert!(sim.step().contacts.is_empty());
    // Radius 1.75: it reaches 1.75, 0.25 past the face.
    sim.set_shape(ball, Shape::circle(1.75).unwrap()).unwrap();
    let out = sim.step();
    let c = &out.contacts[..];
    assert_eq!(c.len(), 1, "{c:?}");
    assert_eq!(
        (c[0].a, c[0].b, c[0].normal),
        (ball, wall, Vec2::new(1.0, 0.0))
    );
    assert_eq!(c[0].depth, 0.25);
    // Back to 0.5, then the wall widened to a half width of 1.75: its face at 0.25.
    sim.set_shape(ball, Shape::circle(0.5).unwrap()).unwrap();
    assert!(sim.step().contacts.is_empty());
    sim.set_shape(wall, aabb(1.75, 5.0)).unwrap();
    let out = sim.step();
    assert_eq!(out.contacts.len(), 1);
    assert_eq!(out.contacts[0].depth, 0.25);
    assert_eq!(sim.shape(wall), Some(&aabb(1.75, 5.0)));
    sim.despawn(wall).unwrap();
    assert!(sim.set_shape(wall, aabb(1.0, 1.0)).is_err());
}

#[test]
fn user_data_lives_as_long_as_its_body_and_a_removal_names_the_layer() {
    let mut layers = Layers::new(vec!["ship".into(), "rock".into(), "bullet".into()]);
    layers.set(1, 2, Response::Report);
    let mut sim = Simulation::from_def(WorldDef {
        layers,
        ..WorldDef::default()
    })
    .unwrap();
    let big = u128::MAX - 7;
    let rock = sim.spawn(&BodyDef {
        layer: 1,
        user_data: big,
        ..BodyDef::default()
    });
    let bullet = sim.spawn(&BodyDef {
        layer: 2,
        position: Vec2::new(10.0, 0.0),
        ..BodyDef::default()
    });
    // Scenery (a static body of nothing but a shape) keeps data set later, and stays put.
    let tile = sim.spawn(&BodyDef {
        layer: 1,
        kind: BodyKind::Static,
        position: Vec2::new(-10.0, 0.0),
        ..BodyDef::default()
    });
    assert_eq!(sim.user_data(rock), Some(big));
    assert_eq!(sim.user_data(bullet), Some(0));
    sim.set_user_data(tile, 42).unwrap();
    for _ in 0..10 {
        sim.step();
    }
    assert_eq!(
        (sim.user_data(rock), sim.user_data(tile)),
        (Some(big), Some(42))
    );
    assert_eq!(sim.position(tile), Some(Vec2::new(-10.0, 0.0)));
    sim.apply(bullet, Action::Destroy).unwrap();
    let out = sim.step();
    assert_eq!(
        out.events,
        [GameEvent::Removed {
            body: bullet,
            layer: 2,
            cause: Removal::Script
        }]
    );
    assert_eq!(out.removed[0].layer, 2);
    assert_eq!(sim.user_data(bullet), None);
    // The freed slot goes to a new body with data of its own.
    let next = sim.spawn(&BodyDef::default());
    assert_eq!(next.index, bullet.index);
    assert_eq!(sim.user_data(next), Some(0));
}

#[test]
fn debug_is_a_summary() {
    let mut sim = platformer(-20.0);
    for k in 0..3 {
        sim.spawn(&BodyDef {
            position: Vec2::new(f64::from(k) * 3.0, 0.0),
            ..BodyDef::default()
        });
    }
    sim.step();
    sim.step();
    let text = format!("{sim:?}");
    assert!(text.starts_with("Simulation {"), "{text}");
    assert!(
        text.contains("frame: 2,") && text.contains("bodies: 3,"),
        "{text}"
    );
}
