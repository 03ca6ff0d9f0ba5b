//! Swept `separate`: a moving body never passes through static geometry it `separate`s from,
//! whatever its speed. Boxes by the per-axis swept move (`stages/sweep_axis.rs`), every
//! other shape by time of impact in `detect`. Each case is checked every frame: once the
//! body's lowest point was above the floor's top, it is never below the floor's bottom.

use ricochet_geom::{Shape, Vec2};
use ricochet_scenes::{layers, scenario};
use ricochet_sim::{BodyDef, BodyKind, Response, SLOP, Simulation, WorldDef};

const THING: u8 = 0;
const FLOOR: u8 = 1;

/// A static floor `thickness` thick, 40 wide, top at y = 0; one dynamic body of `shape`
/// at `(0.1, height)` (off the floor's centre) moving at `vy`, under gravity `g`.
fn drop(shape: Shape, height: f64, vy: f64, g: f64, thickness: f64) -> Simulation {
    let world = WorldDef {
        layers: layers(&["thing", "floor"], &[(THING, FLOOR, Response::Separate)]),
        gravity: Vec2::new(0.0, g),
        ..WorldDef::default()
    };
    let floor = BodyDef {
        name: "floor".to_owned(),
        layer: FLOOR,
        kind: BodyKind::Static,
        shape: Shape::aabb(Vec2::new(20.0, thickness / 2.0)).unwrap(),
        position: Vec2::new(0.0, -thickness / 2.0),
        ..BodyDef::default()
    };
    let thing = BodyDef {
        name: "thing".to_owned(),
        layer: THING,
        shape,
        position: Vec2::new(0.1, height),
        velocity: Vec2::new(0.0, vy),
        ..BodyDef::default()
    };
    Simulation::new(&scenario("drop", world, vec![floor, thing], 10_000))
}

/// Runs `frames` frames and checks every one: the body's lowest point, once above the
/// floor's top (y = 0), never goes below its bottom (y = -thickness). Returns the body's
/// lowest point and y at the end.
fn run(sim: &mut Simulation, frames: u32, thickness: f64, what: &str) -> (f64, f64) {
    let lowest = |sim: &mut Simulation| {
        let i = sim.world().find("thing").unwrap();
        let w = sim.world();
        (w.shape(i).bounds(&w.pose(i)).min.y, w.position[i].y)
    };
    let mut above = lowest(sim).0 >= 0.0;
    for frame in 1..=frames {
        sim.step();
        let (low, y) = lowest(sim);
        assert!(
            !above || low >= -thickness,
            "{what}: frame {frame}: lowest point {low} below the floor's bottom (y = {y})"
        );
        above |= low >= 0.0;
    }
    lowest(sim)
}

/// A 0.8 × 0.8 crate.
fn crate_box() -> Shape {
    Shape::aabb(Vec2::splat(0.4)).unwrap()
}

#[test]
fn the_issue_s_crate_dropped_from_200_rests_on_the_half_unit_ledge() {
    // 0.8 × 0.8 from y = 200 under gravity -30: about 1.8 units a frame at the ledge.
    let mut sim = drop(crate_box(), 200.0, 0.0, -30.0, 0.5);
    let (_, y) = run(&mut sim, 400, 0.5, "crate");
    assert!((y - 0.4).abs() <= SLOP, "the crate ended at y = {y}");
}

#[test]
fn crates_dropped_or_thrown_onto_a_thin_floor_land_flush() {
    for (height, vy) in [
        (10.0, 0.0),
        (100.0, 0.0),
        (1_000.0, 0.0),
        (10_000.0, 0.0),
        (50.0, -1_000.0),
        (50.0, -10_000.0),
        (10_000.0, -10_000.0),
    ] {
        for half in [0.4, 0.01, 3.0] {
            let what = format!("box {half} from {height} at {vy}");
            let shape = Shape::aabb(Vec2::splat(half)).unwrap();
            let mut sim = drop(shape, height, vy, -30.0, 0.05);
            let mut landed = false;
            // At most ~26 s of fall from 10,000 units: 1600 frames.
            for _ in 0..40 {
                let (_, y) = run(&mut sim, 50, 0.05, &what);
                if y <= half + 1.0 {
                    landed = true;
                    break;
                }
            }
            assert!(landed, "{what}: never landed");
            let (_, y) = run(&mut sim, 5, 0.05, &what);
            assert!((y - half).abs() <= SLOP, "{what}: rests at y = {y}");
        }
    }
}

#[test]
fn the_landing_frame_puts_a_fast_crate_exactly_flush() {
    // 10,000 units/s: 166.7 units a frame; the frame it meets the floor, it stops on it.
    let mut sim = drop(crate_box(), 100.0, -10_000.0, 0.0, 0.05);
    sim.step(); // frame 0: the initial state
    sim.step();
    let i = sim.world().find("thing").unwrap();
    assert_eq!(sim.world().position[i].y, 0.4);
    assert_eq!(sim.world().velocity(i).y, 0.0);
    assert!(sim.world().grounded(i));
}

#[test]
fn a_fast_crate_thrown_sideways_stops_flush_against_a_thin_wall() {
    let world = WorldDef {
        layers: layers(&["thing", "floor"], &[(THING, FLOOR, Response::Separate)]),
        ..WorldDef::default()
    };
    let wall = BodyDef {
        name: "wall".to_owned(),
        layer: FLOOR,
        kind: BodyKind::Static,
        shape: Shape::aabb(Vec2::new(0.025, 5.0)).unwrap(),
        position: Vec2::new(10.025, 0.0),
        ..BodyDef::default()
    };
    let thing = BodyDef {
        name: "thing".to_owned(),
        layer: THING,
        shape: crate_box(),
        velocity: Vec2::new(10_000.0, 0.0),
        ..BodyDef::default()
    };
    let mut sim = Simulation::new(&scenario("wall", world, vec![wall, thing], 10));
    sim.step(); // frame 0: the initial state
    sim.step();
    let i = sim.world().find("thing").unwrap();
    assert_eq!(sim.world().position[i].x, 9.6);
    assert_eq!(sim.world().velocity(i).x, 0.0);
}

#[test]
fn the_issue_s_ball_thrown_down_at_120_rests_on_the_half_unit_ledge() {
    // A 0.3-radius ball thrown down at 120 units/s (2 units a frame): from a few heights,
    // so the frames fall differently against the ledge.
    for k in 0..8 {
        let height = 10.0 + 0.25 * f64::from(k);
        let mut sim = drop(Shape::circle(0.3).unwrap(), height, -120.0, -30.0, 0.5);
        let (low, _) = run(&mut sim, 200, 0.5, &format!("ball from {height}"));
        assert!(
            low.abs() <= 1e-6,
            "from {height}: rests with its bottom at {low}"
        );
    }
}

/// A shape of every kind that is not resolved per axis, about 0.6 across.
fn shapes() -> Vec<(&'static str, Shape)> {
    let v = |x, y| Vec2::new(x, y);
    vec![
        ("ball", Shape::circle(0.3).unwrap()),
        ("small ball", Shape::circle(0.01).unwrap()),
        (
            "capsule",
            Shape::capsule(v(-0.3, 0.0), v(0.3, 0.0), 0.1).unwrap(),
        ),
        (
            "upright capsule",
            Shape::capsule(v(0.0, -0.3), v(0.0, 0.3), 0.05).unwrap(),
        ),
        (
            "polygon",
            Shape::polygon(&[
                v(-0.3, -0.2),
                v(0.3, -0.3),
                v(0.35, 0.2),
                v(0.0, 0.4),
                v(-0.3, 0.2),
            ])
            .unwrap(),
        ),
        (
            "triangle",
            Shape::polygon(&[v(-0.3, -0.2), v(0.3, -0.2), v(0.0, 0.3)]).unwrap(),
        ),
    ]
}

#[test]
fn balls_capsules_and_polygons_dropped_or_thrown_onto_a_thin_floor_rest_on_it() {
    for (name, shape) in shapes() {
        for (height, vy) in [
            (10.0, 0.0),
            (1_000.0, 0.0),
            (10_000.0, 0.0),
            (50.0, -1_000.0),
            (50.0, -10_000.0),
            (10_000.0, -10_000.0),
        ] {
            let what = format!("{name} from {height} at {vy}");
            let mut sim = drop(shape.clone(), height, vy, -30.0, 0.05);
            let mut landed = false;
            for _ in 0..40 {
                let (low, _) = run(&mut sim, 50, 0.05, &what);
                if low <= 1.0 {
                    landed = true;
                    break;
                }
            }
            assert!(landed, "{what}: never landed");
            let (low, _) = run(&mut sim, 30, 0.05, &what);
            assert!(
                low.abs() <= 1e-6,
                "{what}: rests with its lowest point at {low}"
            );
        }
    }
}

#[test]
fn a_fast_ball_rolling_over_a_tiled_floor_is_not_stopped_at_the_seams() {
    // 30 units/s along x (half a unit a frame, more than the 0.1 radius): every frame it
    // touches the next tile on the way; it must not stop there.
    for g in [-30.0, 0.0] {
        let world = WorldDef {
            layers: layers(&["thing", "floor"], &[(THING, FLOOR, Response::Separate)]),
            gravity: Vec2::new(0.0, g),
            ..WorldDef::default()
        };
        let mut bodies: Vec<BodyDef> = (0..60)
            .map(|k| BodyDef {
                name: format!("tile{k}"),
                layer: FLOOR,
                kind: BodyKind::Static,
                shape: Shape::aabb(Vec2::new(0.5, 0.5)).unwrap(),
                position: Vec2::new(f64::from(k), -0.5),
                ..BodyDef::default()
            })
            .collect();
        bodies.push(BodyDef {
            name: "thing".to_owned(),
            layer: THING,
            shape: Shape::circle(0.1).unwrap(),
            position: Vec2::new(0.0, 0.1),
            velocity: Vec2::new(30.0, 0.0),
            ..BodyDef::default()
        });
        let mut sim = Simulation::new(&scenario("roll", world, bodies, 100));
        for _ in 0..=60 {
            sim.step();
        }
        let i = sim.world().find("thing").unwrap();
        let (p, v) = (sim.world().position[i], sim.world().velocity(i));
        assert_eq!(v.x, 30.0, "gravity {g}: the ball slowed to {v}");
        assert!((p.x - 30.0).abs() < 1e-9, "gravity {g}: the ball is at {p}");
        assert!((p.y - 0.1).abs() <= 1e-6, "gravity {g}: the ball is at {p}");
    }
}

#[test]
fn fast_bodies_land_on_a_thin_rising_kinematic_platform() {
    // The platform rises at 3 units/s; a crate and a ball fall onto it at 2,000 units/s.
    for (name, shape, half) in [
        ("crate", crate_box(), 0.4),
        ("ball", Shape::circle(0.3).unwrap(), 0.3),
    ] {
        let world = WorldDef {
            layers: layers(&["thing", "floor"], &[(THING, FLOOR, Response::Separate)]),
            gravity: Vec2::new(0.0, -30.0),
            ..WorldDef::default()
        };
        let lift = BodyDef {
            name: "lift".to_owned(),
            layer: FLOOR,
            kind: BodyKind::Kinematic,
            shape: Shape::aabb(Vec2::new(5.0, 0.025)).unwrap(),
            position: Vec2::new(0.0, -0.025),
            velocity: Vec2::new(0.0, 3.0),
            ..BodyDef::default()
        };
        let thing = BodyDef {
            name: "thing".to_owned(),
            layer: THING,
            shape,
            position: Vec2::new(0.1, 100.0),
            velocity: Vec2::new(0.0, -2_000.0),
            ..BodyDef::default()
        };
        let mut sim = Simulation::new(&scenario("lift", world, vec![lift, thing], 100));
        for frame in 0..=30 {
            sim.step();
            let w = sim.world();
            let (l, t) = (w.find("lift").unwrap(), w.find("thing").unwrap());
            let top = w.position[l].y + 0.025;
            let low = w.position[t].y - half;
            assert!(
                low >= top - 0.05 - 1e-9,
                "{name}: frame {frame}: lowest point {low} below the lift's bottom ({top} top)"
            );
        }
        let w = sim.world();
        let (l, t) = (w.find("lift").unwrap(), w.find("thing").unwrap());
        let gap = (w.position[t].y - half) - (w.position[l].y + 0.025);
        assert!(gap.abs() <= 1e-6, "{name}: rests {gap} above the lift");
    }
}
