//! The determinism gate's program, as a library: what it steps and what it prints.
//!
//! **Owns:** the gate's list of built-in scenes (bench scenes at small sizes, tile scenes) and
//! the one text format every target prints, a line per frame with the simulation's
//! [`checksum`](ricochet_sim::Simulation::checksum) and the world's
//! [`digest`](ricochet_sim::World::digest), so that `scripts/determinism-gate.sh` can compare
//! the output of x86-64, aarch64 (under qemu) and wasm32 (under Node) line by line.
//!
//! **Never:** reads the clock or formats floats: every printed value is an
//! integer in hex, so no platform's float formatting can hide or fake a difference.

use std::fmt::Write as _;

use ricochet_scenes::bench::{asteroids, platformer, rain};
use ricochet_scenes::tiles::Tiles;
use ricochet_sim::{Scenario, Simulation};

/// Frames the built-in scenes run: 5 s at 60 Hz, enough for piles to settle and bodies to
/// wrap, small enough for qemu.
pub const SCENE_FRAMES: u64 = 300;

/// The most frames a scenario file runs in the gate: the shipped ones last 300 to 600
/// frames; a longer one is cut here (said in its header line) to keep the gate's time.
pub const MAX_FILE_FRAMES: u64 = 600;

/// The built-in scenes, by name, at the gate's sizes: the three bench scenes small (every
/// shape kind, wrap-around worlds, swept bullets, tiles and walkers) and two tile scenes
/// (boxes and balls that `separate` from static tiles under gravity).
#[must_use]
pub fn builtin_scenes() -> Vec<(String, Scenario)> {
    vec![
        ("asteroids-200".into(), asteroids(200, SCENE_FRAMES)),
        (
            "platformer-400-20".into(),
            platformer(400, 20, SCENE_FRAMES),
        ),
        ("rain-300".into(), rain(300, SCENE_FRAMES)),
        ("tiles-boxes".into(), tiles_boxes()),
        ("tiles-balls".into(), tiles_balls()),
        ("ship-circling".into(), ship_circling()),
    ]
}

/// A ship that turns and thrusts for the whole run, its heading through hundreds of
/// angles: the one place trigonometry feeds the state (thrust), exercised at every frame.
/// The bench scenes' rotations only place shapes, whose contacts there push nothing.
const SHIP_CIRCLING: &str = r#"
name = "ship-circling"
hz = 60
frames = 300
layers = ["ship", "bullet"]
script = [
  { frame = 0, action = "turn", body = "ship", input = 1 },
  { frame = 0, action = "thrust", body = "ship", on = true },
  { frame = 97, action = "turn", body = "ship", input = -0.37 },
  { frame = 211, action = "turn", body = "ship", input = 0.81 },
]

[world]
bounds = { min = [-40, -25], max = [40, 25], wrap = true }

[templates.bullet]
layer = "bullet"
shape = { kind = "circle", radius = 0.2 }
mass = 0.05

[[bodies]]
name = "ship"
layer = "ship"
shape = { kind = "polygon", vertices = [[1.2, 0.0], [-0.8, 0.7], [-0.8, -0.7]] }
mass = 1
controller = { kind = "ship", thrust = 12, turn_rate = 3.3, bullet = "bullet", bullet_speed = 30, muzzle = 1.5 }
"#;

/// [`SHIP_CIRCLING`], loaded.
fn ship_circling() -> Scenario {
    ricochet_sim::load_scenario(SHIP_CIRCLING, "ship-circling.toml")
        .expect("the gate's built-in scene is valid")
}

/// A floor and two walls, and a column of boxes dropped at staggered x so they topple.
fn tiles_boxes() -> Scenario {
    let mut t = Tiles::new("box", -20.0)
        .tile("floor", [10.0, 1.0], [0.0, -1.0])
        .tile("left", [1.0, 6.0], [-9.0, 5.0])
        .tile("right", [1.0, 6.0], [9.0, 5.0]);
    for k in 0..12 {
        let x = f64::from(k % 5) * 0.37 - 0.8;
        t = t.aabb(
            &format!("box{k}"),
            [0.5, 0.4],
            [x, 1.0 + 1.1 * f64::from(k)],
        );
    }
    let mut s = t.scenario();
    s.frames = SCENE_FRAMES;
    s
}

/// Stairs of tiles, and balls rolling off them.
fn tiles_balls() -> Scenario {
    let mut t = Tiles::new("ball", -20.0).tile("floor", [12.0, 1.0], [0.0, -1.0]);
    for k in 0..4 {
        let k = f64::from(k);
        t = t.tile(&format!("step{k}"), [1.0, 0.5], [-6.0 + 2.0 * k, 4.0 - k]);
    }
    for k in 0..10 {
        let k = f64::from(k);
        t = t.ball(
            &format!("ball{k}"),
            0.3 + 0.02 * k,
            [-6.5 + 0.9 * k, 6.0 + 0.7 * k],
        );
    }
    let mut s = t.scenario();
    s.frames = SCENE_FRAMES;
    s
}

/// Steps `scenario` from frame 0 through `frames` and appends the gate's text for it to
/// `out`: a header `scene NAME frames N bodies B`, a line `FRAME CHECKSUM DIGEST` per frame
/// (both 16 hex digits), and `end NAME frames N bodies B hash DIGEST`, whose last three
/// fields are a `recordings/*.digest` file's. `each` sees the simulation after every step
/// (the log writer uses it). `threads` as `Simulation::set_threads` takes it: a build
/// without `ricochet-sim`'s `parallel` feature (wasm32) uses the calling thread whatever it
/// says, and the output is the same.
pub fn run(
    name: &str,
    scenario: &Scenario,
    (frames, threads): (u64, usize),
    out: &mut String,
    mut each: impl FnMut(&Simulation, &ricochet_sim::FrameOutput),
) {
    let mut sim = Simulation::new(scenario);
    sim.set_threads(threads);
    let bodies = sim.world().len();
    let _ = writeln!(out, "scene {name} frames {frames} bodies {bodies}");
    for _ in 0..=frames {
        let frame = sim.step();
        each(&sim, &frame);
        let _ = writeln!(
            out,
            "{} {:016x} {:016x}",
            frame.frame,
            sim.checksum(),
            sim.world().digest()
        );
    }
    let _ = writeln!(
        out,
        "end {name} frames {frames} bodies {} hash {:016x}",
        sim.world().len(),
        sim.world().digest()
    );
}
