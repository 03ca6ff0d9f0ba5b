//! Helpers shared by the integration tests.

use std::path::PathBuf;
use std::process::{Command, Output, Stdio};

/// The project root (where `tests/data` lives).
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A path under `tests/data`.
pub fn data(name: &str) -> PathBuf {
    root().join("tests").join("data").join(name)
}

/// Runs the built `ricochet` binary with `args`, feeding `stdin`.
pub fn ricochet(args: &[&str], stdin: &[u8]) -> Output {
    use std::io::Write;
    let mut child = Command::new(env!("CARGO_BIN_EXE_ricochet"))
        .args(args)
        .current_dir(root())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the ricochet binary starts");
    let mut input = child.stdin.take().expect("stdin is piped");
    input.write_all(stdin).expect("stdin accepts the input");
    drop(input);
    child.wait_with_output().expect("ricochet runs to the end")
}

/// Every scenario file shipped at the top of `scenarios/` (not `stress/`), sorted.
pub fn scenarios() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(root().join("scenarios"))
        .expect("scenarios/ exists")
        .map(|e| e.expect("a readable entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    assert!(
        files.len() >= 3,
        "asteroids, platformer and shapes at least: {files:?}"
    );
    files
}

/// Runs `ricochet run SCENARIO -o OUT` with the real binary; panics with its stderr if it fails.
pub fn record(scenario: &std::path::Path, out: &std::path::Path) {
    record_with(scenario, out, &[]);
}

/// [`record`], with more arguments for `ricochet run`.
pub fn record_with(scenario: &std::path::Path, out: &std::path::Path, args: &[&str]) {
    let mut all = vec![
        "run",
        scenario.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ];
    all.extend_from_slice(args);
    let o = ricochet(&all, b"");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// The `/bodies` messages of a decoded log, each rebuilt in full (every live body with every
/// field) from the keyframes and deltas: what `/bodies` meant before it sent only changes.
pub fn full_bodies(log: &[ricochet_log::LogMessage]) -> Vec<serde_json::Value> {
    let mut states = ricochet_log::BodyStates::default();
    log.iter()
        .filter(|m| m.topic == "/bodies")
        .map(|m| states.apply(&m.data))
        .collect()
}

/// A `/bodies` shape (`{"circle": {"radius": 1, "center": [0, 0]}}`, as `ricochet.Shape`
/// decodes) as the scenario's `ShapeDef`.
pub fn shape_def(v: &serde_json::Value) -> ricochet_geom::ShapeDef {
    use ricochet_geom::ShapeDef;
    let pair = |v: &serde_json::Value| -> [f64; 2] {
        let a = v.as_array().expect("a point");
        [a[0].as_f64().unwrap(), a[1].as_f64().unwrap()]
    };
    let num = |v: &serde_json::Value| v.as_f64().unwrap();
    let (kind, s) = v
        .as_object()
        .and_then(|o| o.iter().next())
        .expect("one kind of shape");
    match kind.as_str() {
        "circle" => ShapeDef::Circle {
            radius: num(&s["radius"]),
            center: pair(&s["center"]),
        },
        "aabb" => ShapeDef::Aabb {
            half_extents: pair(&s["half_extents"]),
            center: pair(&s["center"]),
        },
        "obb" => ShapeDef::Obb {
            half_extents: pair(&s["half_extents"]),
            center: pair(&s["center"]),
            angle: num(&s["angle"]),
        },
        "capsule" => ShapeDef::Capsule {
            a: pair(&s["a"]),
            b: pair(&s["b"]),
            radius: num(&s["radius"]),
            center: [0.0, 0.0],
        },
        "polygon" => ShapeDef::Polygon {
            vertices: s["vertices"]
                .as_array()
                .unwrap()
                .chunks(2)
                .map(|p| [p[0].as_f64().unwrap(), p[1].as_f64().unwrap()])
                .collect(),
            center: [0.0, 0.0],
        },
        // A chain is logged as a compound of its segments, each a capsule of radius 0 (its
        // ghost points are not logged: a chain without `prev`/`next` is rebuilt whole).
        "compound" if is_chain(&s["parts"]) => {
            let parts = s["parts"].as_array().unwrap();
            let mut points = vec![pair(&parts[0]["capsule"]["a"])];
            points.extend(parts.iter().map(|p| pair(&p["capsule"]["b"])));
            ShapeDef::Chain {
                points,
                prev: None,
                next: None,
            }
        }
        "compound" => ShapeDef::Compound {
            parts: s["parts"]
                .as_array()
                .unwrap()
                .iter()
                .map(shape_def)
                .collect(),
        },
        other => panic!("unknown shape kind {other}"),
    }
}

/// Whether a logged compound's parts are a chain's segments: capsules of radius 0, each
/// starting where the one before ends.
fn is_chain(parts: &serde_json::Value) -> bool {
    let parts = parts.as_array().expect("parts");
    parts
        .iter()
        .all(|p| p["capsule"]["radius"].as_f64() == Some(0.0))
        && parts
            .windows(2)
            .all(|w| w[0]["capsule"]["b"] == w[1]["capsule"]["a"])
}

/// Runs the built `ricochet` binary with `args` in the folder `dir`, stdin empty.
pub fn ricochet_in(dir: &std::path::Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ricochet"))
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .output()
        .expect("the ricochet binary starts")
}

/// A temporary folder holding a copy of `scenarios/*.toml` (the top level), of the Tiled
/// maps they read (`scenarios/maps/`) and of `recordings/`, as a game's repository would: for
/// tests that change or bless them.
pub fn suite_copy() -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("a temporary folder");
    for (from, to) in [
        ("scenarios", "scenarios"),
        ("scenarios/maps", "scenarios/maps"),
        ("recordings", "recordings"),
    ] {
        std::fs::create_dir(dir.path().join(to)).unwrap();
        for entry in std::fs::read_dir(root().join(from)).unwrap() {
            let path = entry.unwrap().path();
            if path.is_file() {
                std::fs::copy(&path, dir.path().join(to).join(path.file_name().unwrap())).unwrap();
            }
        }
    }
    dir
}

/// A scenario's text with the x velocity of the first body that has a `velocity = [x, y]`
/// line raised by one ulp (the next float up, from its bits), and that body's index in the
/// file (its id: bodies are spawned in file order).
pub fn one_ulp_up(text: &str) -> (String, usize) {
    let mut out = String::new();
    let mut body = None;
    let mut bodies = 0;
    for line in text.lines() {
        if line.trim_start().starts_with("[[bodies]]") {
            bodies += 1;
        }
        let mut line = line.to_owned();
        if body.is_none() && bodies > 0 && line.starts_with("velocity = [") {
            let inner = &line["velocity = [".len()..line.find(']').unwrap()];
            let (x, rest) = inner.split_once(',').unwrap();
            let x: f64 = x.trim().parse().unwrap();
            let up = f64::from_bits(x.to_bits() + 1);
            assert!(x > 0.0 && up > x, "a positive x to raise: {x}");
            line = format!("velocity = [{up:?},{rest}]");
            body = Some(bodies - 1);
        }
        out.push_str(&line);
        out.push('\n');
    }
    (out, body.expect("a body with a velocity line"))
}
