//! The `[world]` options `broad_phase`, `sleep_after` and `active_region`: what a file loads
//! into, their defaults, and the values that are rejected (`tests/data/bad-scenarios/` at the
//! workspace root holds one file per error message, checked through the CLI).

use ricochet_geom::Vec2;
use ricochet_sim::broad_phase::BroadPhaseKind;
use ricochet_sim::{ActiveRegion, ScenarioError, WorldDef, load_scenario};

const BODIES: &str = r#"
[[bodies]]
name = "floor"
layer = "tile"
kind = "static"
shape = { kind = "aabb", half_extents = [20, 0.5] }

[[bodies]]
name = "player"
layer = "player"
shape = { kind = "aabb", half_extents = [0.4, 0.8] }
position = [0, 1.3]
"#;

fn world(world_table: &str) -> Result<WorldDef, ScenarioError> {
    let text = format!("hz = 60\nlayers = [\"tile\", \"player\"]\n\n{world_table}\n{BODIES}");
    load_scenario(&text, "options.toml").map(|s| s.world)
}

fn rejected(world_table: &str) -> ScenarioError {
    match world(world_table) {
        Ok(w) => panic!("accepted {world_table:?} as {w:?}"),
        Err(e) => e,
    }
}

#[test]
fn all_three_options_load_into_the_world_def() {
    let w = world(
        r#"[world]
gravity = [0, -9.81]
broad_phase = "sort-and-sweep"
sleep_after = 30

[world.active_region]
focus = "player"
half_extents = [40.0, 25]
"#,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(w.broad_phase, BroadPhaseKind::SortAndSweep);
    assert_eq!(w.sleep_after, Some(30));
    assert_eq!(
        w.active_region,
        Some(ActiveRegion {
            focus: "player".to_owned(),
            half_extents: Vec2::new(40.0, 25.0),
        })
    );
    assert_eq!(w.gravity, Vec2::new(0.0, -9.81));
}

#[test]
fn absent_options_take_the_world_def_defaults() {
    let w = world("").unwrap_or_else(|e| panic!("{e}"));
    let d = WorldDef::default();
    assert_eq!(w.broad_phase, d.broad_phase);
    assert_eq!(w.broad_phase, BroadPhaseKind::Auto);
    assert_eq!(w.sleep_after, None);
    assert_eq!(w.active_region, None);
}

#[test]
fn each_broad_phase_name_maps_to_its_kind() {
    for (name, kind) in [
        ("auto", BroadPhaseKind::Auto),
        ("brute-force", BroadPhaseKind::BruteForce),
        ("sort-and-sweep", BroadPhaseKind::SortAndSweep),
        ("grid", BroadPhaseKind::Grid),
        ("strips", BroadPhaseKind::Strips),
        ("quadtree", BroadPhaseKind::Quadtree),
        ("tree", BroadPhaseKind::Tree),
    ] {
        let w = world(&format!("[world]\nbroad_phase = \"{name}\"\n"))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(w.broad_phase, kind, "{name}");
    }
}

#[test]
fn broad_phase_names_are_kebab_case_only() {
    for name in [
        "SortAndSweep",
        "sort_and_sweep",
        "Grid",
        "QuadTree",
        "dynamic-tree",
        "",
    ] {
        let e = rejected(&format!("[world]\nbroad_phase = \"{name}\"\n"));
        assert_eq!(e.field, "world.broad_phase", "{name}");
        assert_eq!(
            e.problem,
            format!(
                "expected auto, brute-force, sort-and-sweep, grid, strips, quadtree or tree, got \"{name}\""
            )
        );
    }
}

#[test]
fn sleep_after_accepts_1_to_u32_max_frames() {
    for (n, want) in [(1_i64, 1_u32), (4_294_967_295, u32::MAX)] {
        let w = world(&format!("[world]\nsleep_after = {n}\n")).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(w.sleep_after, Some(want));
    }
    for n in [0, -1, i64::MIN, 4_294_967_296, i64::MAX] {
        let e = rejected(&format!("[world]\nsleep_after = {n}\n"));
        assert_eq!(e.field, "world.sleep_after", "{n}");
        assert!(e.problem.ends_with(&format!("got {n}")), "{e}");
        // At the value: line 5 (after `hz`, `layers`, a blank line and `[world]`), column 15.
        assert_eq!((e.line, e.column), (5, 15), "{e}");
    }
}

#[test]
fn sleep_after_must_be_a_whole_number() {
    // A type error comes from the TOML parser, located at the value.
    let e = rejected("[world]\nsleep_after = 1.5\n");
    assert_eq!((e.line, e.column), (5, 15), "{e}");
    assert!(e.problem.contains("expected i64"), "{e}");
}

#[test]
fn active_region_half_extents_must_be_finite_and_positive() {
    for h in [
        "[0, 1]",
        "[1, 0]",
        "[-1, 1]",
        "[1, -0.0]",
        "[nan, 1]",
        "[1, inf]",
        "[-inf, 1]",
    ] {
        let e = rejected(&format!(
            "[world.active_region]\nfocus = \"player\"\nhalf_extents = {h}\n"
        ));
        assert_eq!(e.field, "world.active_region.half_extents", "{h}");
        assert!(
            e.problem
                .starts_with("must be finite numbers > 0 on both axes"),
            "{e}"
        );
        assert_eq!((e.line, e.column), (6, 16), "{e}");
    }
}

#[test]
fn active_region_focus_must_name_a_body_present_at_frame_0() {
    let e = rejected("[world.active_region]\nfocus = \"ghost\"\nhalf_extents = [10, 10]\n");
    assert_eq!(e.field, "world.active_region.focus");
    assert_eq!(
        e.problem,
        "no body in [[bodies]] is named \"ghost\"; known: floor, player"
    );
    assert_eq!((e.line, e.column), (5, 9), "{e}");
}

#[test]
fn active_region_focus_may_be_a_name_taken_from_a_template() {
    let text = r#"
layers = ["player"]

[world]
active_region = { focus = "hero", half_extents = [8, 4.5] }

[templates.hero]
layer = "player"
shape = { kind = "circle", radius = 0.5 }

[[bodies]]
template = "hero"
"#;
    let s = load_scenario(text, "template.toml").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        s.world.active_region.map(|r| r.focus),
        Some("hero".to_owned())
    );
}

#[test]
fn a_template_or_spawn_name_alone_is_not_a_focus() {
    let text = r#"
layers = ["player"]

[world]
active_region = { focus = "hero", half_extents = [8, 4.5] }

[templates.hero]
layer = "player"
shape = { kind = "circle", radius = 0.5 }

[[script]]
frame = 0
action = "spawn"
template = "hero"
position = [0, 0]
"#;
    let e = load_scenario(text, "spawned.toml").unwrap_err();
    assert_eq!(e.field, "world.active_region.focus");
    assert_eq!(
        e.problem,
        "no body in [[bodies]] is named \"hero\"; known: none"
    );
}

#[test]
fn active_region_fields_are_required_and_closed() {
    let e = rejected("[world.active_region]\nfocus = \"player\"\n");
    assert!(e.problem.contains("missing field `half_extents`"), "{e}");
    let e =
        rejected("[world.active_region]\nfocus = \"player\"\nhalf_extents = [1, 1]\nradius = 3\n");
    assert!(e.problem.contains("unknown field `radius`"), "{e}");
}
