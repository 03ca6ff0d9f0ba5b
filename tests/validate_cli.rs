//! `ricochet validate` and `ricochet run --validate`: rapier2d as the referee.

use std::process::Command;

use crate::util::{ricochet, root, scenarios};

#[test]
fn validate_passes_on_every_scenario() {
    for s in scenarios() {
        let s = s.to_string_lossy();
        let o = ricochet(&["validate", &s], b"");
        let table = String::from_utf8_lossy(&o.stdout);
        assert_eq!(
            o.status.code(),
            Some(0),
            "{s}:\n{table}{}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(
            table.contains(": PASS") && table.contains("unexplained mismatches     0"),
            "{table}"
        );
    }
}

#[test]
fn a_broken_narrow_phase_makes_validate_fail() {
    let o = Command::new(env!("CARGO_BIN_EXE_ricochet"))
        .args(["validate", "scenarios/shapes.toml", "--frames", "120"])
        .current_dir(root())
        .env("RICOCHET_TEST_CORRUPT_CONTACTS", "1")
        .output()
        .unwrap();
    let table = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "{table}");
    assert!(table.contains(": FAIL"), "{table}");
}

#[test]
fn run_with_validate_writes_a_validation_channel() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("v.mcap");
    let o = ricochet(
        &[
            "run",
            "scenarios/validation.toml",
            "--frames",
            "60",
            "--validate",
            "-o",
            out.to_str().unwrap(),
        ],
        b"",
    );
    assert!(
        o.status.success(),
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    let log = ricochet_log::read_log_file(&out).unwrap();
    let v: Vec<_> = log.iter().filter(|m| m.topic == "/validation").collect();
    assert_eq!(v.len(), 61);
    for m in &v {
        assert_eq!(m.schema_name, "ricochet.Validation");
        assert_eq!(m.data["mismatches"], 0);
    }
    assert!(
        v.iter()
            .map(|m| m.data["contacts_compared"].as_u64().unwrap())
            .sum::<u64>()
            > 0
    );
}

#[test]
fn validate_turns_culling_and_sleeping_off_and_says_so() {
    // The referee tests every pair, so `validate` runs the scene with neither feature and
    // says so (they are tested on their own, in crates/sim/tests/rest.rs).
    let text = std::fs::read_to_string(root().join("scenarios/platformer.toml")).unwrap();
    assert!(text.contains("\n[world]\n"));
    let text = text.replacen("\n[world]\n", "\n[world]\nsleep_after = 5\n", 1);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sleepy.toml");
    std::fs::write(&path, text).unwrap();
    let o = ricochet(&["validate", path.to_str().unwrap()], b"");
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{stderr}");
    assert!(
        stderr.contains("active_region and sleep_after are turned off"),
        "{stderr}"
    );
}
