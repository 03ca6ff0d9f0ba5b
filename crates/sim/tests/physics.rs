//! The physics against exact answers: semi-implicit Euler's closed form, and per-axis
//! separation's landing, corner and wall cases.

use ricochet_geom::{Shape, Vec2};
use ricochet_scenes::tiles::Tiles;
use ricochet_scenes::{layers, scenario};
use ricochet_sim::{BodyDef, FrameOutput, Phase, SLOP, Simulation, WorldDef};

/// Semi-implicit Euler with constant acceleration `a`: `v_n = v0 + n a dt`,
/// `x_n = x0 + n v0 dt + n(n+1)/2 a dt²` (not the continuous parabola's `n²/2`).
fn closed_form(x0: Vec2, v0: Vec2, a: Vec2, dt: f64, n: u64) -> Vec2 {
    let n = n as f64;
    x0 + v0 * (n * dt) + a * (n * (n + 1.0) / 2.0 * dt * dt)
}

/// Rounding bound for n steps: each step rounds `v += a dt` and `x += v dt` once per
/// operation, so the error grows at most by a few ulps of the largest magnitude per step.
fn bound(x0: Vec2, v0: Vec2, a: Vec2, dt: f64, n: u64) -> f64 {
    let nf = n as f64;
    let scale = x0.abs().max_element()
        + nf * v0.abs().max_element() * dt
        + nf * nf * a.abs().max_element() * dt * dt;
    4.0 * nf * f64::EPSILON * scale
}

/// Steps frame 0, then `frames` frames: body 0 stays within [`bound`] of [`closed_form`]
/// from `(x0, v0, a, dt)`. `also` sees the simulation, the frame and the position.
fn follows_closed_form(
    s: &mut Simulation,
    (x0, v0, a, dt): (Vec2, Vec2, Vec2, f64),
    frames: u64,
    mut also: impl FnMut(&Simulation, u64, Vec2),
) {
    s.step(); // frame 0: the initial state
    for n in 1..=frames {
        s.step();
        let x = s.world().position[0];
        let want = closed_form(x0, v0, a, dt, n);
        let tol = bound(x0, v0, a, dt, n);
        assert!(
            (x - want).abs().max_element() <= tol,
            "frame {n}: {x} vs {want} (bound {tol})"
        );
        also(s, n, x);
    }
}

#[test]
fn a_projectile_follows_the_semi_implicit_euler_closed_form() {
    let ball = BodyDef {
        shape: Shape::circle(0.1).unwrap(),
        mass: 3.0,
        position: Vec2::new(1.0, 2.0),
        velocity: Vec2::new(3.0, 10.0),
        ..BodyDef::default()
    };
    let world = WorldDef {
        dt: 0.01,
        gravity: Vec2::new(0.0, -9.81),
        layers: layers(&["ball"], &[]),
        ..WorldDef::default()
    };
    let mut s = Simulation::new(&scenario("projectile", world, vec![ball], 600));
    let (x0, v0, a, dt) = (
        Vec2::new(1.0, 2.0),
        Vec2::new(3.0, 10.0),
        Vec2::new(0.0, -9.81),
        0.01,
    );
    follows_closed_form(&mut s, (x0, v0, a, dt), 500, |_, n, x| {
        // And it is not the continuous parabola: that differs by n a dt²/2.
        let parabola = x0 + v0 * (n as f64 * dt) + a * 0.5 * (n as f64 * dt).powi(2);
        assert!((x - parabola).y.abs() > 0.4 * n as f64 * 9.81 * dt * dt);
    });
}

#[test]
fn a_thrusting_ship_follows_the_closed_form() {
    let ship = ricochet_sim::load_scenario(
        r#"
        dt = 0.02
        layers = ["ship", "bullet"]
        [templates.bullet]
        layer = "bullet"
        shape = { kind = "circle", radius = 0.1 }
        [[bodies]]
        name = "ship"
        layer = "ship"
        shape = { kind = "polygon", vertices = [[1, 0], [-1, 0.6], [-1, -0.6]] }
        mass = 2
        angle = 0.5
        velocity = [1, -1]
        controller = { kind = "ship", thrust = 7, turn_rate = 3, bullet = "bullet", bullet_speed = 20 }
        [[script]]
        frame = 0
        action = "thrust"
        body = "ship"
    "#,
        "ship.toml",
    );
    let mut s = Simulation::new(&ship.unwrap_or_else(|e| panic!("{e}")));
    let heading = Vec2::new(libm::cos(0.5), libm::sin(0.5));
    let (x0, v0, a, dt) = (Vec2::ZERO, Vec2::new(1.0, -1.0), heading * 3.5, 0.02);
    follows_closed_form(&mut s, (x0, v0, a, dt), 300, |s, _, _| {
        assert_eq!(s.world().angle[0], 0.5, "no turn input, no turning");
    });
}

/// A floor (top at y = 0) under gravity `[0, -20]`; boxes `separate` from it.
fn floor() -> Tiles {
    Tiles::new("box", -20.0).tile("floor", [10.0, 1.0], [0.0, -1.0])
}

/// Overlap of two boxes given as (centre, half extents), on both axes.
fn box_overlap(c1: Vec2, h1: Vec2, c2: Vec2, h2: Vec2) -> Vec2 {
    (h1 + h2) - (c2 - c1).abs()
}

#[test]
fn a_falling_box_lands_flush_and_grounded() {
    let mut s = Simulation::new(&floor().aabb("box", [0.5, 0.5], [0.3, 3.0]).scenario());
    let mut landed_at = None;
    for frame in 0..=240u64 {
        let out = s.step();
        let o = box_overlap(
            Vec2::new(0.0, -1.0),
            Vec2::new(10.0, 1.0),
            s.world().position[1],
            Vec2::splat(0.5),
        );
        assert!(
            o.y <= SLOP,
            "frame {frame}: box sunk {} into the floor",
            o.y
        );
        if s.world().grounded(1) && landed_at.is_none() {
            landed_at = Some(frame);
            assert!(
                out.contacts.iter().all(|c| c.phase == Phase::Y),
                "{:?}",
                out.contacts
            );
        }
    }
    // Free fall from 2.5 above the floor at 20 units/s² takes 0.5 s: about frame 30.
    let landed = landed_at.expect("the box lands");
    assert!((29..=32).contains(&landed), "landed at frame {landed}");
    assert!(s.world().grounded(1));
    assert!(
        (s.world().position[1].y - 0.5).abs() <= SLOP,
        "{}",
        s.world().position[1]
    );
    assert_eq!(
        s.world().position[1].x,
        0.3,
        "a vertical landing never moves x"
    );
}

#[test]
fn a_corner_hit_resolves_along_one_axis_only() {
    // The box reaches the corner diagonally: after the x move it is still above the block,
    // after the y move it overlaps by 0.08 vertically and 0.15 horizontally.
    let mut s = Simulation::new(
        &Tiles::new("box", 0.0)
            .tile("body", [1.0, 1.0], [0.0, 0.0])
            .aabb("body", [0.5, 0.5], [-1.45, 1.52])
            .with(|b| b.velocity = Vec2::new(6.0, -6.0))
            .scenario(),
    );
    s.step();
    let out: FrameOutput = s.step();
    assert_eq!(out.contacts.len(), 1, "{:?}", out.contacts);
    let c = &out.contacts[0];
    assert_eq!(c.phase, Phase::Y);
    assert_eq!(c.resolved.x, 0.0, "nothing along x");
    assert!((c.resolved.y - 0.08).abs() < 1e-12, "{:?}", c.resolved);
    assert_eq!(
        s.world().velocity(1),
        Vec2::new(6.0, 0.0),
        "x velocity kept, y stopped"
    );
    assert!(s.world().grounded(1));
}

#[test]
fn a_body_running_into_a_wall_stops_flush() {
    let mut s = Simulation::new(
        &Tiles::new("box", 0.0)
            .tile("wall", [0.5, 5.0], [5.5, 0.0])
            .aabb("box", [0.5, 0.5], [0.0, 0.0])
            .with(|b| b.velocity = Vec2::new(10.0, 0.0))
            .scenario(),
    );
    let mut hits = 0;
    for _ in 0..=60 {
        let out = s.step();
        hits += out.contacts.len();
        for c in &out.contacts {
            assert_eq!(c.phase, Phase::X);
            assert_eq!(c.resolved.y, 0.0);
        }
    }
    assert_eq!(hits, 1, "one hit, then it rests flush");
    assert!(
        (s.world().position[1].x - 4.5).abs() <= SLOP,
        "{}",
        s.world().position[1]
    );
    assert_eq!(s.world().velocity(1).x, 0.0);
}
