//! A scenario of 100,000 bodies is checked in memory proportional to its bodies (issue 11:
//! a 50 MB file took 2.45 GB). The child runs under a data-segment limit (`ulimit -d`, which
//! counts the heap and every private mapping) of 1 KiB per body plus 16 MiB: over it, an
//! allocation fails and the process aborts, so the test fails.

use std::fmt::Write as _;
use std::process::Command;

const BODIES: u64 = 100_000;

#[test]
fn a_large_scenario_checks_in_a_kilobyte_a_body() {
    let mut text = String::from("layers = [\"rock\"]\n");
    let mut rng = ricochet_scenes::Rng::new(11);
    for _ in 0..BODIES {
        let (x, y) = (rng.range(-1e5, 1e5), rng.range(-1e5, 1e5));
        writeln!(
            text,
            "[[bodies]]\nlayer = \"rock\"\nshape = {{ kind = \"circle\", radius = 1 }}\n\
             position = [{x:.3}, {y:.3}]"
        )
        .unwrap();
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("large.toml");
    std::fs::write(&path, &text).unwrap();
    let limit_kib = BODIES + 16 * 1024;
    let out = Command::new("sh")
        .args([
            "-c",
            "ulimit -d \"$2\" && exec \"$0\" check \"$1\"",
            env!("CARGO_BIN_EXE_ricochet"),
            path.to_str().unwrap(),
            &limit_kib.to_string(),
        ])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "check under {limit_kib} KiB failed: {:?} {}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains(&format!("{BODIES} bodies")), "{stdout}");
}
