//! `ricochet sweep` (issue #23): errors against exact math, located errors for bad keys and
//! values, a collider's false contacts predicted by geometry, the CSV, and shards.

use std::path::{Path, PathBuf};

use crate::util::ricochet;

/// A ball thrown under gravity g = -8 units/s², dt = 1/32 s, 64 frames (2 s). Powers of two
/// keep the arithmetic nearly exact. `mass` is on line 11 (the located-error test).
pub(crate) const PROJECTILE: &str = "\
name = \"projectile\"
dt = 0.03125
frames = 64
layers = [\"ball\"]

[world]
gravity = [0, -8]

[[bodies]]
name = \"ball\"
mass = 1
layer = \"ball\"
shape = { kind = \"circle\", radius = 0.1 }
position = [0, 1.5]
velocity = [3, 12]
";

/// A static square rock (half side 1) at the origin and a probe (radius 0.25) moving left
/// along y = 0 at 1 unit/s from x = 3.0625, dt = 1/8 s: `x_k = 3.0625 - k/8` at frame k.
const ROCK: &str = "\
name = \"rock\"
dt = 0.125
frames = 16
layers = [\"rock\", \"probe\"]

[[collide]]
a = \"probe\"
b = \"rock\"
response = \"report\"

[[bodies]]
name = \"rock\"
layer = \"rock\"
kind = \"static\"
shape = { kind = \"polygon\", vertices = [[-1, -1], [1, -1], [1, 1], [-1, 1]] }

[[bodies]]
name = \"probe\"
layer = \"probe\"
shape = { kind = \"circle\", radius = 0.25 }
position = [3.0625, 0]
velocity = [-1, 0]
";

pub(crate) fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// Runs a sweep with its CSV and SVG in `dir`; returns (exit code, stdout, stderr).
pub(crate) fn sweep(
    dir: &Path,
    scenario: &Path,
    extra: &[&str],
    csv: &str,
) -> (i32, String, String) {
    let csv = dir.join(csv);
    let mut args = vec![
        "sweep",
        scenario.to_str().unwrap(),
        "--repeat",
        "1",
        "--csv",
        csv.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let out = ricochet(&args, b"");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The CSV as a header and rows of named fields, checking every row has the header's
/// width (no field holds a comma here).
pub(crate) fn read_csv(path: &Path) -> Vec<std::collections::BTreeMap<String, String>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    lines
        .map(|l| {
            let fields: Vec<&str> = l.split(',').collect();
            assert_eq!(fields.len(), header.len(), "row {l:?} against {header:?}");
            header
                .iter()
                .zip(fields)
                .map(|(h, f)| ((*h).to_owned(), f.to_owned()))
                .collect()
        })
        .collect()
}

pub(crate) fn num(row: &std::collections::BTreeMap<String, String>, key: &str) -> f64 {
    row[key].parse().unwrap()
}

#[test]
fn projectile_error_halves_when_dt_halves() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "projectile.toml", PROJECTILE);
    let (code, stdout, stderr) = sweep(
        dir.path(),
        &file,
        &[
            "--set",
            "world.dt=1/32,1/64,1/128",
            "--reference",
            "world.dt=1/1024",
        ],
        "p.csv",
    );
    assert_eq!(code, 0, "{stdout}{stderr}");
    let rows = read_csv(&dir.path().join("p.csv"));
    assert_eq!(rows.len(), 3);
    // Semi-implicit Euler (v += g dt, then x += v dt) after n steps of dt: y = y0 + v0 t +
    // g t²/2 + g t dt/2, so a run at dt and the reference at dt_r differ by
    // |g| t (dt - dt_r) / 2, largest at the last time both reach, T = 2 s; x is exact.
    let (g, t, dt_r) = (8.0, 2.0, 1.0 / 1024.0);
    // Rounding: at most ~2 ulps of |y| <= 11 per step, 1024 reference steps: < 1e-11.
    let tolerance = 1e-9;
    let mut with_reference_error = Vec::new();
    for (row, dt) in rows.iter().zip([1.0 / 32.0, 1.0 / 64.0, 1.0 / 128.0]) {
        let expected = g * t * (dt - dt_r) / 2.0;
        let got = num(row, "position_max");
        assert!(
            (got - expected).abs() < tolerance,
            "dt {dt}: {got} against {expected}"
        );
        assert_eq!(row["worst_body"], "ball");
        assert_eq!(num(row, "matched_frames"), 2.0 / dt + 1.0);
        // The error against the exact answer: this one plus the reference's own, |g| T dt_r/2.
        with_reference_error.push(got + g * t * dt_r / 2.0);
    }
    for pair in with_reference_error.windows(2) {
        let ratio = pair[0] / pair[1];
        // Both errors are exact up to 2 · tolerance over errors of at least 0.0625.
        assert!((ratio - 2.0).abs() < 1e-7, "ratio {ratio}");
    }
}

#[test]
fn a_bad_key_or_value_exits_2_with_a_located_error() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "projectile.toml", PROJECTILE);
    let name = file.display().to_string();
    // A value the loader refuses: its line and column in the file.
    let (code, _, stderr) = sweep(
        dir.path(),
        &file,
        &["--set", "bodies.ball.mass=1,-1"],
        "a.csv",
    );
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains(&format!("{name}:11:")), "{stderr}");
    assert!(stderr.contains("bodies.ball.mass=-1"), "{stderr}");
    // A field the file's schema does not have: the loader names it.
    let (code, _, stderr) = sweep(
        dir.path(),
        &file,
        &["--set", "world.gravity_scale=1"],
        "a.csv",
    );
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains(&format!("{name}:")) && stderr.contains("gravity_scale"),
        "{stderr}"
    );
    // Paths and values that never reach the file.
    for (args, says) in [
        (
            &["--set", "bodies.bal.mass=2"][..],
            "no body named `bal` (its bodies: ball)",
        ),
        (&["--set", "world.dt=1/30,abc"][..], "`abc` is not a number"),
        (&["--set", "wold.dt=1/30"][..], "`wold.dt` is not a key"),
        (
            &["--set", "bodies.ball.shape=square:1"][..],
            "`square` is not a shape kind",
        ),
        (
            &["--set", "world.dt=1/30", "--shard", "3/3"][..],
            "--shard 3/3",
        ),
    ] {
        let (code, _, stderr) = sweep(dir.path(), &file, args, "a.csv");
        assert_eq!(code, 2, "{args:?}: {stderr}");
        assert!(stderr.contains(says), "{args:?}: {stderr}");
    }
    assert!(
        !dir.path().join("a.csv").exists(),
        "nothing written on bad input"
    );
}

#[test]
fn a_circle_collider_has_the_false_contacts_geometry_predicts() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "rock.toml", ROCK);
    let (code, stdout, stderr) = sweep(
        dir.path(),
        &file,
        &["--set", "bodies.rock.shape=file,circle:1.5,circle:0.9"],
        "r.csv",
    );
    assert_eq!(code, 0, "{stdout}{stderr}");
    let rows = read_csv(&dir.path().join("r.csv"));
    assert_eq!(rows.len(), 3);
    // The probe (x_k = 3.0625 - k/8, radius 0.25) overlaps the square (side x = 1) when
    // x_k < 1.25: frames 15 and 16. The circumscribing circle 1.5 when x_k < 1.75: frames
    // 11 to 16, so 4 false positives (11 to 14) and its touch begins 4 frames early; the
    // inscribed circle 0.9 when x_k < 1.15: frame 16 only, 1 false negative (15).
    let expect = [
        ("file", 0, 0, 0),
        ("circle:1.5", 4, 0, 1),
        ("circle:0.9", 0, 1, 1),
    ];
    for (row, (shape, fp, fn_, moved)) in rows.iter().zip(expect) {
        assert_eq!(row["bodies.rock.shape"], shape);
        assert_eq!(
            num(row, "false_positive_contacts"),
            f64::from(fp),
            "{shape}"
        );
        assert_eq!(
            num(row, "false_negative_contacts"),
            f64::from(fn_),
            "{shape}"
        );
        assert_eq!(num(row, "touch_moved"), f64::from(moved), "{shape}");
        assert_eq!(
            num(row, "position_max"),
            0.0,
            "report lets the probe through"
        );
    }
}

#[test]
fn the_csv_has_one_row_per_combination_and_shards_partition_them() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "rock.toml", ROCK);
    let set = [
        "--set",
        "world.dt=1/8,1/16",
        "--set",
        "bodies.rock.shape=file,circle:1.5,circle:0.9",
    ];
    let (code, stdout, stderr) = sweep(dir.path(), &file, &set, "all.csv");
    assert_eq!(code, 0, "{stdout}{stderr}");
    assert!(stdout.contains("sweep: 6 runs"), "{stdout}");
    let all = read_csv(&dir.path().join("all.csv"));
    let combos: Vec<(String, String)> = all
        .iter()
        .map(|r| (r["world.dt"].clone(), r["bodies.rock.shape"].clone()))
        .collect();
    let mut expected = Vec::new();
    for dt in ["1/8", "1/16"] {
        for s in ["file", "circle:1.5", "circle:0.9"] {
            expected.push((dt.to_owned(), s.to_owned()));
        }
    }
    assert_eq!(combos, expected);
    assert!(dir.path().join("all.svg").exists());

    let mut seen = Vec::new();
    for k in 0..3 {
        let shard = format!("{k}/3");
        let mut args = set.to_vec();
        args.extend(["--shard", shard.as_str()]);
        let csv = format!("s{k}.csv");
        let (code, _, stderr) = sweep(dir.path(), &file, &args, &csv);
        assert_eq!(code, 0, "{stderr}");
        for row in read_csv(&dir.path().join(&csv)) {
            let i: usize = row["index"].parse().unwrap();
            assert_eq!(i % 3, k);
            // The same run whichever shard runs it.
            assert_eq!(row["digest"], all[i]["digest"]);
            assert_eq!(
                row["false_positive_contacts"],
                all[i]["false_positive_contacts"]
            );
            seen.push(i);
        }
    }
    seen.sort_unstable();
    assert_eq!(seen, (0..6).collect::<Vec<_>>());
}

#[test]
fn a_touch_between_two_coarse_frames_belongs_to_the_frame_after_it() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "rock.toml", ROCK);
    let (code, stdout, stderr) = sweep(
        dir.path(),
        &file,
        &["--set", "world.dt=1/8", "--reference", "world.dt=1/24"],
        "t.csv",
    );
    assert_eq!(code, 0, "{stdout}{stderr}");
    let rows = read_csv(&dir.path().join("t.csv"));
    // At 1/24 s the probe (x = 3.0625 - t) first overlaps the square (x < 1.25) at frame 44,
    // t = 1.833 s; at 1/8 s at frame 15, t = 1.875 s: the first coarse frame at or after it,
    // so the begin has not moved. The coarse frames meet every 3rd fine one; both runs are
    // in contact at 45 and 48 (coarse 15 and 16) and apart at 42 (coarse 14).
    let row = &rows[0];
    assert_eq!(row["frames"], "16");
    assert_eq!(num(row, "matched_frames"), 17.0);
    assert_eq!(num(row, "touch_moved"), 0.0);
    assert_eq!(num(row, "touch_appear") + num(row, "touch_vanish"), 0.0);
    assert_eq!(num(row, "false_positive_contacts"), 0.0);
    assert_eq!(num(row, "false_negative_contacts"), 0.0);
}

/// `sweep --item` (what a cluster worker runs, issue #23): each combination's JSON line
/// holds the row the local sweep writes, the reference's is the run with the same values,
/// and an index past the end is named. Untimed (`--repeat 0`), two local sweeps write the
/// same bytes, which is what `sweep --cluster`'s merge is compared with in
/// scripts/cluster-ci.sh.
#[test]
fn sweep_items_print_the_rows_of_the_local_sweep() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "rock.toml", ROCK);
    let file = file.to_str().unwrap();
    let set = [
        "--set",
        "world.dt=1/8,1/16",
        "--set",
        "bodies.rock.shape=file,circle:0.9",
        "--repeat",
        "0",
    ];
    let local = |name: &str| {
        let csv = dir.path().join(name);
        let mut args = vec!["sweep", file];
        args.extend(set);
        args.extend(["--csv", csv.to_str().unwrap()]);
        let out = ricochet(&args, b"");
        assert_eq!(out.status.code(), Some(0), "{out:?}");
        csv
    };
    let (a, b) = (local("a.csv"), local("b.csv"));
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let svg = |p: &Path| std::fs::read(p.with_extension("svg")).unwrap();
    assert_eq!(svg(&a), svg(&b));
    let rows = read_csv(&a);
    assert_eq!(rows.len(), 4);

    let item = |which: &str| {
        let mut args = vec!["sweep", file];
        args.extend(set);
        args.extend(["--item", which]);
        let out = ricochet(&args, b"");
        let line: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
            panic!("{e}: {}", String::from_utf8_lossy(&out.stdout));
        });
        (out.status.code(), line)
    };
    for (i, row) in rows.iter().enumerate() {
        assert_eq!(row["step_us"], "", "untimed");
        let (code, line) = item(&i.to_string());
        assert_eq!(code, Some(0));
        assert_eq!(line["format"], 1);
        assert_eq!(line["reference"], false);
        let r = &line["row"];
        assert_eq!(r["index"], i);
        assert_eq!(r["values"][0], row["world.dt"].as_str());
        assert_eq!(r["values"][1], row["bodies.rock.shape"].as_str());
        assert_eq!(r["digest"], row["digest"].as_str());
        assert_eq!(r["step_seconds"], "NaN");
        let exact = |v: &serde_json::Value| v.as_str().unwrap().parse::<f64>().unwrap();
        assert_eq!(exact(&r["error"]["position_max"]), num(row, "position_max"));
        assert_eq!(
            r["error"]["false_positives"].as_u64().unwrap().to_string(),
            row["false_positive_contacts"]
        );
    }
    // The reference: the file at the finest dt, which is combination 2 (1/16, file).
    let (code, line) = item("reference");
    assert_eq!(code, Some(0));
    assert_eq!(line["reference"], true);
    assert_eq!(line["row"]["digest"], rows[2]["digest"].as_str());
    assert_eq!(rows[2]["position_max"], "0e0");

    let mut args = vec!["sweep", file];
    args.extend(set);
    args.extend(["--item", "4"]);
    let out = ricochet(&args, b"");
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("--item 4: the sweep has 4 combinations (0 to 3)"),
        "{stderr}"
    );
}
