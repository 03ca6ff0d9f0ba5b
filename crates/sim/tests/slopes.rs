//! Slopes for the `runner` and `walker` controllers (issue #36): up and down 30° and 45°
//! ramps grounded in every frame with the height following the ramp, idle on a ramp without
//! sliding, no launch off a crest, no bounce walking down, a 60° ramp a wall unless
//! `max_climb_angle` is raised, and a walker that climbs and turns at a steep wall.
//!
//! Expected heights come from the scene's own geometry: the ground's height `h(x)` is the
//! floor (0), the ramp (`x tan θ` from its toe at x = 0 to its top at x = L), then the
//! plateau (`H = L tan θ`). A box of half width `HW` resting on it has its bottom at the
//! highest ground under it, `max h` over `[x - HW, x + HW]`.
//!
//! Tolerance: [`TOL`] = 1e-8 on the bottom's height. The push leaves at most `SLOP` = 1e-9
//! of overlap along the ramp's normal (`1e-9 / cos 45°` vertically), and the snap to the
//! ground stops within the time of impact's gap (`1e-9` × the box's half-diagonal, under
//! 1e-9 here, again over `cos θ`): about 3e-9 at worst, well under 1e-8, while one frame
//! of a fall (`g dt²` = 8.3e-3) or of a launch is a million times more.

use ricochet_sim::{Action, Entity, Simulation, load_scenario};

/// The bottom's height may differ from the ground's by this (module docs).
const TOL: f64 = 1e-8;
/// The runner's half width and half height (the platformer's player).
const HW: f64 = 0.4;
const HH: f64 = 0.8;
/// The ramp's horizontal length.
const L: f64 = 4.0;

/// `tan` of `degrees`, as the test computes the scene's numbers.
fn tan(degrees: f64) -> f64 {
    libm::tan(degrees.to_radians())
}

/// A scene: a floor (top y = 0) from x = -30 to 30, a ramp of `angle` degrees rising to
/// the right from (0, 0) to (L, H), a plateau of height H from x = L to L + 10, and
/// `body` (TOML lines, on layer `actor`). `world` adds lines to `[world]`.
fn scene(angle: f64, world: &str, body: &str) -> Simulation {
    let h = L * tan(angle);
    let text = format!(
        r#"
name = "slopes"
hz = 60
frames = 600
layers = ["ground", "actor"]
[world]
gravity = [0, -30]
{world}
[[collide]]
a = "actor"
b = "ground"
response = "separate"
[[bodies]]
name = "floor"
layer = "ground"
kind = "static"
shape = {{ kind = "aabb", half_extents = [30, 0.5] }}
position = [0, -0.5]
[[bodies]]
name = "ramp"
layer = "ground"
kind = "static"
shape = {{ kind = "polygon", vertices = [[0, 0], [{L:?}, 0], [{L:?}, {h:?}]] }}
position = [0, 0]
[[bodies]]
name = "plateau"
layer = "ground"
kind = "static"
shape = {{ kind = "aabb", half_extents = [5, {hh:?}] }}
position = [{px:?}, {hh:?}]
[[bodies]]
name = "actor"
layer = "actor"
{body}
"#,
        hh = h / 2.0,
        px = L + 5.0,
    );
    let s = load_scenario(&text, "slopes.toml").unwrap_or_else(|e| panic!("{e}"));
    Simulation::new(&s)
}

/// A runner box at `(x, y)`.
fn runner(x: f64, y: f64) -> String {
    format!(
        r#"shape = {{ kind = "aabb", half_extents = [{HW:?}, {HH:?}] }}
position = [{x:?}, {y:?}]
controller = {{ kind = "runner", run_speed = 5, jump_speed = 15 }}"#
    )
}

/// The ground's height at `x` (module docs), for a ramp of `angle` degrees.
fn ground(angle: f64, x: f64) -> f64 {
    x.clamp(0.0, L) * tan(angle)
}

/// The highest ground under a box centred at `x`: the ground rises to the right, so under
/// its right edge.
fn ground_under(angle: f64, x: f64) -> f64 {
    ground(angle, x + HW)
}

fn actor(s: &Simulation) -> Entity {
    s.entity_named("actor").expect("alive")
}

/// Runs a runner with input `input` for `frames` frames; every frame it must be grounded
/// with its bottom on the ground under it, and have moved `input × run_speed × dt` along x
/// (never held back, at the crest either). Returns its final x.
fn walk(angle: f64, start_x: f64, input: f64, frames: u32) -> f64 {
    let y = ground_under(angle, start_x) + HH;
    let mut s = scene(angle, "", &runner(start_x, y));
    let a = actor(&s);
    s.step();
    s.apply(a, Action::Move(input)).unwrap();
    let mut top = f64::NEG_INFINITY;
    let mut x = start_x;
    for frame in 1..=frames {
        s.step();
        let p = s.position(a).unwrap();
        let step = p.x - x;
        x = p.x;
        assert!(
            (step - input * 5.0 / 60.0).abs() <= TOL,
            "{angle}°, frame {frame}: moved {step} along x to {x}"
        );
        let bottom = p.y - HH;
        let want = ground_under(angle, p.x);
        assert!(
            (bottom - want).abs() <= TOL,
            "{angle}°, frame {frame}: bottom {bottom} at x {}, ground {want}",
            p.x
        );
        assert!(
            s.grounded(a).unwrap(),
            "{angle}°, frame {frame}: grounded at x {}",
            p.x
        );
        top = top.max(bottom);
    }
    assert!(
        top <= L * tan(angle) + TOL,
        "{angle}°: never above the plateau"
    );
    s.position(a).unwrap().x
}

#[test]
fn a_runner_walks_up_30_and_45_degree_ramps_onto_the_plateau_without_leaving_the_ground() {
    for angle in [30.0, 45.0] {
        // From the floor, 3 units before the toe, at 5 units/s for 3 s: 15 units, over the
        // ramp (about 4 to 5.7 units along x) and onto the plateau (no launch at its crest).
        let x = walk(angle, -3.0, 1.0, 180);
        assert!(x > L + 2.0, "{angle}°: it reached the plateau, x = {x}");
    }
}

#[test]
fn a_runner_walks_down_30_and_45_degree_ramps_from_the_plateau_without_bouncing() {
    for angle in [30.0, 45.0] {
        // From the plateau, 3 units past the crest, leftwards down the ramp to the floor.
        let x = walk(angle, L + 3.0, -1.0, 180);
        assert!(x < -2.0, "{angle}°: it reached the floor, x = {x}");
    }
}

/// Steps `s` 600 frames: the actor, idle at `start`, moves less than 1e-9 and is grounded
/// from frame 1 on.
fn stays_put(angle: f64, mut s: Simulation, start: (f64, f64)) {
    let a = actor(&s);
    for frame in 0..=600 {
        s.step();
        let p = s.position(a).unwrap();
        let moved = ((p.x - start.0).powi(2) + (p.y - start.1).powi(2)).sqrt();
        assert!(
            moved < 1e-9,
            "{angle}°, frame {frame}: moved {moved} to {p:?}"
        );
        if frame > 0 {
            assert!(s.grounded(a).unwrap(), "{angle}°, frame {frame}");
        }
    }
}

#[test]
fn an_idle_runner_stays_put_on_30_and_45_degree_ramps() {
    for angle in [30.0, 45.0] {
        // Halfway up, its bottom right corner on the ramp.
        let x = 2.0;
        let start = (x, ground_under(angle, x) + HH);
        stays_put(angle, scene(angle, "", &runner(start.0, start.1)), start);
    }
}

#[test]
fn an_idle_runner_stays_put_on_a_rotated_box_ramp() {
    for angle in [30.0f64, 45.0] {
        // A static `obb` of half extents [3, 0.5] at (-15, 0) (over the floor, far from
        // the ramp) turned by `angle`: its top face is the line through
        // (-15, 0) + 0.5 (-sin, cos), of slope tan(angle). The runner's bottom right corner
        // (the highest ground under it) is on it.
        let (sin, cos) = (libm::sin(angle.to_radians()), libm::cos(angle.to_radians()));
        let (fx, fy) = (-15.0 - 0.5 * sin, 0.5 * cos);
        let x = -15.6;
        let start = (x, fy + (x + HW - fx) * tan(angle) + HH);
        let body = format!(
            r#"{}
[[bodies]]
name = "tilted"
layer = "ground"
kind = "static"
shape = {{ kind = "obb", half_extents = [3, 0.5] }}
position = [-15, 0]
angle = {:?}"#,
            runner(start.0, start.1),
            angle.to_radians()
        );
        stays_put(angle, scene(angle, "", &body), start);
    }
}

/// A runner running right at a 60° ramp from the floor for 2 s, with `world` lines; its
/// final position. Every frame it is grounded, and its bottom is on the floor or, with
/// `climbs`, on the ramp under its right edge.
fn run_at_60(world: &str, climbs: bool) -> ricochet_geom::Vec2 {
    let mut s = scene(60.0, world, &runner(-2.0, HH));
    let a = actor(&s);
    s.step();
    s.apply(a, Action::Move(1.0)).unwrap();
    for frame in 1..=120 {
        s.step();
        let p = s.position(a).unwrap();
        let want = if climbs { ground_under(60.0, p.x) } else { 0.0 };
        assert!(
            (p.y - HH - want).abs() <= TOL,
            "frame {frame}: bottom {} at x {}, ground {want}",
            p.y - HH,
            p.x
        );
        assert!(
            s.grounded(a).unwrap(),
            "frame {frame}: grounded at x {}",
            p.x
        );
    }
    s.position(a).unwrap()
}

#[test]
fn a_60_degree_ramp_is_a_wall_by_default() {
    let p = run_at_60("", false);
    // Stopped at the toe (x = 0) with its right edge, standing on the floor.
    assert!(
        (p.x + HW).abs() <= TOL,
        "stopped at the toe: right edge at {}",
        p.x + HW
    );
}

#[test]
fn a_60_degree_ramp_is_climbed_with_max_climb_angle_65() {
    let p = run_at_60("max_climb_angle = 65", true);
    // 10 units of run: up the ramp (H = 6.93) and onto the plateau.
    assert!(p.x > L + 1.0, "on the plateau: x = {}", p.x);
}

/// A walker scene: the 30° ramp and plateau of [`scene`], and a 60° wall rising right from
/// the plateau's top at x = 10 (steeper than 45°: a wall to it). The walker starts on the
/// floor at x = -3 walking right at 2 units/s.
fn walker_scene() -> Simulation {
    let h = L * tan(30.0);
    let top = h + 3.0 * tan(60.0);
    let body = format!(
        r#"shape = {{ kind = "aabb", half_extents = [{HW:?}, {HH:?}] }}
position = [-3.0, {HH:?}]
controller = {{ kind = "walker", speed = 2 }}
[[bodies]]
name = "wall"
layer = "ground"
kind = "static"
shape = {{ kind = "polygon", vertices = [[10, {h:?}], [13, {h:?}], [13, {top:?}]] }}"#
    );
    scene(30.0, "", &body)
}

#[test]
fn a_walker_climbs_a_ramp_turns_at_a_steep_wall_and_walks_back_down() {
    let mut s = walker_scene();
    let a = actor(&s);
    s.step();
    let mut turned = None;
    let mut x_max = f64::NEG_INFINITY;
    // 2 units/s: 13 units to the wall (about 6.6 s), back down to x = -3 by about 14 s.
    for frame in 1..=840 {
        s.step();
        let p = s.position(a).unwrap();
        x_max = x_max.max(p.x + HW);
        let v = s.velocity(a).unwrap();
        if turned.is_none() && v.x < 0.0 {
            turned = Some(frame);
        }
        // The highest ground under the box: the ground rises to the right up to the wall.
        let want = ground(30.0, (p.x + HW).min(10.0));
        let bottom = p.y - HH;
        assert!(
            (bottom - want).abs() <= TOL,
            "frame {frame}: bottom {bottom} at x {}, ground {want}",
            p.x
        );
        assert!(
            s.grounded(a).unwrap(),
            "frame {frame}: grounded at x {}",
            p.x
        );
    }
    let turned = turned.expect("it turned round");
    assert!(turned > 300, "at the wall, not before: frame {turned}");
    assert!(
        x_max <= 10.0 + TOL,
        "it never went up the wall: right edge reached {x_max}"
    );
    let p = s.position(a).unwrap();
    assert!(p.x < -2.0, "back on the floor: x = {}", p.x);
}

#[test]
fn max_climb_angle_out_of_range_is_a_located_error() {
    for (value, shown) in [
        ("90", "90"),
        ("-1", "-1"),
        ("nan", "NaN"),
        ("120.5", "120.5"),
    ] {
        let text = format!(
            "name = \"x\"\nhz = 60\nframes = 1\nlayers = [\"a\"]\n[world]\nmax_climb_angle = {value}\n"
        );
        let e = load_scenario(&text, "x.toml").expect_err(value);
        let msg = e.to_string();
        assert!(msg.contains("x.toml:6:"), "{value}: located: {msg}");
        assert!(
            msg.contains("world.max_climb_angle"),
            "{value}: named: {msg}"
        );
        assert!(
            msg.contains(&format!("from 0 to less than 90, got {shown}")),
            "{value}: {msg}"
        );
    }
    let text =
        "name = \"x\"\nhz = 60\nframes = 1\nlayers = [\"a\"]\n[world]\nmax_climb_angle = 30\n";
    let s = load_scenario(text, "x.toml").unwrap();
    assert_eq!(s.world.max_climb_angle, 30.0);
    let s = load_scenario(
        "name = \"x\"\nhz = 60\nframes = 1\nlayers = [\"a\"]\n",
        "x.toml",
    );
    assert_eq!(s.unwrap().world.max_climb_angle, 45.0);
}
