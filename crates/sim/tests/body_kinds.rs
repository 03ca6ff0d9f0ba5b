//! What a body's kind does with its fields: a field the stages ignore for that kind is an
//! error naming it (whoever wrote it expected motion), and every field the kind uses loads.
//! (`tests/data/bad-scenarios/` at the workspace root pins the messages through the CLI.)

use ricochet_sim::{ScenarioError, load_scenario};

/// One body of `kind` with `extra` lines, a `bullet` template for ships.
fn body(kind: &str, extra: &str) -> Result<ricochet_sim::Scenario, ScenarioError> {
    let text = format!(
        r#"layers = ["a"]
[templates.bullet]
layer = "a"
shape = {{ kind = "circle", radius = 0.1 }}
[templates.piece]
layer = "a"
shape = {{ kind = "circle", radius = 0.5 }}
[[bodies]]
layer = "a"
kind = "{kind}"
shape = {{ kind = "aabb", half_extents = [1, 1] }}
{extra}
"#
    );
    load_scenario(&text, "kinds.toml")
}

const SHIP: &str = r#"controller = { kind = "ship", thrust = 5, turn_rate = 2, bullet = "bullet", bullet_speed = 9 }"#;

#[test]
fn each_field_a_kind_ignores_is_rejected_by_name() {
    let cases = [
        ("static", "velocity = [3, 0]", "velocity"),
        ("static", "angular_velocity = 1", "angular_velocity"),
        ("static", "force = [0, 1]", "force"),
        ("static", "gravity_scale = 0", "gravity_scale"),
        ("static", "mass = 2", "mass"),
        (
            "static",
            r#"controller = { kind = "runner", run_speed = 5, jump_speed = 9 }"#,
            "controller",
        ),
        (
            "static",
            r#"controller = { kind = "walker", speed = 2 }"#,
            "controller",
        ),
        ("kinematic", "force = [0, 1]", "force"),
        ("kinematic", "gravity_scale = 0", "gravity_scale"),
        ("kinematic", "mass = 2", "mass"),
    ];
    for (kind, line, field) in cases {
        let e = body(kind, line).expect_err(line);
        assert_eq!(e.field, format!("bodies[0].{field}"), "{kind}: {line}: {e}");
        assert!(e.problem.contains(&format!("a {kind} body")), "{e}");
        // Located at the key.
        assert_eq!((e.line, e.column), (12, 1), "{e}");
    }
}

#[test]
fn every_field_a_kind_uses_loads() {
    // A kinematic body moves, turns, patrols or steers; a static one has an angle, a
    // lifetime, split pieces, and may be a turret (a static ship fires).
    let kinematic = [
        "velocity = [3, 0]\nangular_velocity = 1",
        r#"controller = { kind = "walker", speed = 2 }"#,
        SHIP,
    ];
    for extra in kinematic {
        body("kinematic", extra).unwrap_or_else(|e| panic!("{extra}: {e}"));
    }
    let fixed = [
        "angle = 0.5",
        "lifetime = 30",
        r#"split = [{ template = "piece", offset = [1, 0] }]"#,
        SHIP,
    ];
    for extra in fixed {
        body("static", extra).unwrap_or_else(|e| panic!("{extra}: {e}"));
    }
    // A dynamic body uses every field.
    let all = format!(
        "velocity = [1, 2]\nangular_velocity = 1\nforce = [0, 1]\ngravity_scale = 0.5\nmass = 3\n{SHIP}"
    );
    body("dynamic", &all).unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn a_template_is_checked_as_the_body_it_describes_and_a_body_as_used() {
    let text = |template_kind: &str, body_kind: &str| {
        format!(
            r#"layers = ["a"]
[templates.crate]
layer = "a"
kind = "{template_kind}"
shape = {{ kind = "aabb", half_extents = [1, 1] }}
velocity = [1, 0]
[[bodies]]
template = "crate"
kind = "{body_kind}"
"#
        )
    };
    // A static template with a velocity is wrong whatever uses it.
    let e = load_scenario(&text("static", "kinematic"), "t.toml").unwrap_err();
    assert_eq!(e.field, "templates.crate.velocity", "{e}");
    // A kinematic template's velocity is dropped by a body that makes it static: the body
    // is wrong, and the error says the field came from the template.
    let e = load_scenario(&text("kinematic", "static"), "t.toml").unwrap_err();
    assert_eq!(e.field, "bodies[0].velocity", "{e}");
    assert!(e.problem.ends_with(r#"(set by template "crate")"#), "{e}");
    assert_eq!((e.line, e.column), (7, 1), "at the body: {e}");
    load_scenario(&text("kinematic", "dynamic"), "t.toml").unwrap();
}
