//! `ricochet collide`: the narrow phase from the command line.

use serde_json::Value;

use crate::util::{data, ricochet};

#[test]
fn collide_prints_one_line_per_shared_case() {
    let path = data("collision-cases.json");
    let out = ricochet(&["collide", path.to_str().unwrap()], b"");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 3000);
    for (i, line) in lines.iter().enumerate() {
        assert_eq!(line["id"], i as u64);
        assert!(line["overlap"].is_boolean());
        assert!(line["depth"].is_f64());
        assert_eq!(line["normal"].as_array().unwrap().len(), 2);
        assert_eq!(line["point"].as_array().unwrap().len(), 2);
    }
}

#[test]
fn collide_reads_json_lines_from_stdin() {
    let input = br#"{"id": "touching", "a": {"shape": {"kind": "circle", "radius": 1}, "position": [0, 0]}, "b": {"shape": {"kind": "aabb", "half_extents": [1, 1]}, "position": [1.5, 0]}}
{"id": 2, "a": {"shape": {"kind": "circle", "radius": 1}, "position": [0, 0]}, "b": {"shape": {"kind": "circle", "radius": 1}, "position": [3, 4]}}
"#;
    let out = ricochet(&["collide", "-"], input);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    // Circle radius 1 at the origin, box from x = 0.5: 0.5 deep, pushed along +x.
    assert_eq!(lines[0]["id"], "touching");
    assert_eq!(lines[0]["overlap"], true);
    assert_eq!(lines[0]["depth"], 0.5);
    assert_eq!(lines[0]["normal"], serde_json::json!([1.0, 0.0]));
    // Centres 5 apart, radii 1 + 1: 3 apart along (0.6, 0.8).
    assert_eq!(lines[1]["overlap"], false);
    assert_eq!(lines[1]["depth"], -3.0);
    assert_eq!(lines[1]["normal"], serde_json::json!([0.6, 0.8]));
}

fn rejected(input: &str) -> String {
    let out = ricochet(&["collide", "-"], input.as_bytes());
    assert_eq!(out.status.code(), Some(2), "bad input exits 2");
    assert!(
        out.stdout.is_empty(),
        "nothing is collided when the input is bad"
    );
    String::from_utf8(out.stderr).unwrap()
}

#[test]
fn collide_rejects_a_clockwise_polygon_by_case_and_field() {
    let err = rejected(
        r#"{"id": 41, "a": {"shape": {"kind": "polygon", "vertices": [[0,0],[0,1],[1,0]]}, "position": [0, 0]}, "b": {"shape": {"kind": "circle", "radius": 1}, "position": [0, 0]}}"#,
    );
    assert!(err.contains("case 41"), "{err}");
    assert!(err.contains("a.shape.vertices"), "{err}");
    assert!(err.contains("clockwise"), "{err}");
}

#[test]
fn collide_rejects_a_non_convex_polygon() {
    let err = rejected(
        r#"{"id": 1, "a": {"shape": {"kind": "circle", "radius": 1}, "position": [0, 0]}, "b": {"shape": {"kind": "polygon", "vertices": [[0,0],[2,0],[1,0.2],[2,2],[0,2]]}, "position": [0, 0]}}"#,
    );
    assert!(
        err.contains("b.shape.vertices[2]") && err.contains("not convex"),
        "{err}"
    );
}

#[test]
fn collide_rejects_a_negative_radius() {
    let err = rejected(
        r#"{"id": 7, "a": {"shape": {"kind": "circle", "radius": -1}, "position": [0, 0]}, "b": {"shape": {"kind": "circle", "radius": 1}, "position": [0, 0]}}"#,
    );
    assert!(
        err.contains("case 7") && err.contains("a.shape.radius"),
        "{err}"
    );
}

#[test]
fn collide_rejects_an_unknown_kind() {
    let err = rejected(
        r#"{"id": 3, "a": {"shape": {"kind": "triangle", "radius": 1}, "position": [0, 0]}, "b": {"shape": {"kind": "circle", "radius": 1}, "position": [0, 0]}}"#,
    );
    assert!(err.contains("case 3") && err.contains("triangle"), "{err}");
}

#[test]
fn collide_rejects_non_finite_numbers() {
    // JSON has no NaN literal; a number too large for f64 is the way to smuggle in infinity.
    let err = rejected(
        r#"{"id": 9, "a": {"shape": {"kind": "circle", "radius": 1}, "position": [1e999, 0]}, "b": {"shape": {"kind": "circle", "radius": 1}, "position": [0, 0]}}"#,
    );
    assert!(err.contains("line 1"), "{err}");
}

#[test]
fn collide_reports_a_missing_file_with_exit_2() {
    let out = ricochet(&["collide", "no/such/file.json"], b"");
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no/such/file.json"));
}

#[test]
fn collide_rejects_unknown_keys_by_case_and_field() {
    // A stray key at the top of a case, a misspelt `angle` in a body, a misspelt `center` in
    // a shape: each is named by case id and field, never silently ignored.
    let err = rejected(
        r#"{"id": 5, "tolerance": 1e-3, "a": {"shape": {"kind": "circle", "radius": 1}, "position": [0, 0]}, "b": {"shape": {"kind": "circle", "radius": 1}, "position": [3, 4]}}
{"id": "six", "a": {"shape": {"kind": "circle", "radius": 1}, "position": [0, 0], "angel": 0.5}, "b": {"shape": {"kind": "circle", "radius": 1}, "position": [3, 4]}}
{"id": 7, "a": {"shape": {"kind": "circle", "radius": 1}, "position": [0, 0]}, "b": {"shape": {"kind": "circle", "radius": 1, "centre": [1, 0]}, "position": [3, 4]}}"#,
    );
    assert!(
        err.contains("case 5 (line 1): tolerance: unknown field `tolerance`"),
        "{err}"
    );
    assert!(
        err.contains("case \"six\" (line 2): a.angel: unknown field `angel`"),
        "{err}"
    );
    // Inside a shape (tagged by `kind`) the path stops at the shape; the message names the key.
    assert!(
        err.contains("case 7 (line 3): b.shape: unknown field `centre`"),
        "{err}"
    );
    assert!(err.contains("3 bad case(s)"), "{err}");
}

#[test]
fn collide_still_accepts_the_shared_files_extra_keys() {
    // `pair`, `scenario` and `truth` come with the shared ground-truth cases.
    let out = ricochet(
        &["collide", "-"],
        br#"{"id": 1, "pair": "circle-circle", "scenario": "random", "truth": {"depth": 1}, "a": {"id": 0, "shape": {"kind": "circle", "radius": 1}, "position": [0, 0]}, "b": {"shape": {"kind": "circle", "radius": 1}, "position": [1, 0]}}"#,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}
