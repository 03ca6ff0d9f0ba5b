//! Bad scenarios: one file per error class in `tests/data/bad-scenarios/`, each rejected by
//! `ricochet check` with exit code 2 and a `file:line:column: field: problem` message.
//!
//! Each case states independently what the message must contain (the line and column of
//! the offending key, the field path, the words that say what was expected); the insta
//! snapshot then pins the whole message so any change in wording is reviewed.

use crate::util::ricochet;

fn check(name: &str) -> String {
    let path = format!("tests/data/bad-scenarios/{name}.toml");
    let out = ricochet(&["check", &path], b"");
    assert_eq!(out.status.code(), Some(2), "{name}: bad input exits 2");
    assert!(out.stdout.is_empty());
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(!err.contains("panicked"), "{err}");
    err
}

fn case(name: &str, location: &str, must_contain: &[&str]) {
    let err = check(name);
    let want = format!("error: tests/data/bad-scenarios/{name}.toml:{location}: ");
    assert!(
        err.starts_with(&want),
        "{name}: expected {want:?}, got {err}"
    );
    for s in must_contain {
        assert!(err.contains(s), "{name}: expected {s:?} in {err}");
    }
    insta::assert_snapshot!(name, err);
}

#[test]
fn each_error_class_is_named_with_its_location() {
    case("syntax-error", "3:10", &["expected `]`"]);
    case("unknown-field", "6:1", &["unknown field `colour`"]);
    case(
        "nan-position",
        "6:1",
        &["bodies[0].position", "finite", "NaN"],
    );
    case(
        "infinite-velocity",
        "6:1",
        &["bodies[0].velocity", "finite", "inf"],
    );
    case(
        "zero-radius",
        "5:28",
        &["bodies[0].shape.radius", "greater than 0"],
    );
    case(
        "negative-half-extent",
        "6:26",
        &["bodies[0].shape.half_extents[1]", "greater than 0"],
    );
    case(
        "negative-mass",
        "6:1",
        &["bodies[0].mass", "greater than 0"],
    );
    case(
        "clockwise-polygon",
        "5:29",
        &["bodies[0].shape.vertices", "clockwise"],
    );
    case(
        "non-convex-polygon",
        "5:29",
        &["bodies[0].shape.vertices[2]", "not convex"],
    );
    case(
        "unknown-layer",
        "4:1",
        &[
            "bodies[0].layer",
            "unknown layer \"balll\"",
            "known: ball, wall",
        ],
    );
    case(
        "unknown-layer-in-collide",
        "5:1",
        &["collide[0].b", "unknown layer \"floor\""],
    );
    case(
        "unknown-response",
        "6:1",
        &["collide[0].response", "\"bounce\""],
    );
    // A touches value is located like any other: a wrong type at the value, a switch on a
    // pair that is never tested at its key.
    case(
        "touches-not-a-bool",
        "7:11",
        &["collide[0].touches", "expected a boolean"],
    );
    case(
        "touches-on-an-ignore-pair",
        "7:1",
        &["collide[0].touches", "`ignore` pair", "never touches"],
    );
    case(
        "split-cycle",
        "10:1",
        &["templates.pebble.split", "pebble -> rock -> pebble"],
    );
    case(
        "position-too-far",
        "6:1",
        &["bodies[0].position", "1e16", "largest coordinate"],
    );
    case(
        "size-too-small",
        "5:28",
        &["bodies[0].shape.radius", "1e-13", "smallest size"],
    );
    case(
        "same-layer-destroy-one",
        "7:1",
        &["collide[0].destroy", "\"both\""],
    );
    case(
        "unknown-template",
        "6:1",
        &["script[0].template", "unknown template \"rock\""],
    );
    case(
        "event-in-the-past",
        "9:1",
        &["script[0].frame", "in the past"],
    );
    case(
        "unknown-body-in-script",
        "11:1",
        &["script[0].body", "\"player\""],
    );
    case("unknown-action", "3:1", &["unknown variant `teleport`"]);
    case(
        "unknown-shape-kind",
        "5:18",
        &["unknown variant `triangle`"],
    );
    case(
        "missing-shape",
        "3:1",
        &["bodies[0].shape", "needs a shape"],
    );
    case("hz-and-dt", "1:6", &["hz", "not both"]);
    case("non-positive-dt", "1:6", &["dt", "> 0"]);
    case(
        "unknown-broad-phase",
        "5:15",
        &[
            "world.broad_phase",
            "auto, brute-force, sort-and-sweep, grid, strips, quadtree or tree",
            "\"octree\"",
        ],
    );
    case(
        "max-climb-angle-90",
        "6:19",
        &["world.max_climb_angle", "from 0 to less than 90", "got 90"],
    );
    case(
        "sleep-after-zero",
        "6:15",
        &["world.sleep_after", "from 1 to 4294967295", "got 0"],
    );
    case(
        "sleep-after-too-large",
        "5:15",
        &[
            "world.sleep_after",
            "from 1 to 4294967295",
            "got 4294967296",
        ],
    );
    case(
        "unknown-focus",
        "8:9",
        &[
            "world.active_region.focus",
            "no body in [[bodies]] is named \"plyer\"",
            "known: floor, player",
        ],
    );
    case(
        "zero-active-region",
        "6:16",
        &["world.active_region.half_extents", "> 0", "[40, 0]"],
    );
    case(
        "infinite-active-region",
        "5:52",
        &["world.active_region.half_extents", "finite", "[inf, 25]"],
    );
}

/// Inputs found by hostile use (issue 11): each was accepted, hung or misreported before.
#[test]
fn hostile_scenarios_are_named_with_their_location() {
    // Was: every path of the chain walked, 2^40 of them (still running after 10 minutes).
    // The count is exact: r_k creates 2 (1 + c_{k+1}) with c_39 = 0, so c_0 = 2^40 - 2.
    case(
        "split-chain-too-long",
        "6:1",
        &["templates.r0.split", "1099511627774 bodies", "65536"],
    );
    // Was: every log time 0.
    case("timestep-rounds-to-zero", "2:6", &["dt", "rounds to 0 ns"]);
    // Was: log times decreasing.
    case("run-too-long", "2:6", &["dt", "2^64 ns"]);
    // Was: log_time wrapping past u64 (2e9 s = 2e18 ns per step; frame 10 is 2e19 > 2^64).
    case(
        "frames-too-long",
        "3:10",
        &["frames", "frame 10", "2^64 ns"],
    );
    case(
        "event-after-last-frame",
        "10:1",
        &["script[0].frame", "1000", "last frame (5)"],
    );
    // Was: the event went to the lowest id silently. Bodies may share a name (a label);
    // a name that addresses an event or the active region must name one body.
    case(
        "duplicate-body-name",
        "18:1",
        &[
            "script[0].body",
            "2 bodies are named \"ship\"",
            "bodies[0], bodies[1]",
        ],
    );
    case(
        "duplicate-focus",
        "5:9",
        &["world.active_region.focus", "2 bodies are named \"player\""],
    );
    case(
        "spawn-too-far",
        "11:1",
        &["script[0].position", "beyond ±1e15"],
    );
    case(
        "muzzle-too-far",
        "11:96",
        &["bodies[0].controller.muzzle", "beyond ±1e15"],
    );
    // Was: reported without a field path.
    case(
        "integer-too-large",
        "10:12",
        &["bodies[1].lifetime", "99999999999999999999"],
    );
    // Was: "must be >= 1" for a number far above 1.
    case(
        "lifetime-too-large",
        "6:1",
        &[
            "bodies[0].lifetime",
            "from 1 to 4294967295",
            "9223372036854775807",
        ],
    );
}

/// A field the body's kind ignores is rejected: whoever wrote it expected it to do
/// something (a static lift given a velocity meant `kinematic`).
#[test]
fn a_field_the_kind_ignores_is_named_with_what_to_write() {
    case(
        "static-with-velocity",
        "8:1",
        &[
            "bodies[0].velocity",
            "static body never moves",
            "kind = \"kinematic\"",
        ],
    );
    case(
        "kinematic-with-template-gravity",
        "6:1",
        &[
            "bodies[0].gravity_scale",
            "kinematic body",
            "set by template \"crate\"",
        ],
    );
    case(
        "spawn-static-with-velocity",
        "12:1",
        &["script[0].velocity", "\"wall\" is static", "kinematic"],
    );
}

/// Issue #20's small ones and its bodies larger than the world: each was accepted (exit 0)
/// before, and silently wrong.
#[test]
fn issue_20_limits_are_named_with_their_location() {
    // Was: /stats.kinetic_energy = Infinity (0.5 * 1e300 * 1000^2), exit 0.
    case(
        "mass-too-large",
        "7:1",
        &["bodies[0].mass", "1e300", "outside 1e-12 to 1e15"],
    );
    // Was: the bullet appeared at rest, its velocity (ship's + bullet_speed) dropped.
    case(
        "static-bullet",
        "12:58",
        &[
            "bodies[0].controller.bullet",
            "template \"bullet\" is static",
            "kind = \"dynamic\"",
        ],
    );
    // The capsule reaches 5.5 from its origin (end a, 5 away, plus the radius 0.5): at some
    // angle it spans 11 across the 10-wide world, so an image two world sizes away could
    // touch a body the seam never tests there.
    case(
        "wider-than-wrap-world",
        "19:1",
        &[
            "bodies[1].shape",
            "reaches 5.5 along x and 5.5 along y",
            "10 x 10",
        ],
    );
    // Was: every digit of -5e29 (30 of them), and 309 of 1e308: numbers are quoted in
    // their shortest round-trip form, scientific past 1e16.
    case(
        "huge-clockwise-polygon",
        "4:29",
        &["bodies[0].shape.vertices", "(signed area -5e29)"],
    );
    case(
        "huge-turn-input",
        "2:53",
        &["script[0].input", "between -1 and 1, got 1e308\n"],
    );
    // Was: accepted, and the run overflowed at frame 1. The script's values are held to
    // the ±1e15 a body's and a live input's are.
    case(
        "huge-script-impulse",
        "2:62",
        &["script[0].impulse", "[1.7e308, 0] is beyond ±1e15"],
    );
    // A static body is never wrapped: two widths out it would be met only at its images one
    // width away (at x = 15 and 35), never at x = 5 where the disc overlaps it.
    case(
        "static-outside-wrap-world",
        "20:1",
        &[
            "bodies[1].position",
            "[25, 5] is outside the wrap-around world",
        ],
    );
    case(
        "static-spawned-outside-wrap-world",
        "2:61",
        &["script[0].position", "[5, -25] is outside"],
    );
    case(
        "static-split-child",
        "16:12",
        &[
            "bodies[0].split[0].template",
            "template \"debris\" is static",
        ],
    );
    // A template only the script spawns, in a world 100 wide but 10 tall: the box's centre
    // (4.5 away, it turns with the body) plus its half height 1 is 5.5 up.
    case(
        "template-wider-than-wrap-world",
        "8:1",
        &["templates.pair.shape", "5.5 along y", "100 x 10"],
    );
}

/// The other side of `static-split-child`: a static parent splitting into static debris
/// with no split velocity drops nothing, so it loads.
#[test]
fn a_static_child_of_a_static_parent_without_velocity_loads() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("debris.toml");
    std::fs::write(
        &path,
        "layers = [\"a\"]\n[templates.debris]\nlayer = \"a\"\nkind = \"static\"\nshape = \
         { kind = \"circle\", radius = 0.5 }\n[[bodies]]\nname = \"wall\"\nlayer = \"a\"\n\
         kind = \"static\"\nshape = { kind = \"circle\", radius = 1 }\nsplit = [{ template \
         = \"debris\", offset = [1, 0] }]\n",
    )
    .unwrap();
    let o = crate::util::ricochet(&["check", path.to_str().unwrap()], b"");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn every_bad_scenario_file_has_a_case() {
    let mut files: Vec<String> = std::fs::read_dir(crate::util::data("bad-scenarios"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".toml"))
        .collect();
    files.sort();
    let source = include_str!("bad_scenarios.rs");
    for f in files {
        let name = f.trim_end_matches(".toml");
        let quoted = format!("\"{name}\",");
        assert!(source.contains(&quoted), "{f} has no case");
    }
}

#[test]
fn a_missing_scenario_file_is_bad_input() {
    let out = ricochet(&["check", "no/such/scenario.toml"], b"");
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no/such/scenario.toml"));
}
