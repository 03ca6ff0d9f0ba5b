//! Slopes on a terrain chain (issue #36): a runner walks up and down a chain that climbs at
//! 30° then at 45° onto a plateau, grounded in every frame with its bottom on the chain, and
//! stays put when idle on either slope; a chain rising at 60° is a wall to it.
//!
//! The ground is the chain alone (no floor under it): the points (-30, 0), (0, 0),
//! (L, L tan 30°), (2L, L tan 30° + L tan 45°), (2L + 20, the same). Its height `h(x)` never
//! falls to the right, so the highest ground under a box centred at `x` is `h(x + HW)`.
//! Tolerance: [`TOL`] = 1e-8 on the bottom's height, as in `slopes.rs` (a push leaves at most
//! 1e-9 of overlap along the normal, over cos 45° vertically, and the snap stops within the
//! time of impact's gap): a frame of a fall (`g dt²` = 8.3e-3) is a million times more.

use ricochet_sim::{Action, Simulation, load_scenario};

const TOL: f64 = 1e-8;
const HW: f64 = 0.4;
const HH: f64 = 0.8;
/// Each slope's horizontal length.
const L: f64 = 4.0;
const RUN: f64 = 5.0;

fn tan(degrees: f64) -> f64 {
    libm::tan(degrees.to_radians())
}

/// The chain's points: flat, up at `first`°, up at `second`°, flat.
fn points(first: f64, second: f64) -> Vec<(f64, f64)> {
    let h1 = L * tan(first);
    let h2 = h1 + L * tan(second);
    vec![
        (-30.0, 0.0),
        (0.0, 0.0),
        (L, h1),
        (2.0 * L, h2),
        (2.0 * L + 20.0, h2),
    ]
}

/// The chain's height at `x` (linear between its points).
fn height(p: &[(f64, f64)], x: f64) -> f64 {
    for w in p.windows(2) {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        if x <= x1 {
            return y0 + (y1 - y0) * ((x - x0) / (x1 - x0));
        }
    }
    p[p.len() - 1].1
}

fn scene(p: &[(f64, f64)], x: f64, y: f64) -> Simulation {
    let pts: Vec<String> = p.iter().map(|(x, y)| format!("[{x:?}, {y:?}]")).collect();
    let text = format!(
        r#"
name = "chain_slopes"
hz = 60
frames = 600
layers = ["ground", "actor"]
[world]
gravity = [0, -30]
[[collide]]
a = "actor"
b = "ground"
response = "separate"
[[bodies]]
name = "hills"
layer = "ground"
kind = "static"
position = [0, 0]
shape = {{ kind = "chain", points = [{}] }}
[[bodies]]
name = "actor"
layer = "actor"
shape = {{ kind = "aabb", half_extents = [{HW:?}, {HH:?}] }}
position = [{x:?}, {y:?}]
controller = {{ kind = "runner", run_speed = {RUN:?}, jump_speed = 15 }}
"#,
        pts.join(", ")
    );
    let s = load_scenario(&text, "chain_slopes.toml").unwrap_or_else(|e| panic!("{e}"));
    Simulation::new(&s)
}

/// A runner walking with `input` from `start_x` for `frames` frames: grounded every frame,
/// its bottom on the chain under its highest corner, moving `input × RUN × dt`
/// along x each frame. Returns its last x.
fn walk(first: f64, second: f64, start_x: f64, input: f64, frames: u32) -> f64 {
    let p = points(first, second);
    let mut s = scene(&p, start_x, height(&p, start_x + HW) + HH);
    let a = s.entity_named("actor").expect("alive");
    s.step();
    s.apply(a, Action::Move(input)).unwrap();
    let mut x = start_x;
    for frame in 1..=frames {
        s.step();
        let at = s.position(a).unwrap();
        let step = at.x - x;
        x = at.x;
        assert!(
            (step - input * RUN / 60.0).abs() <= TOL,
            "frame {frame}: moved {step} along x to {x}"
        );
        let bottom = at.y - HH;
        let want = height(&p, at.x + HW);
        assert!(
            (bottom - want).abs() <= TOL,
            "frame {frame}: bottom {bottom} at x {x}, chain {want}"
        );
        assert!(s.grounded(a).unwrap(), "frame {frame}: grounded at x {x}");
    }
    x
}

#[test]
fn a_runner_walks_up_a_chain_of_30_then_45_degrees_grounded_on_it_every_frame() {
    // 3 s at 5 units/s from 3 units before the first joint: past both slopes (8 units along
    // x) onto the plateau.
    let x = walk(30.0, 45.0, -3.0, 1.0, 180);
    assert!(x > 2.0 * L + 2.0, "it reached the plateau, x = {x}");
}

#[test]
fn a_runner_walks_down_a_chain_of_45_then_30_degrees_grounded_on_it_every_frame() {
    let x = walk(30.0, 45.0, 2.0 * L + 3.0, -1.0, 180);
    assert!(x < -2.0, "it reached the flat, x = {x}");
}

#[test]
fn an_idle_runner_stays_put_on_a_chain_at_30_and_45_degrees() {
    let p = points(30.0, 45.0);
    // Halfway up each slope.
    for x in [L / 2.0, 1.5 * L] {
        let start = (x, height(&p, x + HW) + HH);
        let mut s = scene(&p, start.0, start.1);
        let a = s.entity_named("actor").expect("alive");
        for frame in 0..=600 {
            s.step();
            let at = s.position(a).unwrap();
            let moved = ((at.x - start.0).powi(2) + (at.y - start.1).powi(2)).sqrt();
            assert!(
                moved < 1e-9,
                "x {x}, frame {frame}: moved {moved} to {at:?}"
            );
            if frame > 0 {
                assert!(s.grounded(a).unwrap(), "x {x}, frame {frame}");
            }
        }
    }
}

#[test]
fn a_chain_rising_at_60_degrees_stops_a_runner() {
    // Flat, then 60° (steeper than the default max_climb_angle of 45°).
    let p = points(60.0, 60.0);
    let mut s = scene(&p, -3.0, HH);
    let a = s.entity_named("actor").expect("alive");
    s.step();
    s.apply(a, Action::Move(1.0)).unwrap();
    for _ in 0..180 {
        s.step();
    }
    let at = s.position(a).unwrap();
    // Its right edge stops at the foot of the slope (x = 0), up to the push's slop.
    assert!(
        at.x + HW <= 1e-6 && at.y - HH <= 1e-6,
        "it climbed the 60° chain: {at:?}"
    );
}
