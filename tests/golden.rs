//! Golden logs: every scenario in `scenarios/` is re-run and must give the recording in
//! `recordings/` byte for byte, and the digest of its final state (Box2D's determinism gate:
//! frame count and a hash of every body's raw float bits in id order) must match
//! `recordings/<name>.digest`.
//!
//! On a mismatch the test prints `ricochet diff`'s report (first divergent frame, topic,
//! body, field, both values). If the change is intended, re-bless:
//! `RICOCHET_BLESS=1 cargo test --test integration golden`.

use std::path::{Path, PathBuf};

use ricochet_sim::{Simulation, load_scenario};

use crate::util::{record, ricochet, root, scenarios};

const BLESS: &str = "RICOCHET_BLESS=1 cargo test --test integration golden";

/// Recordings must stay small enough to keep in git.
const MAX_RECORDING_BYTES: u64 = 2_000_000;

fn recording(name: &str, ext: &str) -> PathBuf {
    root().join("recordings").join(format!("{name}.{ext}"))
}

/// `frames N`, `bodies N`, `hash X` of the scenario's final state, computed by the library.
fn digest(scenario: &Path) -> String {
    let text = std::fs::read_to_string(scenario).unwrap();
    let s = load_scenario(&text, &scenario.display().to_string()).unwrap();
    let mut sim = Simulation::new(&s);
    for _ in 0..=s.frames {
        sim.step();
    }
    format!(
        "frames {}\nbodies {}\nhash {:016x}\n",
        s.frames,
        sim.world().len(),
        sim.world().digest()
    )
}

/// Compares a fresh log with the golden one; the error says what diverged and what to do.
fn compare(golden: &Path, fresh: &Path) -> Result<(), String> {
    let (g, f) = (
        std::fs::read(golden).map_err(|e| format!("{}: {e}", golden.display()))?,
        std::fs::read(fresh).unwrap(),
    );
    if g == f {
        return Ok(());
    }
    let o = ricochet(
        &["diff", golden.to_str().unwrap(), fresh.to_str().unwrap()],
        b"",
    );
    Err(format!(
        "{} no longer matches its golden log.\n{}{}\nIf this change in the physics is intended, re-bless the recordings:\n    {BLESS}\n",
        golden.display(),
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr),
    ))
}

#[test]
fn golden_every_scenario_matches_its_recording_and_digest() {
    let bless = std::env::var_os("RICOCHET_BLESS").is_some_and(|v| v == "1");
    let dir = tempfile::tempdir().unwrap();
    let mut failures = Vec::new();
    for scenario in scenarios() {
        let name = scenario.file_stem().unwrap().to_string_lossy().into_owned();
        let fresh = dir.path().join(format!("{name}.mcap"));
        record(&scenario, &fresh);
        let size = std::fs::metadata(&fresh).unwrap().len();
        assert!(
            size <= MAX_RECORDING_BYTES,
            "{name}.mcap is {size} bytes, over {MAX_RECORDING_BYTES}"
        );
        let d = digest(&scenario);
        if bless {
            std::fs::copy(&fresh, recording(&name, "mcap")).unwrap();
            std::fs::write(recording(&name, "digest"), &d).unwrap();
            continue;
        }
        if let Err(e) = compare(&recording(&name, "mcap"), &fresh) {
            failures.push(e);
        }
        let kept = std::fs::read_to_string(recording(&name, "digest")).unwrap_or_default();
        if kept != d {
            failures.push(format!(
                "{name}: the final-state digest changed\n  recorded:\n{kept}  now:\n{d}If intended:\n    {BLESS}\n"
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The velocity line of the first body that has one, nudged up by one ulp in x.
fn perturbed(text: &str) -> (String, usize) {
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
            line = format!("velocity = [{:?},{rest}]", x.next_up());
            body = Some(bodies - 1);
        }
        out.push_str(&line);
        out.push('\n');
    }
    (out, body.expect("a body with a velocity line"))
}

#[test]
fn golden_a_one_ulp_velocity_change_fails_and_the_diff_names_the_body_and_frame() {
    let scenario = root().join("scenarios/asteroids.toml");
    let (text, index) = perturbed(&std::fs::read_to_string(&scenario).unwrap());
    let name = load_scenario(&text, "perturbed.toml").unwrap().bodies[index]
        .name
        .clone();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("perturbed.toml");
    std::fs::write(&path, text).unwrap();
    let fresh = dir.path().join("perturbed.mcap");
    record(&path, &fresh);
    let err = compare(&recording("asteroids", "mcap"), &fresh)
        .expect_err("one ulp must fail the golden test");
    // Bodies are spawned in file order with ids 0, 1, ... (generation 0): the index is the
    // id.
    assert!(err.contains(&format!("body {index}:0 ({name})")), "{err}");
    assert!(err.contains("first difference: frame 0"), "{err}");
    assert!(
        err.contains(&format!("bodies[id={index}:0].velocity[0]")),
        "{err}"
    );
    assert!(err.contains(BLESS), "{err}");
}

#[test]
fn diff_of_a_log_against_itself_is_equal_and_a_truncated_copy_is_unreadable() {
    let golden = recording("asteroids", "mcap");
    let g = golden.to_str().unwrap();
    let same = ricochet(&["diff", g, g], b"");
    assert_eq!(
        same.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&same.stdout)
    );
    let dir = tempfile::tempdir().unwrap();
    let cut = dir.path().join("cut.mcap");
    let bytes = std::fs::read(&golden).unwrap();
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let o = ricochet(&["diff", g, cut.to_str().unwrap()], b"");
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("cut.mcap") && err.contains("truncated"),
        "{err}"
    );
    let json = ricochet(&["diff", g, g, "--json"], b"");
    let report: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    assert_eq!(report["equal"], true);
}
