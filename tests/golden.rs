//! Golden logs: every scenario in `scenarios/` is re-run by `ricochet test scenarios
//! --golden recordings` (the runner a game uses on its own scenarios) and must give the
//! recording in `recordings/` byte for byte, and the digest of its final state (Box2D's
//! determinism gate: frame count and a hash of every body's raw float bits in id order)
//! must match `recordings/<name>.digest`.
//!
//! On a mismatch the test prints the runner's lines and `ricochet diff`'s report of each
//! failing scenario (first divergent frame, topic, body, field, both values). If the change
//! is intended, re-bless: `RICOCHET_BLESS=1 cargo test --test integration golden`, which
//! runs `ricochet test scenarios --golden recordings --bless`.

use std::path::{Path, PathBuf};

use ricochet_sim::load_scenario;

use crate::util::{one_ulp_up, record, ricochet, root, scenarios};

const BLESS: &str = "RICOCHET_BLESS=1 cargo test --test integration golden";

/// Recordings must stay small enough to keep in git.
const MAX_RECORDING_BYTES: u64 = 2_000_000;

fn recording(name: &str, ext: &str) -> PathBuf {
    root().join("recordings").join(format!("{name}.{ext}"))
}

#[test]
fn golden_every_scenario_matches_its_recording_and_digest() {
    let bless = std::env::var_os("RICOCHET_BLESS").is_some_and(|v| v == "1");
    let fresh = tempfile::tempdir().unwrap();
    let keep = fresh.path().to_str().unwrap();
    let mut args = vec![
        "test",
        "scenarios",
        "--golden",
        "recordings",
        "--keep",
        keep,
    ];
    if bless {
        args.push("--bless");
    }
    let o = ricochet(&args, b"");
    let stdout = String::from_utf8_lossy(&o.stdout);
    let expected = scenarios();
    // The sizes of the fresh logs, which equal the recordings when the test passes.
    for scenario in &expected {
        let name = scenario.file_stem().unwrap().to_string_lossy();
        let log = fresh.path().join(format!("{name}.mcap"));
        let size = std::fs::metadata(&log)
            .unwrap_or_else(|e| panic!("{}: {e}\n{stdout}", log.display()))
            .len();
        assert!(
            size <= MAX_RECORDING_BYTES,
            "{name}.mcap is {size} bytes, over {MAX_RECORDING_BYTES}"
        );
    }
    let mut report = String::new();
    for line in stdout.lines().filter(|l| l.contains(": differs")) {
        let name = Path::new(line.split(':').next().unwrap())
            .file_stem()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        let fresh_log = fresh.path().join(format!("{name}.mcap"));
        let golden = recording(&name, "mcap");
        let d = ricochet(
            &[
                "diff",
                golden.to_str().unwrap(),
                fresh_log.to_str().unwrap(),
            ],
            b"",
        );
        report += &String::from_utf8_lossy(&d.stdout);
    }
    assert!(
        o.status.success(),
        "the golden logs or digests no longer match:\n{stdout}{}\n{report}\nIf this change in \
         the physics is intended, re-bless the recordings:\n    {BLESS}\n",
        String::from_utf8_lossy(&o.stderr)
    );
    // Every scenario was judged, each on its own line, then the summary.
    let n = expected.len();
    assert_eq!(stdout.lines().count(), n + 1, "{stdout}");
    let verdict = if bless { "" } else { ": ok" };
    for scenario in &expected {
        let shown = scenario.strip_prefix(root()).unwrap().display().to_string();
        assert!(
            stdout
                .lines()
                .any(|l| l.starts_with(&format!("{shown}:")) && l.contains(verdict)),
            "{shown} has no line with {verdict:?}:\n{stdout}"
        );
    }
    assert!(
        stdout.ends_with(&format!("\n{n} passed, 0 failed\n")),
        "{stdout}"
    );
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
fn golden_a_one_ulp_velocity_change_fails_and_the_diff_names_the_body_and_frame() {
    let scenario = root().join("scenarios/asteroids.toml");
    let (text, index) = one_ulp_up(&std::fs::read_to_string(&scenario).unwrap());
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
