//! `ricochet sweep` hardened (issue #34): a combination that overflows, too many
//! combinations, memory flat in the frame count, outputs that would overwrite each other or
//! the scenario, and a failed write that loses nothing. The sweep's own behaviour is in
//! `sweep_cli.rs`, whose helpers this file shares.

use std::path::{Path, PathBuf};

use crate::sweep_cli::{PROJECTILE, num, read_csv, sweep, write};
use crate::util::ricochet;

/// The asteroids scenario with its gravity's y set to `g`.
fn asteroids_with_gravity(dir: &Path, g: &str) -> PathBuf {
    let text = std::fs::read_to_string(crate::util::root().join("scenarios/asteroids.toml"))
        .unwrap()
        .replace("gravity = [0, 0]", &format!("gravity = [0, {g}]"));
    assert!(text.contains(&format!("gravity = [0, {g}]")));
    write(dir, &format!("asteroids-{g}.toml"), &text)
}

/// Issue #34: a combination that overflows was measured as a good row (position error NaN,
/// energy error 0, or at 1.7e307 even finite errors) and the sweep exited 0. It is stopped
/// where `ricochet run` stops the same scenario, said so in its row, the summary and on
/// stderr, not measured, and the sweep fails (exit code 1) after writing the other rows.
#[test]
fn an_overflowing_combination_is_stopped_where_run_stops_and_fails_the_sweep() {
    let dir = tempfile::tempdir().unwrap();
    let file = crate::util::root().join("scenarios/asteroids.toml");
    let csv = dir.path().join("o.csv");
    let out = ricochet(
        &[
            "sweep",
            file.to_str().unwrap(),
            "--set",
            "world.gravity.y=0,1.7e307,1.79e308",
            "--repeat",
            "0",
            "--csv",
            csv.to_str().unwrap(),
        ],
        b"",
    );
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert_eq!(out.status.code(), Some(1), "{stdout}{stderr}");
    let rows = read_csv(&csv);
    assert_eq!(rows.len(), 3);
    // Gravity 0 is the file's own: the reference's run, no error, not overflowed.
    assert_eq!(num(&rows[0], "position_max"), 0.0);
    assert_eq!(rows[0]["overflowed_at_frame"], "");
    for (row, g) in rows[1..].iter().zip(["1.7e307", "1.79e308"]) {
        // What `ricochet run` says of the same scenario: "frame N: WHAT; the simulation
        // overflowed".
        let alone = asteroids_with_gravity(dir.path(), g);
        let log = dir.path().join(format!("{g}.mcap"));
        let run = ricochet(
            &["run", alone.to_str().unwrap(), "-o", log.to_str().unwrap()],
            b"",
        );
        assert_eq!(run.status.code(), Some(1));
        let said = String::from_utf8_lossy(&run.stderr);
        let said = said
            .split("error: ")
            .nth(1)
            .and_then(|s| s.split("; the simulation overflowed").next())
            .unwrap_or_else(|| panic!("run: {said}"));
        let frame = said
            .strip_prefix("frame ")
            .and_then(|s| s.split(':').next())
            .unwrap();
        assert!(
            stderr.contains(&format!(
                "with world.gravity.y={g}: {said}; the simulation overflowed"
            )),
            "{g}: run says {said:?}; sweep: {stderr}"
        );
        assert_eq!(row["overflowed_at_frame"], frame, "{g}");
        for measure in ["position_max", "energy_error", "energy_drift", "digest"] {
            assert_eq!(row[measure], "", "{g}: {measure} measured");
        }
        let line = stdout
            .lines()
            .find(|l| l.starts_with(&format!("world.gravity.y={g} ")))
            .unwrap();
        assert!(
            line.contains(&format!("overflowed at frame {frame}")),
            "{line}"
        );
    }
    let summary = stdout.lines().find(|l| l.starts_with("sweep:")).unwrap();
    assert!(summary.contains("no position error"), "{summary}");
    assert!(summary.contains("2 overflowed, not measured"), "{summary}");

    // A reference that overflows leaves nothing to measure against: nothing is written.
    let csv = dir.path().join("r.csv");
    let out = ricochet(
        &[
            "sweep",
            file.to_str().unwrap(),
            "--set",
            "world.gravity.y=0",
            "--reference",
            "world.gravity.y=1.79e308",
            "--repeat",
            "0",
            "--csv",
            csv.to_str().unwrap(),
        ],
        b"",
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("the reference (world.gravity.y=1.79e308): frame 1:"),
        "{stderr}"
    );
    assert!(!csv.exists() && !csv.with_extension("svg").exists());
}

/// A comma-separated list of `n` masses.
fn masses(n: usize) -> String {
    (1..=n).map(|m| m.to_string()).collect::<Vec<_>>().join(",")
}

/// Issue #34: no cap on the combinations (8,000,000 kept every scenario before the first
/// run, then aborted). Over 100,000 is refused by name before anything runs, and a sweep
/// under it builds a combination's scenario only when it runs: `--item` of the last of
/// 90,000 needs no more memory than a small sweep (all of them loaded ahead took ~300 MB).
#[test]
fn too_many_combinations_are_refused_and_none_are_built_ahead() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "projectile.toml", PROJECTILE);
    let (a, b) = (
        format!("bodies.ball.mass={}", masses(400)),
        format!("world.gravity.y={}", masses(251)),
    );
    // 400 × 251 = 100,400.
    let (code, _, stderr) = sweep(dir.path(), &file, &["--set", &a, "--set", &b], "c.csv");
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("too many combinations: 400 × 251 = 100400, more than the 100000"),
        "{stderr}"
    );
    assert!(!dir.path().join("c.csv").exists());

    // 300 × 300 = 90,000: the last one alone, in the memory of a small sweep.
    let g = format!("world.gravity.y={}", masses(300));
    let m = format!("bodies.ball.mass={}", masses(300));
    let out = under_memory_limit(&[
        "sweep",
        file.to_str().unwrap(),
        "--set",
        &m,
        "--set",
        &g,
        "--repeat",
        "0",
        "--item",
        "89999",
    ]);
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    let line: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(line["row"]["values"][0], "300");
    assert_eq!(line["row"]["values"][1], "300");
}

/// Runs the binary under an address-space limit of 60 MB (`ulimit -v`): a small sweep
/// runs in about 21 MB of resident memory and needs 20 to 40 MB of address space.
fn under_memory_limit(args: &[&str]) -> std::process::Output {
    let mut command = std::process::Command::new("sh");
    command
        .arg("-c")
        .arg("ulimit -v 60000 && exec \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_ricochet"))
        .args(args)
        .current_dir(crate::util::root())
        .stdin(std::process::Stdio::null());
    command.output().unwrap()
}

/// Issue #34: every frame's sample was kept (`--set frames=100000000` aborted at once). A
/// run of 200,000 frames and its reference of as many (~100 MB of samples kept) run in a
/// 60 MB address space, and the run is the reference's own: every frame compared, no error.
#[test]
fn memory_is_flat_in_the_frame_count() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "projectile.toml", PROJECTILE);
    let csv = dir.path().join("f.csv");
    let out = under_memory_limit(&[
        "sweep",
        file.to_str().unwrap(),
        "--set",
        "frames=200000",
        "--reference",
        "frames=200000",
        "--repeat",
        "0",
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    let rows = read_csv(&csv);
    assert_eq!(num(&rows[0], "matched_frames"), 200_001.0);
    assert_eq!(num(&rows[0], "position_max"), 0.0);
    assert_eq!(num(&rows[0], "energy_error"), 0.0);
}

/// Issue #34: `--csv X --svg X` and `--csv X.svg` lost the CSV, `--csv game.toml`
/// overwrote the scenario, a device or FIFO was replaced by a regular file. Each is refused
/// before any run (exit code 2) and leaves every file as it was.
#[test]
fn outputs_onto_each_other_the_scenario_or_a_fifo_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "projectile.toml", PROJECTILE);
    let path = |n: &str| dir.path().join(n).to_str().unwrap().to_owned();
    let flag = |f: &str| f.to_owned();
    let fifo = path("fifo");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap();
    assert!(made.success());
    let set = ["--set", "world.dt=1/32,1/64"];
    for (outputs, says) in [
        (
            vec![flag("--csv"), path("x"), flag("--svg"), path("x")],
            "same file",
        ),
        (vec![flag("--csv"), path("x.svg")], "same file"),
        (
            vec![flag("--csv"), path("projectile.toml")],
            "an input of this run",
        ),
        (
            vec![flag("--csv"), path("y.csv"), flag("--svg"), fifo.clone()],
            "not a regular file",
        ),
        (vec![flag("--csv"), fifo.clone()], "not a regular file"),
    ] {
        let mut args = vec!["sweep", file.to_str().unwrap()];
        args.extend(set);
        args.extend(outputs.iter().map(String::as_str));
        let out = ricochet(&args, b"");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{outputs:?}: {stderr}");
        assert!(stderr.contains(says), "{outputs:?}: {stderr}");
    }
    assert_eq!(std::fs::read_to_string(&file).unwrap(), PROJECTILE);
    use std::os::unix::fs::FileTypeExt;
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    let mut left: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(left, ["fifo", "projectile.toml"]);
}

/// Issue #34: when the SVG could not be written (a full disk) after the CSV was, the new
/// CSV sat beside the previous run's SVG. The pair is written all or nothing: with the
/// file size limited to 1 KB (`ulimit -f 2`, 512-byte blocks in a POSIX sh; SIGXFSZ
/// ignored so the write fails with EFBIG), the CSV (~440 bytes) fits and the SVG (~2.4
/// KB) does not, and both previous files are left as they were.
#[test]
fn a_failed_svg_write_leaves_both_previous_files() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "projectile.toml", PROJECTILE);
    let (csv, svg) = (dir.path().join("w.csv"), dir.path().join("w.svg"));
    std::fs::write(&csv, "old csv").unwrap();
    std::fs::write(&svg, "old svg").unwrap();
    let out = std::process::Command::new("sh")
        .arg("-c")
        .arg("trap '' XFSZ; ulimit -f 2 && exec \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_ricochet"))
        .args([
            "sweep",
            file.to_str().unwrap(),
            "--set",
            "world.dt=1/32,1/64",
            "--repeat",
            "0",
            "--csv",
            csv.to_str().unwrap(),
        ])
        .stdin(std::process::Stdio::null())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("w.svg"), "{stderr}");
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), "old csv");
    assert_eq!(std::fs::read_to_string(&svg).unwrap(), "old svg");
    let left = std::fs::read_dir(dir.path()).unwrap().count();
    assert_eq!(left, 3, "a temporary file was left");
}
