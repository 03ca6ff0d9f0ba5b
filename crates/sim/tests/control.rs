//! The library API a game embeds: scenes built in code, bodies addressed by entity, and
//! writes that keep the broad phase's static structures right.

use ricochet_geom::{Shape, Vec2};
use ricochet_sim::broad_phase::BroadPhaseKind;
use ricochet_sim::{
    Action, BodyDef, BodyKind, ControlError, Event, GameEvent, Layers, NonFinite, Response,
    Scenario, ScriptAction, ScriptInput, Simulation, WorldBounds, WorldDef,
};

const KINDS: [BroadPhaseKind; 6] = [
    BroadPhaseKind::Auto,
    BroadPhaseKind::BruteForce,
    BroadPhaseKind::SortAndSweep,
    BroadPhaseKind::Grid,
    BroadPhaseKind::Quadtree,
    BroadPhaseKind::Tree,
];

fn world(kind: BroadPhaseKind, response: Response) -> WorldDef {
    let mut layers = Layers::new(vec!["ball".to_owned(), "wall".to_owned()]);
    layers.set(0, 1, response);
    WorldDef {
        layers,
        broad_phase: kind,
        ..WorldDef::default()
    }
}

fn circle(layer: u8, kind: BodyKind, x: f64) -> BodyDef {
    BodyDef {
        layer,
        kind,
        shape: Shape::circle(1.0).unwrap(),
        position: Vec2::new(x, 0.0),
        ..BodyDef::default()
    }
}

/// A static circle moved through the API next to a resting ball is found at its new place
/// by every broad phase (the static structures are rebuilt), and no longer at its old one.
#[test]
fn a_moved_static_body_is_seen_by_the_broad_phase() {
    for kind in KINDS {
        let mut sim = Simulation::from_def(world(kind, Response::Report)).unwrap();
        let ball = sim.spawn(&circle(0, BodyKind::Dynamic, 0.0));
        // Enough static bodies that `Auto` picks the grid for its statics.
        let walls: Vec<_> = (0..40)
            .map(|k| sim.spawn(&circle(1, BodyKind::Static, 100.0 + 3.0 * f64::from(k))))
            .collect();
        for _ in 0..3 {
            assert!(
                sim.step().contacts.is_empty(),
                "{kind:?}: nothing touches yet"
            );
        }
        sim.set_position(walls[7], Vec2::new(1.5, 0.0)).unwrap();
        let out = sim.step();
        assert_eq!(out.contacts.len(), 1, "{kind:?}: the moved wall is found");
        let c = &out.contacts[0];
        assert_eq!((c.a, c.b), (ball, walls[7]));
        // Two unit circles 1.5 apart: depth 2 - 1.5, normal +x, exactly.
        assert_eq!(c.depth, 0.5);
        assert_eq!(c.normal, Vec2::new(1.0, 0.0));
        // Moved away again: the old place is empty.
        sim.set_position(walls[7], Vec2::new(-500.0, 0.0)).unwrap();
        assert!(sim.step().contacts.is_empty(), "{kind:?}: no stale pair");
    }
}

/// A static floor tile moved under a falling box is solid to the per-axis stages at its new
/// place: the box lands on it, flush.
#[test]
fn a_moved_static_tile_holds_up_a_box() {
    let mut def = world(BroadPhaseKind::Auto, Response::Separate);
    def.gravity = Vec2::new(0.0, -10.0);
    let mut sim = Simulation::from_def(def).unwrap();
    let crate_ = sim.spawn(&BodyDef {
        layer: 0,
        shape: Shape::aabb(Vec2::splat(0.5)).unwrap(),
        position: Vec2::new(0.0, 2.0),
        ..BodyDef::default()
    });
    let tile = |x: f64| BodyDef {
        layer: 1,
        kind: BodyKind::Static,
        shape: Shape::aabb(Vec2::new(1.0, 0.5)).unwrap(),
        position: Vec2::new(x, 0.0),
        ..BodyDef::default()
    };
    let floor = sim.spawn(&tile(50.0));
    for _ in 0..3 {
        sim.step();
    }
    sim.set_position(floor, Vec2::new(0.0, 0.0)).unwrap();
    for _ in 0..120 {
        sim.step();
    }
    // Resting on the tile's top (y = 0.5): the box's centre is at 1.0 exactly.
    assert_eq!(sim.position(crate_).unwrap().y, 1.0);
    assert_eq!(sim.grounded(crate_), Some(true));
}

#[test]
fn a_removed_body_is_an_error_not_another_body() {
    let mut sim = Simulation::from_def(world(BroadPhaseKind::Auto, Response::Report)).unwrap();
    let a = sim.spawn(&circle(0, BodyKind::Dynamic, 0.0));
    sim.despawn(a).unwrap();
    // The slot is reused with the next generation: the old id names nothing.
    let b = sim.spawn(&circle(0, BodyKind::Dynamic, 5.0));
    assert_eq!((b.index, b.generation), (a.index, a.generation + 1));
    assert_eq!(sim.position(a), None);
    assert_eq!(sim.position(b), Some(Vec2::new(5.0, 0.0)));
    assert_eq!(
        sim.set_position(a, Vec2::ZERO),
        Err(ControlError::NoSuchBody(a))
    );
    assert_eq!(
        sim.set_velocity(b, Vec2::new(f64::NAN, 0.0)),
        Err(ControlError::OutOfRange { field: "velocity" })
    );
    assert_eq!(
        sim.set_position(b, Vec2::new(1e300, 0.0)),
        Err(ControlError::OutOfRange { field: "position" })
    );
}

#[test]
fn world_settings_built_in_code_are_checked() {
    let bad_dt = WorldDef {
        dt: 0.0,
        ..WorldDef::default()
    };
    assert!(matches!(
        Simulation::from_def(bad_dt),
        Err(ControlError::World { field: "dt", .. })
    ));
    let bad_bounds = WorldDef {
        bounds: Some(WorldBounds {
            min: Vec2::new(1.0, 0.0),
            max: Vec2::new(0.0, 1.0),
            wrap: true,
        }),
        ..WorldDef::default()
    };
    assert!(matches!(
        Simulation::from_def(bad_bounds),
        Err(ControlError::World {
            field: "bounds",
            ..
        })
    ));
}

/// Velocity set through the API moves the body by exactly `v dt` per step (semi-implicit
/// Euler with no force), and a static body's velocity stays zero.
#[test]
fn set_velocity_moves_a_body_and_never_a_static_one() {
    let mut sim = Simulation::from_def(world(BroadPhaseKind::Auto, Response::Ignore)).unwrap();
    let ball = sim.spawn(&circle(0, BodyKind::Dynamic, 0.0));
    let wall = sim.spawn(&circle(1, BodyKind::Static, 10.0));
    sim.step(); // frame 0: the initial state
    sim.set_velocity(ball, Vec2::new(60.0, 0.0)).unwrap();
    sim.set_velocity(wall, Vec2::new(60.0, 0.0)).unwrap();
    sim.step();
    assert_eq!(
        sim.position(ball),
        Some(Vec2::new(60.0 * (1.0 / 60.0), 0.0))
    );
    assert_eq!(sim.position(wall), Some(Vec2::new(10.0, 0.0)));
    assert_eq!(sim.velocity(wall), Some(Vec2::ZERO));
}

/// Actions sent with `apply` take effect at the next step, after that frame's script events,
/// in the order sent; one sent to a body removed before the step is reported, not applied.
#[test]
fn applied_actions_follow_the_script_in_the_order_sent() {
    let scenario = Scenario {
        world: world(BroadPhaseKind::Auto, Response::Ignore),
        bodies: vec![
            BodyDef {
                name: "a".to_owned(),
                ..circle(0, BodyKind::Dynamic, 0.0)
            },
            BodyDef {
                name: "b".to_owned(),
                ..circle(0, BodyKind::Dynamic, 10.0)
            },
        ],
        script: vec![Event {
            frame: 1,
            action: ScriptAction::Body {
                name: "a".to_owned(),
                action: Action::SetVelocity(Vec2::new(1.0, 0.0)),
            },
        }],
        ..Scenario::default()
    };
    let mut sim = Simulation::from_scenario(scenario);
    let (a, b) = (
        sim.entity_named("a").unwrap(),
        sim.entity_named("b").unwrap(),
    );
    sim.step();
    // Sent before frame 1: applied after the script's set_velocity, so the last one wins.
    sim.apply(a, Action::SetVelocity(Vec2::new(2.0, 0.0)))
        .unwrap();
    sim.apply(a, Action::SetVelocity(Vec2::new(3.0, 0.0)))
        .unwrap();
    sim.apply(b, Action::Destroy).unwrap();
    assert_eq!(
        sim.position(a),
        Some(Vec2::ZERO),
        "nothing happens before the step"
    );
    let out = sim.step();
    let inputs: Vec<_> = out
        .events
        .iter()
        .filter_map(|e| match e {
            GameEvent::Input { body, input } => Some((*body, input.clone())),
            _ => None,
        })
        .collect();
    assert_eq!(
        inputs,
        vec![
            (a, ScriptInput::Velocity(Vec2::new(1.0, 0.0))),
            (a, ScriptInput::Velocity(Vec2::new(2.0, 0.0))),
            (a, ScriptInput::Velocity(Vec2::new(3.0, 0.0))),
        ]
    );
    assert_eq!(sim.velocity(a), Some(Vec2::new(3.0, 0.0)));
    assert_eq!(sim.position(a), Some(Vec2::new(3.0 * (1.0 / 60.0), 0.0)));
    assert!(!sim.contains(b));
    // b is gone: an action sent to it now is refused at once ...
    assert_eq!(sim.apply(b, Action::Jump), Err(ControlError::NoSuchBody(b)));
    // ... and one sent to a body removed before the step is reported as gone.
    sim.apply(a, Action::Thrust(true)).unwrap();
    sim.despawn(a).unwrap();
    let out = sim.step();
    assert_eq!(
        out.events,
        vec![GameEvent::Gone {
            action: "thrust",
            body: a
        }]
    );
    // Out-of-range values are refused and never queued.
    let c = sim.spawn(&circle(0, BodyKind::Dynamic, 0.0));
    assert_eq!(
        sim.apply(c, Action::Turn(1.5)),
        Err(ControlError::OutOfRange { field: "input" })
    );
    assert!(sim.step().events.is_empty());
}

/// Gravity 1e308 times a scale of 1e308 overflows to -inf at once: the first step leaves the
/// body at y = -inf (issue 11), and `first_non_finite` names it, its field and value.
#[test]
fn an_overflowing_body_is_named() {
    let mut world = world(BroadPhaseKind::Auto, Response::Ignore);
    world.gravity = Vec2::new(0.0, -1e308);
    let mut sim = Simulation::from_def(world).unwrap();
    let calm = sim.spawn(&BodyDef {
        gravity_scale: 0.0,
        ..circle(0, BodyKind::Dynamic, 0.0)
    });
    let falling = sim.spawn(&BodyDef {
        gravity_scale: 1e308,
        ..circle(0, BodyKind::Dynamic, 5.0)
    });
    sim.step();
    assert_eq!(sim.first_non_finite(), None, "frame 0 moves nothing");
    sim.step();
    let bad = sim.first_non_finite().unwrap();
    // v = -inf after the forces; y = 0 + -inf * dt = -inf.
    assert_eq!(bad.body, falling);
    assert_eq!(bad.field, "position");
    assert_eq!(bad.value, [5.0, f64::NEG_INFINITY]);
    assert!(sim.position(calm).unwrap().is_finite());
}

/// Two bodies whose `m v² / 2` are each finite but sum past `f64::MAX` overflow the
/// kinetic energy: both checks name the second, by the step's reported sum
/// (`first_non_finite_after`) or by summing again. An `out` of an earlier step is not
/// trusted: after a frame that made the energy overflow, the stale `out` (whose reported sum
/// was finite) still finds it.
#[test]
fn an_overflowing_kinetic_energy_is_named_by_the_steps_sum_or_a_new_one() {
    let mut sim = Simulation::from_def(world(BroadPhaseKind::Auto, Response::Ignore)).unwrap();
    let heavy = |x| BodyDef {
        mass: 2.0,
        ..circle(0, BodyKind::Dynamic, x)
    };
    let (a, b) = (sim.spawn(&heavy(0.0)), sim.spawn(&heavy(10.0)));
    let calm = sim.step();
    assert!(calm.stats.kinetic_energy.is_finite());
    assert_eq!(sim.first_non_finite_after(&calm), None);
    // v² = 0.9 MAX and m = 2: each body's m v² / 2 is 0.9 MAX, their sum 1.8 MAX.
    let v = (f64::MAX * 0.9).sqrt();
    for e in [a, b] {
        sim.set_velocity(e, Vec2::new(v, 0.0)).unwrap();
    }
    let out = sim.step();
    assert!(out.stats.kinetic_energy.is_infinite());
    let want = NonFinite {
        body: b,
        field: "kinetic_energy",
        value: [f64::INFINITY, 0.0],
    };
    assert_eq!(sim.first_non_finite(), Some(want));
    assert_eq!(sim.first_non_finite_after(&out), Some(want));
    assert_eq!(sim.first_non_finite_after(&calm), Some(want), "a stale out");
}

/// Finite values whose sum overflows are finite still: `first_non_finite`'s quick pass adds
/// each body's values up, so a kinematic body moving at `(f64::MAX, f64::MAX)` (no kinetic
/// energy is counted for it) sends it to the value-by-value check, which finds nothing.
#[test]
fn finite_values_summing_past_the_largest_f64_are_not_named() {
    let mut sim = Simulation::from_def(world(BroadPhaseKind::Auto, Response::Ignore)).unwrap();
    let fast = sim.spawn(&circle(0, BodyKind::Kinematic, 0.0));
    sim.set_velocity(fast, Vec2::new(f64::MAX, f64::MAX))
        .unwrap();
    assert!(
        (f64::MAX + f64::MAX).is_infinite(),
        "the sum the quick pass sees"
    );
    assert_eq!(sim.first_non_finite(), None);
}

/// A clone is a snapshot: stepped on, it gives the same states as the original, bit for bit
/// (`ricochet serve` seeks back from such snapshots). Every kind of broad phase and the
/// per-axis grids are exercised: asteroids (sort and sweep), rain (the grid for a crowd),
/// a platformer (static grids, per-axis separation).
#[test]
fn a_cloned_simulation_steps_exactly_as_the_original() {
    use ricochet_scenes::bench::Scene;
    for name in ["asteroids-2000", "rain-2000", "platformer-2000-200"] {
        let scenario = Scene::parse(name).unwrap().build(120);
        let mut sim = Simulation::new(&scenario);
        for _ in 0..40 {
            sim.step();
        }
        let mut snapshot = sim.clone();
        assert_eq!(snapshot.frame(), sim.frame());
        for _ in 0..60 {
            let (a, b) = (sim.step(), snapshot.step());
            assert_eq!(
                a.contacts.len(),
                b.contacts.len(),
                "{name}: frame {}",
                a.frame
            );
            assert_eq!(
                sim.world().digest(),
                snapshot.world().digest(),
                "{name}: frame {}",
                a.frame
            );
        }
    }
}
