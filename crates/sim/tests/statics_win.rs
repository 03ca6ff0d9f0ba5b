//! Statics win (issue #20, "pushed through static floors"): a push from another dynamic body
//! never moves a body into or through a static body.
//!
//! The scenes pile bodies at one point just above a static floor whose top is `y = 0`, all
//! `separate`ing from each other and from the floor. The expected values are geometry: a
//! body never overlaps the floor by more than [`SLOP`] (the contact depth, exact for these
//! shapes), so a circle's centre never goes below `radius - SLOP`. Before the fix, pairs
//! later in the pass pushed bodies back into (and through) the floor: with 20 circles one
//! ended at `y = -0.05`, with the floor last in id order at `y = -26`.
//! The pile of 3,000 is in the stress suite (`tests/stress.rs`).

use ricochet_geom::contact;
use ricochet_sim::{BodyKind, SLOP, Simulation, load_scenario};

/// Rounding on top of [`SLOP`] in these scenes (coordinates of a few units).
const ROUNDING: f64 = 1e-12;

/// A scene of `n` bodies of `shape`, all at `[0, y]`, above a static floor 1 unit thick
/// per `thickness` (top at `y = 0`), listed before the bodies or after them (the pass meets
/// pairs in id order, so both orders are tried).
fn pile(n: usize, shape: &str, y: f64, thickness: f64, floor_first: bool) -> String {
    let mut s = String::from(
        r#"
hz = 60
layers = ["floor", "ball"]
[world]
gravity = [0, -10]
[[collide]]
a = "ball"
b = "floor"
response = "separate"
[[collide]]
a = "ball"
b = "ball"
response = "separate"
"#,
    );
    let floor = format!(
        "[[bodies]]\nname = \"floor\"\nlayer = \"floor\"\nkind = \"static\"\n\
         shape = {{ kind = \"aabb\", half_extents = [100, {}] }}\nposition = [0, {}]\n",
        thickness / 2.0,
        -thickness / 2.0
    );
    if floor_first {
        s.push_str(&floor);
    }
    for k in 0..n {
        s.push_str(&format!(
            "[[bodies]]\nname = \"b{k}\"\nlayer = \"ball\"\nshape = {shape}\nposition = [0, {y}]\n"
        ));
    }
    if !floor_first {
        s.push_str(&floor);
    }
    s
}

const CIRCLE: &str = r#"{ kind = "circle", radius = 0.5 }"#;

/// Steps `text` for frames 0 to `frames` and asserts after every frame that no dynamic body
/// overlaps the floor by more than `SLOP` and none is below its top. Returns the highest
/// body's centre at the end (how far the pile spread, so a test is never vacuous).
fn assert_above_floor(text: &str, frames: u64) -> f64 {
    let mut sim = Simulation::new(&load_scenario(text, "pile.toml").unwrap());
    let mut highest = f64::NEG_INFINITY;
    for frame in 0..=frames {
        sim.step();
        let w = sim.world();
        let f = w.find("floor").unwrap();
        highest = f64::NEG_INFINITY;
        for i in 0..w.len() {
            if w.kind[i] != BodyKind::Dynamic {
                continue;
            }
            let c = contact(w.shape(i), &w.pose(i), w.shape(f), &w.pose(f));
            let bottom = w.shape(i).bounds(&w.pose(i)).min.y;
            assert!(
                c.depth <= SLOP + ROUNDING && bottom >= -SLOP - ROUNDING,
                "frame {frame}: body {i} at {} overlaps the floor by {} (its bottom at {bottom})",
                w.position[i],
                c.depth
            );
            highest = highest.max(w.position[i].y);
        }
    }
    highest
}

#[test]
fn twenty_circles_started_at_one_point_never_sink_into_the_floor() {
    for floor_first in [true, false] {
        let highest = assert_above_floor(&pile(20, CIRCLE, 0.6, 2.0, floor_first), 120);
        // They pushed each other apart, some onto others (not all flat on the floor).
        assert!(highest > 1.0, "the pile spread upwards too: {highest}");
    }
}

#[test]
fn twenty_circles_never_pass_through_a_thin_floor() {
    // A floor thinner than one push (pushes of up to half a circle's width): a push that
    // is not clipped along its path goes right through.
    for floor_first in [true, false] {
        assert_above_floor(&pile(20, CIRCLE, 0.6, 0.05, floor_first), 120);
    }
}

#[test]
fn piles_of_every_shape_pushed_along_the_normal_stay_above_the_floor() {
    let shapes = [
        r#"{ kind = "polygon", vertices = [[-0.5, -0.5], [0.5, -0.5], [0, 0.5]] }"#,
        r#"{ kind = "capsule", a = [-0.3, 0], b = [0.3, 0], radius = 0.2 }"#,
        r#"{ kind = "obb", half_extents = [0.5, 0.25], angle = 0.5 }"#,
    ];
    for shape in shapes {
        for floor_first in [true, false] {
            assert_above_floor(&pile(20, shape, 0.6, 2.0, floor_first), 120);
        }
    }
}

#[test]
fn a_mixed_pile_of_boxes_and_circles_stays_above_the_floor() {
    // Boxes resolve per axis against the floor and each other, and along the normal against
    // the circles: a circle's push must not move a box into the floor either.
    let shapes = [
        r#"{ kind = "aabb", half_extents = [0.5, 2] }"#,
        r#"{ kind = "aabb", half_extents = [0.2, 0.2] }"#,
        CIRCLE,
        r#"{ kind = "aabb", half_extents = [2, 0.3] }"#,
    ];
    for floor_first in [true, false] {
        let mut s = pile(0, CIRCLE, 0.0, 2.0, floor_first);
        for k in 0..40 {
            s.push_str(&format!(
                "[[bodies]]\nname = \"m{k}\"\nlayer = \"ball\"\nshape = {}\nposition = [0, 2.1]\n",
                shapes[k % shapes.len()]
            ));
        }
        assert_above_floor(&s, 120);
    }
}

#[test]
fn a_circle_held_by_the_floor_passes_the_whole_push_to_the_other() {
    // No gravity: `a` rests flush on the floor, `b` overlaps it from above by 0.4. The floor
    // stops `a`, so `b` takes the whole push (infinite mass, as Box2D and rapier treat a
    // static body): `a` stays at 0.5 and `b` ends at 0.5 + 1 = 1.5, flush on `a`.
    let mut s = pile(0, CIRCLE, 0.0, 2.0, true).replace("gravity = [0, -10]", "gravity = [0, 0]");
    s.push_str(&format!(
        "[[bodies]]\nname = \"a\"\nlayer = \"ball\"\nshape = {CIRCLE}\nposition = [0, 0.5]\n\
         [[bodies]]\nname = \"b\"\nlayer = \"ball\"\nshape = {CIRCLE}\nposition = [0, 1.1]\n"
    ));
    let mut sim = Simulation::new(&load_scenario(&s, "pair.toml").unwrap());
    sim.step();
    let w = sim.world();
    let (a, b) = (w.find("a").unwrap(), w.find("b").unwrap());
    assert_eq!(w.position[a].x, 0.0);
    assert_eq!(w.position[b].x, 0.0);
    assert_eq!(w.position[a].y, 0.5, "the floor holds a");
    assert!(
        (w.position[b].y - 1.5).abs() <= ROUNDING,
        "b takes the whole depth: {}",
        w.position[b].y
    );
}

#[test]
fn a_push_between_two_circles_far_from_any_static_body_is_half_each() {
    // The unclipped push is what it always was: half the depth each, bit for bit.
    let mut s = pile(0, CIRCLE, 0.0, 2.0, true).replace("gravity = [0, -10]", "gravity = [0, 0]");
    s.push_str(&format!(
        "[[bodies]]\nname = \"a\"\nlayer = \"ball\"\nshape = {CIRCLE}\nposition = [0, 10]\n\
         [[bodies]]\nname = \"b\"\nlayer = \"ball\"\nshape = {CIRCLE}\nposition = [0, 10.5]\n"
    ));
    let mut sim = Simulation::new(&load_scenario(&s, "pair.toml").unwrap());
    sim.step();
    let w = sim.world();
    let (a, b) = (w.find("a").unwrap(), w.find("b").unwrap());
    // Depth 0.5, normal +y: a down by 0.25, b up by 0.25 (exact in binary).
    assert_eq!(w.position[a].y, 9.75);
    assert_eq!(w.position[b].y, 10.75);
}

#[test]
fn piles_of_boxes_of_random_sizes_stay_above_the_floor() {
    // Boxes resolve per axis: a box pushed out of a settled box by the smaller overlap must
    // not be pushed into the floor (it goes out of the other side, or stops on the floor).
    // Before the fix a third of these piles had a box inside the floor after frame 1.
    let mut seed: u64 = 12345;
    let mut uniform = || {
        // xorshift64: a fixed sequence, so the piles are the same every run.
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    for trial in 0..200 {
        let mut s = pile(0, CIRCLE, 0.0, 2.0, trial % 2 == 0);
        let n = 2 + (uniform() * 10.0) as usize;
        for k in 0..n {
            let (hx, hy) = (0.1 + uniform() * 2.0, 0.1 + uniform() * 2.0);
            let (x, y) = (uniform(), hy + 0.01 + uniform());
            s.push_str(&format!(
                "[[bodies]]\nname = \"m{k}\"\nlayer = \"ball\"\n\
                 shape = {{ kind = \"aabb\", half_extents = [{hx}, {hy}] }}\nposition = [{x}, {y}]\n"
            ));
        }
        assert_above_floor(&s, 60);
    }
}
