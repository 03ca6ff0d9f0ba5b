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
    let o = ricochet(
        &[
            "run",
            scenario.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ],
        b"",
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}
