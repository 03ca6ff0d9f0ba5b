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

/// Issue 20: a disc two world widths a frame through a wrapping world overlaps the still
/// one by 7 at every logged pose (the scenario's comment says why), so each of the 61
/// frames logs that contact, and the referee, judging the poses wrapped into the world,
/// agrees. Before the fix the log had 1 contact, and `validate` then failed (exit 1).
#[test]
fn a_disc_two_world_widths_a_frame_keeps_its_contact_and_validate_passes() {
    let scenario = crate::util::data("wrap-fast.toml");
    let scenario = scenario.to_str().unwrap();
    let o = ricochet(&["validate", scenario], b"");
    let table = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{table}");
    assert!(table.contains("contacts compared          61"), "{table}");
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("w.mcap");
    let log = log.to_str().unwrap();
    assert!(
        ricochet(&["run", scenario, "-o", log], b"")
            .status
            .success()
    );
    let o = ricochet(&["dump", log, "--topic", "/contacts"], b"");
    assert!(o.status.success());
    let mut depths = Vec::new();
    for line in String::from_utf8_lossy(&o.stdout).lines() {
        let v: serde_json::Value = serde_json::from_str(line).unwrap();
        for c in v["data"]["contacts"].as_array().unwrap() {
            depths.push(c["depth"].as_f64().unwrap());
        }
    }
    // Radii 5 + 5 less the 3 between the centres.
    assert_eq!(depths, vec![7.0; 61]);
}

/// Issue 36: a scene with one-way platforms (a ball jumping up through one and riding it, a
/// crate dropping through onto solid ground) runs, and the referee passes: rapier has no
/// one-way response, so those pairs are left out, and the crate's ground contacts are
/// compared as usual. Before one-way platforms, the scenario was refused (exit 2).
#[test]
fn a_scene_with_one_way_platforms_validates() {
    let scenario = crate::util::data("one-way.toml");
    assert_validates(&scenario);
}

/// Issue 36: a scene with a terrain chain (every shape sliding over its joints, a crest and
/// a slope) runs and the referee passes, rapier's polyline for the chain
/// (docs/validation.md); `check` counts the chain. Before chains, the scene was refused
/// (exit 2: an unknown shape kind).
#[test]
fn a_scene_with_a_terrain_chain_validates() {
    let scenario = crate::util::data("chains.toml");
    assert_validates(&scenario);
    let o = ricochet(&["check", scenario.to_str().unwrap()], b"");
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("terrain chains: 1 bodies, 11 segments"),
        "{out}"
    );
}

/// `ricochet validate SCENARIO` exits 0 with no unexplained mismatch.
fn assert_validates(scenario: &std::path::Path) {
    let o = ricochet(&["validate", scenario.to_str().unwrap()], b"");
    let table = String::from_utf8_lossy(&o.stdout);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{table}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(table.contains("unexplained mismatches     0"), "{table}");
}
