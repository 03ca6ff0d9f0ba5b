//! Free flight: Ricochet's semi-implicit Euler against rapier's integrator.

use ricochet_oracle::{MOTION_POSITION_RELATIVE, compare_motion};
use ricochet_sim::load_scenario;

/// Odd masses, forces, gravity scales and spins, dynamic and kinematic, far from the origin:
/// the force arithmetic differs between the engines (`(f + m g s) / m` against
/// `f (1/m) + g s`), so positions agree to rounding, not to the bit.
const MIXED: &str = r#"
    dt = 0.013
    frames = 2000
    layers = ["a"]
    collide = [{ a = "a", b = "a", response = "report" }]
    world.gravity = [0.37, -9.81]
    [[bodies]]
    name = "heavy"
    layer = "a"
    shape = { kind = "circle", radius = 1 }
    mass = 3.7
    force = [1.3, -0.7]
    gravity_scale = 0.6
    velocity = [3.1, 7.9]
    angular_velocity = 2.9
    [[bodies]]
    name = "light_far"
    layer = "a"
    shape = { kind = "obb", half_extents = [1, 0.2] }
    mass = 0.013
    force = [-0.002, 0.05]
    position = [123456.7, -98765.4]
    velocity = [-1.7, 0.3]
    angle = 2.5
    angular_velocity = -7.3
    [[bodies]]
    name = "floater"
    layer = "a"
    shape = { kind = "aabb", half_extents = [1, 1] }
    gravity_scale = 0
    velocity = [0.1, 0.2]
    [[bodies]]
    name = "spinner"
    layer = "a"
    kind = "kinematic"
    shape = { kind = "capsule", a = [-1, 0], b = [1, 0], radius = 0.2 }
    velocity = [-2.5, 1.0]
    angular_velocity = 4.1
    [[bodies]]
    name = "wall"
    layer = "a"
    kind = "static"
    shape = { kind = "aabb", half_extents = [1, 1] }
"#;

#[test]
fn mixed_bodies_fly_the_same_in_both_engines() {
    let s = load_scenario(MIXED, "mixed.toml").unwrap();
    let r = compare_motion(&s, s.frames);
    println!("{r:#?}");
    assert!(r.passed(), "{r:#?}");
    // The static wall is not compared; the other four are.
    assert_eq!(r.bodies.len(), 4);
    // Rapier's linearised rotation is visible before the correction, for dynamic spinners.
    let heavy = &r.bodies[0];
    assert!(heavy.raw_angle_difference > 1e-4, "{heavy:?}");
    assert!(heavy.max_angle_error < 1e-10, "{heavy:?}");
}

#[test]
fn every_scenario_flies_the_same_in_both_engines() {
    for name in ["asteroids", "platformer", "shapes"] {
        let path = format!("{}/../../scenarios/{name}.toml", env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(&path).unwrap();
        let s = load_scenario(&text, &path).unwrap();
        let r = compare_motion(&s, s.frames);
        assert!(r.passed(), "{name}: {r:#?}");
        assert!(
            r.max_position_error <= MOTION_POSITION_RELATIVE * s.frames as f64 * 100.0,
            "{name}: {r:#?}"
        );
    }
}

/// An overflowing body (issue 11: gravity 1e308 times a scale of 1e308 is infinite) can't
/// be compared, so free flight fails; `f64::max` used to drop the NaN and report a pass.
#[test]
fn an_infinite_state_never_passes() {
    let s = load_scenario(
        r#"
        layers = ["a"]
        world.gravity = [0, -1e308]
        [[bodies]]
        layer = "a"
        shape = { kind = "circle", radius = 1 }
        gravity_scale = 1e308
        "#,
        "overflow.toml",
    )
    .unwrap();
    let r = compare_motion(&s, 5);
    assert!(!r.passed(), "{r:?}");
    assert!(!r.bodies[0].passed());
}

/// A scene with tile rows (a Tiled level's, spawned before the bodies): each body is compared
/// with its own rapier twin, not with a tile of the same index.
#[test]
fn bodies_after_tile_rows_fly_the_same_in_both_engines() {
    use ricochet_sim::{Scenario, TileRows, Vec2};
    let mut s = load_scenario(
        r#"
        frames = 120
        layers = ["tile", "a"]
        world.gravity = [0, -9.81]
        [[bodies]]
        name = "ball"
        layer = "a"
        shape = { kind = "circle", radius = 0.5 }
        position = [0, 10]
        velocity = [2, 3]
        "#,
        "tiles.toml",
    )
    .unwrap();
    s.tiles.push(TileRows {
        name: "tile".to_owned(),
        layer: 0,
        shape: ricochet_sim::Shape::aabb(Vec2::splat(0.5)).unwrap(),
        step: Vec2::new(1.0, 0.0),
        rows: vec![(Vec2::new(0.5, -20.0), 5)],
    });
    let s: Scenario = s;
    let report = compare_motion(&s, s.frames);
    assert_eq!(report.bodies.len(), 1);
    assert!(report.passed(), "{report:?}");
}
