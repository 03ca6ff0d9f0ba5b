//! One-way platforms (issue #36): a body jumps up through one, lands on it, rides one that
//! moves, and drops through with a `drop` input; and no body falling onto one from above,
//! at any speed, ends below its top.
//!
//! Expected frames are free flight replayed with the `f64` operations of the stages
//! (semi-implicit Euler: `v += g dt`, then `y += v dt`), and the platform's top from the
//! scene's own numbers: a body that lands has its bottom exactly on the top (a box on its
//! origin is put at `top + half height`).

use proptest::prelude::*;
use ricochet_geom::Vec2;
use ricochet_sim::{Action, Entity, GameEvent, SLOP, ScriptInput, Simulation, load_scenario};

/// Gravity, units/s².
const G: f64 = -10.0;
/// Seconds per step (`hz = 60`).
const DT: f64 = 1.0 / 60.0;
/// The platform's top: a box of half height 0.25 centred at y = 0.
const TOP: f64 = 0.25;

/// A scene: a `body` layer that meets the `platform` layer one way; a platform of half
/// extents [2, 0.25] at the origin (`platform_extra` adds to it), and `body` (TOML lines).
fn scene(platform_extra: &str, body: &str, script: &str) -> Simulation {
    let text = format!(
        r#"
name = "one_way"
hz = 60
frames = 600
layers = ["body", "platform"]
[world]
gravity = [0, {G}]
[[collide]]
a = "body"
b = "platform"
response = "one_way"
[[bodies]]
name = "platform"
layer = "platform"
shape = {{ kind = "aabb", half_extents = [2, 0.25] }}
position = [0, 0]
{platform_extra}
[[bodies]]
name = "body"
layer = "body"
{body}
{script}
"#
    );
    // A static platform unless `platform_extra` gives its kind.
    let text = if platform_extra.contains("kind") {
        text
    } else {
        text.replace("position = [0, 0]", "position = [0, 0]\nkind = \"static\"")
    };
    let s = load_scenario(&text, "one_way.toml").expect("the scene loads");
    Simulation::new(&s)
}

fn entity(s: &Simulation, name: &str) -> Entity {
    s.entity_named(name).expect("alive")
}

/// Free flight from `(y, vy)` for one step.
fn fly(y: f64, vy: f64) -> (f64, f64) {
    let v = vy + G * DT;
    (y + v * DT, v)
}

#[test]
fn a_body_jumps_up_through_and_lands_on_top() {
    // A box of half size 0.5 starting below the platform (its top at -1.5), moving up at
    // 10 units/s: it rises through the platform untouched (apex near y = 3), then falls
    // back and lands with its bottom on the top.
    let mut s = scene(
        "",
        r#"shape = { kind = "aabb", half_extents = [0.5, 0.5] }
position = [0.3, -2]
velocity = [0, 10]"#,
        "",
    );
    let b = entity(&s, "body");
    s.step();
    let (mut y, mut v) = (-2.0, 10.0);
    let mut passed_inside = 0;
    let mut landed = None;
    for frame in 1..200 {
        let out = s.step();
        let (ny, nv) = fly(y, v);
        if landed.is_none() && nv <= 0.0 && ny - 0.5 <= TOP + SLOP {
            // The first frame its bottom, falling, reaches the top (within SLOP): it lands.
            landed = Some(frame);
            assert_eq!(s.position(b).unwrap().y, TOP + 0.5, "frame {frame}");
            assert_eq!(s.velocity(b).unwrap().y, 0.0, "frame {frame}");
            assert!(s.grounded(b).unwrap(), "frame {frame}");
            assert_eq!(
                out.contacts.len(),
                1,
                "frame {frame}: the landing's contact"
            );
            (y, v) = (TOP + 0.5, 0.0);
            continue;
        }
        if landed.is_some() {
            assert_eq!(
                s.position(b).unwrap().y,
                TOP + 0.5,
                "frame {frame}: resting"
            );
            assert!(s.grounded(b).unwrap());
            continue;
        }
        (y, v) = (ny, nv);
        assert_eq!(s.position(b).unwrap().y, y, "frame {frame}: free flight");
        assert!(
            out.contacts.is_empty(),
            "frame {frame}: no contact going up"
        );
        assert!(!s.grounded(b).unwrap());
        if y - 0.5 < TOP && y + 0.5 > -TOP {
            passed_inside += 1;
        }
    }
    assert!(
        passed_inside >= 3,
        "it overlapped the platform on the way up"
    );
    assert!(landed.is_some(), "it came back down and landed");
}

#[test]
fn a_falling_body_of_each_shape_lands_with_its_bottom_on_the_top() {
    for (shape, bottom) in [
        (r#"{ kind = "aabb", half_extents = [0.5, 0.5] }"#, 0.5),
        (r#"{ kind = "circle", radius = 0.4 }"#, 0.4),
        (
            r#"{ kind = "capsule", a = [0, -0.6], b = [0, 0.6], radius = 0.2 }"#,
            0.8,
        ),
    ] {
        let mut s = scene("", &format!("shape = {shape}\nposition = [-1.2, 3]"), "");
        let b = entity(&s, "body");
        s.step();
        let (mut y, mut v) = (3.0, 0.0);
        for frame in 1..120 {
            s.step();
            (y, v) = fly(y, v);
            let at = s.position(b).unwrap().y;
            if y - bottom < TOP {
                assert!(
                    (at - bottom - TOP).abs() <= SLOP,
                    "{shape} frame {frame}: bottom {} on the top",
                    at - bottom
                );
                assert!(s.grounded(b).unwrap(), "{shape} frame {frame}");
                assert_eq!(s.velocity(b).unwrap().y, 0.0);
                (y, v) = (at, 0.0);
            } else {
                assert_eq!(at, y, "{shape} frame {frame}: still falling");
            }
        }
        assert!((s.position(b).unwrap().y - bottom - TOP).abs() <= SLOP);
    }
}

#[test]
fn a_body_rides_a_moving_one_way_platform() {
    // The platform is kinematic, moving right at 1 and up at 0.5 units/s; the box starts
    // on it, 0.3 right of its centre. Frame 1 lands it (nothing carried it yet, so the
    // platform gained 1/60 along x); from then on it keeps its place on the platform.
    let mut s = scene(
        "velocity = [1, 0.5]\nkind = \"kinematic\"",
        r#"shape = { kind = "aabb", half_extents = [0.5, 0.5] }
position = [0.3, 0.75]"#,
        "",
    );
    let (b, p) = (entity(&s, "body"), entity(&s, "platform"));
    s.step();
    s.step();
    let offset = s.position(b).unwrap().x - s.position(p).unwrap().x;
    assert!((offset - (0.3 - DT)).abs() < 1e-12, "offset {offset}");
    for frame in 2..240 {
        s.step();
        let (pb, pp) = (s.position(b).unwrap(), s.position(p).unwrap());
        assert!(
            (pb.x - pp.x - offset).abs() < 1e-9,
            "frame {frame}: carried along x"
        );
        assert!(
            ((pb.y - 0.5) - (pp.y + TOP)).abs() <= SLOP,
            "frame {frame}: bottom on the rising top"
        );
        assert!(s.grounded(b).unwrap(), "frame {frame}");
        assert_eq!(s.carrier(b).unwrap(), Some(p), "frame {frame}");
    }
    // 240 frames, 239 of them moving (frame 0 moves nothing), at 0.5 units/s.
    assert!((s.position(p).unwrap().y - 0.5 * 239.0 / 60.0).abs() < 1e-9);
}

#[test]
fn a_drop_input_lets_a_grounded_body_fall_through() {
    let mut s = scene(
        "",
        r#"shape = { kind = "aabb", half_extents = [0.5, 0.5] }
position = [0.3, 0.75]"#,
        r#"
[[script]]
frame = 0
action = "drop"
body = "body"
[[script]]
frame = 30
action = "drop"
body = "body""#,
    );
    let b = entity(&s, "body");
    // Frame 0: not grounded yet (nothing has held it up): the drop is ignored.
    let out = s.step();
    assert!(out.events.iter().any(|e| matches!(
        e,
        GameEvent::Input {
            input: ScriptInput::Drop(false),
            ..
        }
    )));
    for _ in 1..30 {
        s.step();
        assert_eq!(s.position(b).unwrap().y, 0.75, "resting on the platform");
    }
    assert!(s.grounded(b).unwrap());
    // Frame 30: the drop; from then on it falls freely from rest at y = 0.75.
    let out = s.step();
    assert!(out.events.iter().any(|e| matches!(
        e,
        GameEvent::Input {
            input: ScriptInput::Drop(true),
            ..
        }
    )));
    let (mut y, mut v) = fly(0.75, 0.0);
    assert_eq!(s.position(b).unwrap().y, y, "frame 30");
    assert!(s.inputs(b).unwrap().drop, "dropping while inside");
    for frame in 31..120 {
        s.step();
        (y, v) = fly(y, v);
        assert_eq!(
            s.position(b).unwrap().y,
            y,
            "frame {frame}: falling through"
        );
    }
    assert!(y + 0.5 < -TOP, "it ended below the platform");
    assert!(
        !s.inputs(b).unwrap().drop,
        "clear of the platform: no longer dropping"
    );
}

#[test]
fn a_drop_sent_by_the_game_works_like_the_scripts() {
    let mut s = scene(
        "",
        r#"shape = { kind = "circle", radius = 0.5 }
position = [0, 0.75]"#,
        "",
    );
    let b = entity(&s, "body");
    for _ in 0..10 {
        s.step();
    }
    assert!((s.position(b).unwrap().y - 0.75).abs() <= SLOP);
    s.apply(b, Action::Drop).unwrap();
    for _ in 0..60 {
        s.step();
    }
    assert!(s.position(b).unwrap().y + 0.5 < -TOP, "fell through");
}

/// Dropping through is state a step reads: a snapshot taken mid-drop restores it, and the
/// restored run falls through as the original does (without it, it would land again).
#[test]
fn a_snapshot_taken_while_dropping_keeps_the_drop() {
    let body = r#"shape = { kind = "aabb", half_extents = [0.5, 0.5] }
position = [0.3, 0.75]"#;
    let mut s = scene("", body, "");
    let b = entity(&s, "body");
    for _ in 0..10 {
        s.step();
    }
    s.apply(b, Action::Drop).unwrap();
    s.step();
    assert!(s.inputs(b).unwrap().drop);
    let snap = s.snapshot();
    let mut copy = scene("", body, "");
    copy.restore(&snap).unwrap();
    assert!(copy.inputs(b).unwrap().drop, "restored dropping");
    assert_eq!(copy.checksum(), s.checksum());
    for _ in 0..60 {
        s.step();
        copy.step();
        assert_eq!(copy.position(b), s.position(b));
    }
    assert!(s.position(b).unwrap().y + 0.5 < -TOP, "fell through");
}

/// A `one_way` pair names two layers (the second the platforms'): one layer paired with
/// itself can't say which body is the platform, and is a located error.
#[test]
fn a_one_way_pair_of_one_layer_is_refused() {
    let text = r#"
name = "bad"
layers = ["a"]
[[collide]]
a = "a"
b = "a"
response = "one_way"
"#;
    let e = load_scenario(text, "bad.toml").unwrap_err();
    assert_eq!(e.field, "collide[0].response");
    assert!(e.problem.contains("needs two layers"), "{}", e.problem);
    let e = load_scenario(
        &text
            .replace("[\"a\"]", "[\"a\", \"b\"]")
            .replace("b = \"a\"", "b = \"b\"\ndestroy = \"a\""),
        "bad.toml",
    )
    .unwrap_err();
    assert_eq!(e.field, "collide[0].destroy");
}

/// The demo scene (`tests/data/one-way.toml`): after 240 frames the ball, which jumped up
/// through the platform, rides it (its bottom on the top, y = 2.25, moving with it), and the
/// crate, dropped at frame 120, rests on the solid ground (its bottom on y = -0.5).
#[test]
fn the_demo_scene_ends_with_the_ball_riding_and_the_crate_on_the_ground() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/data/one-way.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let mut s = Simulation::new(&load_scenario(&text, "one-way.toml").unwrap());
    for _ in 0..=240 {
        s.step();
    }
    let (ball, krate, p) = (
        entity(&s, "ball"),
        entity(&s, "crate"),
        entity(&s, "platform"),
    );
    assert!((s.position(ball).unwrap().y - 0.4 - 2.25).abs() <= SLOP);
    assert_eq!(s.carrier(ball).unwrap(), Some(p));
    assert!((s.position(krate).unwrap().y - 0.4 + 0.5).abs() <= SLOP);
    assert!(s.grounded(krate).unwrap() && s.grounded(ball).unwrap());
}

/// A body shape for the proptest, with its bottom below its centre.
fn shape(kind: u8, size: f64) -> (String, f64) {
    match kind {
        0 => (format!("{{ kind = \"circle\", radius = {size} }}"), size),
        1 => (
            format!(
                "{{ kind = \"aabb\", half_extents = [{}, {size}] }}",
                2.0 * size
            ),
            size,
        ),
        2 => (
            format!("{{ kind = \"capsule\", a = [0, -{size}], b = [0, {size}], radius = 0.1 }}"),
            size + 0.1,
        ),
        _ => (
            format!(
                "{{ kind = \"polygon\", vertices = [[-{size}, -{size}], [{size}, -{size}], [0, {size}]] }}"
            ),
            size,
        ),
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// A body of any shape dropped from above the platform at any speed (up to 600 units/s:
    /// 10 units a step, twenty times the platform's thickness) never ends a step with its
    /// bottom below the top.
    #[test]
    fn no_body_falling_from_above_ends_below_the_top(
        kind in 0u8..4,
        size in 0.05f64..1.5,
        x in -1.9f64..1.9,
        height in 0.0f64..30.0,
        speed in 0.0f64..600.0,
    ) {
        let (shape, bottom) = shape(kind, size);
        let y = TOP + bottom + height;
        let mut s = scene(
            "",
            &format!("shape = {shape}\nposition = [{x}, {y}]\nvelocity = [0, -{speed}]"),
            "",
        );
        let b = entity(&s, "body");
        for frame in 0..120 {
            s.step();
            let at = s.position(b).unwrap().y;
            prop_assert!(
                at - bottom >= TOP - 1e-9,
                "frame {frame}: bottom {} below the top", at - bottom
            );
        }
        prop_assert!(s.grounded(b).unwrap() || s.velocity(b).unwrap() != Vec2::ZERO);
    }
}
