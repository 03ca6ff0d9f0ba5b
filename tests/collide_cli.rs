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

/// A case whose `b` is `b` (a JSON body), with id `id`.
fn case_with(id: &str, b: &str) -> String {
    format!(
        r#"{{"id": {id}, "a": {{"shape": {{"kind": "circle", "radius": 1}}, "position": [0, 0]}}, "b": {b}}}"#
    )
}

const B: &str = r#"{"shape": {"kind": "circle", "radius": 1}, "position": [1, 0]}"#;
const FAR: &str = r#"{"shape": {"kind": "circle", "radius": 1}, "position": [9, 0]}"#;

#[test]
fn collide_refuses_a_key_given_twice_at_every_level() {
    // Issue 20: `{"cases":[<case>],"cases":[]}` exited 0 and printed nothing; a second `b`
    // silently replaced the first.
    let one = case_with("1", B);
    let err = rejected(&format!(r#"{{"cases":[{one}],"cases":[]}}"#));
    assert!(err.contains("line 1): cases: given twice"), "{err}");
    let err = rejected(&format!(r#"{{"id": 2, "a": {B}, "b": {B}, "b": {FAR}}}"#));
    assert!(
        err.contains("case 2 (line 1): b: duplicate field `b`"),
        "{err}"
    );
    let err = rejected(&case_with(
        "3",
        r#"{"shape": {"kind": "circle", "radius": 1}, "position": [1, 0], "angle": 1, "angle": 2}"#,
    ));
    assert!(
        err.contains("case 3 (line 1): b.angle: duplicate field `angle`"),
        "{err}"
    );
    let err = rejected(&format!(
        r#"{{"meta": {{}}, "meta": {{}}, "cases": [{one}]}}"#
    ));
    assert!(err.contains("meta: given twice"), "{err}");
}

#[test]
fn collide_refuses_an_unknown_key_of_the_document() {
    // Issue 20: only `meta` and `cases` may appear at the top of a document.
    let one = case_with("1", B);
    let err = rejected(&format!(
        "{{\"meta\": {{}},\n\"cases\": [{one}],\n\"casez\": []}}"
    ));
    assert!(
        err.contains("(line 3): casez: unknown key; a case document has only `meta` and `cases`"),
        "{err}"
    );
    // And a document without cases is not an empty success.
    let err = rejected(r#"{"meta": {"seed": 1}}"#);
    assert!(
        err.contains("cases: the document has no `cases` list"),
        "{err}"
    );
}

#[test]
fn collide_checks_the_type_of_truth_scenario_and_pair() {
    // Issue 20: they accepted any type; the shared set has strings and an object.
    for (key, value, expected) in [
        ("truth", "5", "expected an object"),
        ("truth", "[1]", "expected an object"),
        ("scenario", "{}", "expected a string"),
        ("pair", "[\"circle-circle\"]", "expected a string"),
    ] {
        let err = rejected(&format!(
            r#"{{"id": 4, "{key}": {value}, "a": {B}, "b": {FAR}}}"#
        ));
        assert!(
            err.contains(&format!("case 4 (line 1): {key}: invalid type")),
            "{err}"
        );
        assert!(err.contains(expected), "{key} {value}: {err}");
    }
}

#[test]
fn collide_names_a_case_that_is_not_an_object() {
    // Issue 20: `[]` gave "invalid length 4".
    let err = rejected("[]");
    assert!(
        err.contains("line 1): case: a case is a JSON object {\"id\", \"a\", \"b\"}, not an array"),
        "{err}"
    );
    assert!(!err.contains("invalid length"), "{err}");
    let one = case_with("1", B);
    let err = rejected(&format!("{{\"cases\": [\n{one},\n7,\n\"x\"]}}"));
    assert!(
        err.contains("(line 3): case: a case is a JSON object"),
        "{err}"
    );
    assert!(
        err.contains("(line 4): case: a case is a JSON object"),
        "{err}"
    );
    assert!(
        err.contains("not a number") && err.contains("not a string"),
        "{err}"
    );
}

#[test]
fn collide_refuses_a_compound_of_more_than_the_limit_before_colliding_it() {
    // Issue 20: two 200,000-part compounds ran past 60 s; the limit is 1024 parts.
    let parts = |n: usize| {
        let part = r#"{"kind": "circle", "radius": 0.5}"#;
        format!(
            r#"{{"shape": {{"kind": "compound", "parts": [{}]}}, "position": [0, 0]}}"#,
            vec![part; n].join(",")
        )
    };
    let err = rejected(&format!(
        r#"{{"id": 5, "a": {}, "b": {}}}"#,
        parts(1025),
        parts(1025)
    ));
    assert!(
        err.contains(
            "case 5 (line 1): a.shape.parts: a compound has at most 1024 parts, this one has 1025"
        ),
        "{err}"
    );
    let out = ricochet(
        &["collide", "-"],
        format!(r#"{{"id": 5, "a": {}, "b": {}}}"#, parts(1024), parts(1024)).as_bytes(),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn collide_cuts_long_values_in_its_messages_and_refuses_a_long_id() {
    // Issue 20: a 100 MB id was echoed whole. An id is at most 256 bytes; messages quote at
    // most 80 characters of any key, value or id.
    let long = "x".repeat(1 << 20);
    let err = rejected(&case_with(&format!("\"{long}\""), B));
    assert!(
        err.contains("id: an id is at most 256 bytes, this one is 1048576"),
        "{err}"
    );
    assert!(err.len() < 1000, "{} bytes of errors", err.len());
    let err = rejected(&format!(r#"{{"id": 6, "{long}": 1, "a": {B}, "b": {B}}}"#));
    assert!(
        err.contains("case 6 (line 1): xxxx") && err.contains("(1048576 bytes)"),
        "{err}"
    );
    assert!(err.len() < 1000, "{} bytes of errors", err.len());
    let err = rejected(&case_with(
        "7",
        &format!(r#"{{"shape": {{"kind": "{long}", "radius": 1}}, "position": [1, 0]}}"#),
    ));
    assert!(
        err.contains("case 7 (line 1): b.shape") && err.contains("bytes)"),
        "{err}"
    );
    assert!(err.len() < 1000, "{} bytes of errors", err.len());
    // A case longer than 4 MiB is skipped unread, and the next one still checked.
    let huge = format!(r#"{{"id": 8, "pad": "{}"}}"#, "y".repeat(5 << 20));
    let err = rejected(&format!("{huge}\n{}", case_with("9", r#"{"shape": 1}"#)));
    assert!(
        err.contains("input (line 1): case: 5242900 bytes, more than the 4194304"),
        "{err}"
    );
    assert!(err.contains("case 9 (line 2): b.shape"), "{err}");
}

/// Runs `ricochet collide -` with its address space capped at `cap_kb`, feeding it the lines
/// `line(i)` for `i` in `0..n` from another thread as it reads them (the input is never held
/// whole by anyone), and returns its exit code, how many lines it printed and its stderr.
fn collide_streamed(
    cap_kb: u64,
    head: &str,
    line: fn(usize) -> String,
    n: usize,
    tail: &str,
) -> (Option<i32>, usize, String) {
    use std::io::{BufRead, Read, Write};
    use std::process::{Command, Stdio};
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v {cap_kb}; exec '{}' collide -",
            env!("CARGO_BIN_EXE_ricochet")
        ))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = std::io::BufWriter::new(child.stdin.take().unwrap());
    let (head, tail) = (head.to_owned(), tail.to_owned());
    let writer = std::thread::spawn(move || {
        // A child that stops reading (it failed) closes the pipe: that ends the writing.
        let _ = stdin.write_all(head.as_bytes());
        for i in 0..n {
            if stdin.write_all(line(i).as_bytes()).is_err() {
                return;
            }
        }
        let _ = stdin.write_all(tail.as_bytes());
    });
    let mut stderr = child.stderr.take().unwrap();
    let errors = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = stderr.read_to_string(&mut s);
        s
    });
    let lines = std::io::BufReader::new(child.stdout.take().unwrap())
        .lines()
        .count();
    let status = child.wait().unwrap();
    writer.join().unwrap();
    (status.code(), lines, errors.join().unwrap())
}

/// A good case (about 170 bytes), as a JSON line or a list element.
fn good(i: usize) -> String {
    format!(
        "{{\"id\": {i}, \"a\": {{\"shape\": {{\"kind\": \"circle\", \"radius\": 1}}, \"position\": [0, 0]}}, \"b\": {{\"shape\": {{\"kind\": \"aabb\", \"half_extents\": [1, 1]}}, \"position\": [1.5, {}]}}}}\n",
        i % 7
    )
}

#[test]
fn collide_streams_valid_input_in_flat_memory() {
    // Issue 20: 111 MB of valid JSON lines used 562 MB. 32 MB of lines, then the same as a
    // document, under a 64 MB cap on address space (the binary alone needs about 30): read
    // whole, the text and its cases took several times the cap.
    const N: usize = 190_000;
    let (code, lines, err) = collide_streamed(64_000, "", good, N, "");
    assert_eq!((code, lines), (Some(0), N), "{err}");
    let element = |i: usize| format!(",{}", good(i + 1));
    let (code, lines, err) = collide_streamed(
        64_000,
        &format!("{{\"meta\": {{\"n\": {N}}}, \"cases\": [{}", good(0)),
        element,
        N - 1,
        "]}\n",
    );
    assert_eq!((code, lines), (Some(0), N), "{err}");
}

#[test]
fn collide_reports_a_bounded_number_of_errors_then_the_count() {
    // Issue 20: 50 MB of bad lines used 3.1 GB and wrote 499 MB of errors. 32 MB of bad
    // lines under a 64 MB cap: the first 20 errors, then how many there were.
    const N: usize = 190_000;
    let bad = |i: usize| good(i).replace("\"radius\": 1", "\"radius\": -1");
    let (code, lines, err) = collide_streamed(64_000, "", bad, N, "");
    assert_eq!((code, lines), (Some(2), 0), "{err}");
    assert_eq!(
        err.lines().filter(|l| l.starts_with("error: ")).count(),
        20,
        "{err}"
    );
    assert!(err.contains("case 19 (line 20): a.shape.radius"), "{err}");
    assert!(
        err.contains(&format!(
            "{N} bad case(s) (the first 20 shown); nothing was collided"
        )),
        "{err}"
    );
    assert!(err.len() < 5_000, "{} bytes of errors", err.len());
}
