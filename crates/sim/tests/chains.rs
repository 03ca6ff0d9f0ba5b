//! Terrain chains (issue #36): bodies of every shape slide along a chain across 1,000
//! joints without catching on one, while the same segments as separate bodies do catch
//! (the "ghost collision" a chain exists to prevent); and a chain is static only.
//!
//! Expected values come from the scene's own numbers: with no friction, a body sliding on
//! flat ground keeps its horizontal speed exactly and never moves up or down, so after `n`
//! steps its x is `x0 + vx dt` applied `n` times (the integrator's `f64` operations), its
//! height is where it started, and its vertical speed is 0. Tolerance `1e-9` on speeds:
//! a contact normal is computed in the pair's frame, so a circle's or capsule's normal on a
//! flat segment can be off vertical by rounding (relative `1e-16`), which leaves about
//! `1e-15` of vertical speed; a catch changes a speed by the order of the speed itself.

use ricochet_sim::{Entity, Simulation, load_scenario};

/// Seconds per step (`hz = 60`).
const DT: f64 = 1.0 / 60.0;
/// Horizontal speed, units/s (leftwards): about 0.4 units a step, not a simple fraction
/// of a segment, so the body's edges land at all sorts of offsets from the joints.
const VX: f64 = -23.712_345;
/// How far a speed may be off from the exact one (module docs).
const SPEED_TOL: f64 = 1e-9;

/// The joints' x: 1,001 collinear segments (1,000 inner joints) from x = 0 leftwards,
/// of `lengths` repeated, and a last one 5 long that the body ends on.
fn joints(lengths: &[f64]) -> Vec<f64> {
    let mut xs = vec![0.0];
    for k in 0..1001 {
        let last = xs[xs.len() - 1];
        let length = if k == 1000 {
            5.0
        } else {
            lengths[k % lengths.len()]
        };
        xs.push(last - length);
    }
    xs
}

/// The ground: one chain through `xs` at y = 0, or (`separate`) one two-point chain per
/// segment, leftmost first: the segment a body moving left enters is met first in the
/// pass (pairs go in id order), before the one it stands on pushes it up.
fn ground(xs: &[f64], separate: bool) -> String {
    let point = |x: f64| format!("[{x:?}, 0.0]");
    if !separate {
        let points: Vec<String> = xs.iter().map(|x| point(*x)).collect();
        return format!(
            "[[bodies]]\nname = \"ground\"\nlayer = \"ground\"\nkind = \"static\"\n\
             shape = {{ kind = \"chain\", points = [{}] }}\n",
            points.join(", ")
        );
    }
    xs.windows(2)
        .rev()
        .enumerate()
        .map(|(k, w)| {
            format!(
                "[[bodies]]\nname = \"segment{k}\"\nlayer = \"ground\"\nkind = \"static\"\n\
                 shape = {{ kind = \"chain\", points = [{}, {}] }}\n",
                point(w[0]),
                point(w[1])
            )
        })
        .collect()
}

/// A scene with gravity, the ground, and a body of `shape` resting on it (its lowest
/// point at y = 0 when its origin is at `rest` high), about to slide leftwards at `VX`.
fn scene(xs: &[f64], separate: bool, shape: &str, rest: f64) -> Simulation {
    let text = format!(
        r#"
name = "chains"
hz = 60
frames = 100000
layers = ["body", "ground"]
[world]
gravity = [0, -10]
[[collide]]
a = "body"
b = "ground"
response = "separate"
{ground}
[[bodies]]
name = "body"
layer = "body"
shape = {shape}
position = [-0.6, {rest:?}]
velocity = [{VX:?}, 0]
"#,
        ground = ground(xs, separate)
    );
    let s = load_scenario(&text, "chains.toml").expect("the scene loads");
    Simulation::new(&s)
}

/// The shapes that slide, each with the height of its origin when resting on y = 0.
const SHAPES: [(&str, &str, f64); 5] = [
    (
        "box",
        r#"{ kind = "aabb", half_extents = [0.5, 0.5] }"#,
        0.5,
    ),
    ("circle", r#"{ kind = "circle", radius = 0.5 }"#, 0.5),
    (
        "capsule",
        r#"{ kind = "capsule", a = [-0.5, 0], b = [0.5, 0], radius = 0.25 }"#,
        0.25,
    ),
    ("obb", r#"{ kind = "obb", half_extents = [0.5, 0.5] }"#, 0.5),
    (
        "polygon",
        r#"{ kind = "polygon", vertices = [[-0.5, 0], [0.5, 0], [0.3, 0.6], [-0.3, 0.6]] }"#,
        0.0,
    ),
];

/// Slides the body of `s` until its whole width has passed the last joint; `Err` at the
/// first step its velocity or height is not the free slide's.
fn slide(s: &mut Simulation, rest: f64, last_joint: f64) -> Result<usize, String> {
    let b: Entity = s.entity_named("body").expect("alive");
    let mut x = -0.6;
    // Frame 0 is the scene as loaded.
    s.step();
    for step in 1.. {
        s.step();
        x += VX * DT;
        let (p, v) = (s.position(b).unwrap(), s.velocity(b).unwrap());
        let what = format!("step {step}: x {}, position {p:?}, velocity {v:?}", x);
        if (v.x - VX).abs() > SPEED_TOL || v.y.abs() > SPEED_TOL {
            return Err(format!("caught: {what}"));
        }
        // The speed's rounding (module docs) adds up over the run: far below a catch.
        if (p.x - x).abs() > 1e-6 || (p.y - rest).abs() > 1e-9 {
            return Err(format!("off the free slide: {what}"));
        }
        if x < last_joint - 1.0 {
            return Ok(step);
        }
    }
    unreachable!()
}

#[test]
fn every_shape_slides_across_1000_joints_of_a_flat_chain() {
    let xs = joints(&[1.0]);
    for (name, shape, rest) in SHAPES {
        let mut s = scene(&xs, false, shape, rest);
        let steps = slide(&mut s, rest, xs[xs.len() - 2]).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(steps > 2400, "{name}: crossed every joint ({steps} steps)");
    }
}

#[test]
fn every_shape_slides_across_1000_joints_of_uneven_collinear_segments() {
    let xs = joints(&[0.3, 1.7, 0.05, 1.0, 0.011, 2.5]);
    for (name, shape, rest) in SHAPES {
        let mut s = scene(&xs, false, shape, rest);
        slide(&mut s, rest, xs[xs.len() - 2]).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
}

#[test]
fn the_same_segments_as_separate_bodies_catch() {
    // The ghost collision is real without chains: each segment a body of its own, the box
    // and the circle catch on a joint (lose speed or gain vertical speed) before the end.
    let xs = joints(&[1.0]);
    for (name, shape, rest) in [SHAPES[0], SHAPES[1]] {
        let mut s = scene(&xs, true, shape, rest);
        let caught = slide(&mut s, rest, xs[xs.len() - 2]);
        assert!(
            caught.is_err(),
            "{name}: slid {caught:?} steps without catching"
        );
    }
}

#[test]
fn a_chain_is_static_terrain_only() {
    let text = r#"
name = "moving chain"
hz = 60
frames = 1
layers = ["a"]
[[bodies]]
layer = "a"
shape = { kind = "chain", points = [[0, 0], [1, 0]] }
position = [0, 0]
"#;
    let e = load_scenario(text, "moving.toml").unwrap_err().to_string();
    assert!(e.contains("bodies[0].kind") && e.contains("static"), "{e}");
}

#[test]
fn bad_chains_are_located_errors() {
    let scene = |shape: &str| {
        format!(
            "name = \"bad\"\nhz = 60\nframes = 1\nlayers = [\"a\"]\n[[bodies]]\nlayer = \"a\"\n\
             kind = \"static\"\nposition = [0, 0]\nshape = {shape}\n"
        )
    };
    let many: Vec<String> = (0..1026).map(|k| format!("[{k}, 0]")).collect();
    for (shape, want) in [
        (
            r#"{ kind = "chain", points = [[0, 0]] }"#.to_owned(),
            "points: a chain needs 2 to 1025 points, got 1",
        ),
        (
            r#"{ kind = "chain", points = [[0, 0], [1, 0], [1, 0]] }"#.to_owned(),
            "points[2]: repeats the previous point",
        ),
        (
            r#"{ kind = "chain", points = [[0, 0], [1, nan]] }"#.to_owned(),
            "points[1][1]: must be a finite number",
        ),
        (
            format!(r#"{{ kind = "chain", points = [{}] }}"#, many.join(", ")),
            "got 1026",
        ),
    ] {
        let e = load_scenario(&scene(&shape), "bad.toml")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("bodies[0].shape") && e.contains(want),
            "{shape:.60}: {e}"
        );
    }
}
