//! The `swept-separate` rule: a fast body that `detect` stopped at its time of impact against
//! static geometry (`stages/sweep_normal.rs`) is explained, its record confirmed as parry's
//! first touch, and a record moved off that touch is caught.

use ricochet_geom::Vec2;
use ricochet_oracle::{FrameReport, Referee, Tolerances, rules};
use ricochet_sim::{Phase, Response, Simulation, load_scenario};

/// A ball at 120 units/s, a capsule at 1,000 and a triangle at 10,000 units/s down onto a
/// static floor 0.05 thick (the crate is resolved per axis).
const SCENE: &str = r#"
name = "fast-drops"
hz = 60
frames = 200
layers = ["thing", "floor"]
collide = [ { a = "thing", b = "floor", response = "separate" } ]

[world]
gravity = [0, -30]

[[bodies]]
name = "floor"
layer = "floor"
kind = "static"
shape = { kind = "aabb", half_extents = [20, 0.025] }
position = [0, -0.025]

[[bodies]]
name = "ball"
layer = "thing"
shape = { kind = "circle", radius = 0.3 }
position = [-5, 10.5]
velocity = [0, -120]

[[bodies]]
name = "crate"
layer = "thing"
shape = { kind = "aabb", half_extents = [0.4, 0.4] }
position = [0, 200]

[[bodies]]
name = "capsule"
layer = "thing"
shape = { kind = "capsule", a = [-0.3, 0], b = [0.3, 0], radius = 0.1 }
position = [5, 50]
velocity = [3, -1000]

[[bodies]]
name = "tri"
layer = "thing"
shape = { kind = "polygon", vertices = [[-0.3, -0.2], [0.3, -0.2], [0.0, 0.3]] }
position = [10, 50]
velocity = [0, -10000]
"#;

/// Runs the scene for frames `0..=frames`, checking each after `edit` changed its output.
fn run(frames: u64, edit: impl Fn(&mut ricochet_sim::FrameOutput)) -> Vec<FrameReport> {
    let scenario = load_scenario(SCENE, "fast.toml").unwrap_or_else(|e| panic!("{e}"));
    let mut sim = Simulation::new(&scenario);
    sim.capture_detect_poses = true;
    let mut referee = Referee::new(&scenario, Tolerances::default());
    (0..=frames)
        .map(|_| {
            let mut out = sim.step();
            edit(&mut out);
            referee.check_frame(&sim, &out)
        })
        .collect()
}

fn is_stop(c: &ricochet_sim::ContactRecord) -> bool {
    c.phase == Phase::Swept && c.response == Response::Separate
}

#[test]
fn swept_separate_stops_are_first_touches() {
    let reports = run(40, |_| {});
    for r in &reports {
        assert_eq!(r.mismatches, 0, "frame {}: {:#?}", r.frame, r.details);
    }
    let explained: u64 = reports
        .iter()
        .map(|r| r.explained.get(rules::SWEPT_SEPARATE).copied().unwrap_or(0))
        .sum();
    let confirmed: u64 = reports.iter().map(|r| r.swept_confirmed).sum();
    assert_eq!(explained, 3, "the ball, the capsule and the triangle");
    assert_eq!(confirmed, 3);
}

#[test]
fn a_stop_logged_past_the_touch_is_caught() {
    let reports = run(40, |out| {
        for c in out.contacts.iter_mut().filter(|c| is_stop(c)) {
            // Half a unit further down: through the floor's top.
            c.pose_b.position += Vec2::new(0.0, -0.5);
        }
    });
    assert!(reports.iter().map(|r| r.mismatches).sum::<u64>() >= 3);
}
