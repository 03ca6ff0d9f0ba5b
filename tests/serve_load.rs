//! `/load` under hostile paths (issue 20): a symlink inside the server's directory that
//! points out of it, and a file past the size cap, are refused with a named error; a file
//! inside loads. (Devices and FIFOs: the unit test in crates/serve/src/load_path.rs.)

use std::process::Command;

use serde_json::Value;

use crate::serve_client::*;

/// Calls `/load` with `scenario` on a server running in `dir`.
fn load_in(dir: &std::path::Path, scenario: &str) -> Result<Value, String> {
    let mut command = Command::new(env!("CARGO_BIN_EXE_ricochet"));
    command
        .args(["serve", "--bind", "127.0.0.1:0", "--paused"])
        .current_dir(dir);
    let server = serve_with(command);
    runtime().block_on(async {
        let (mut ws, _) = connect(&server.url, "foxglove.websocket.v1").await.unwrap();
        let _ = next_json(&mut ws).await;
        let _ = next_json(&mut ws).await;
        let services = any_json(&mut ws).await;
        assert_eq!(services["op"], "advertiseServices");
        let request = serde_json::json!({ "scenario": scenario }).to_string();
        call(&mut ws, &services, "/load", 1, &request).await
    })
}

// Issue 20: `/load` checked the path's text only, so a symlink inside the server's directory
// that points out of it loaded, and nothing capped the size read.
#[test]
fn load_refuses_a_symlink_out_of_its_directory_and_a_file_past_the_cap() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path().join("srv");
    std::fs::create_dir_all(root.join("d")).unwrap();
    let level = std::fs::read_to_string(crate::util::root().join("scenarios/level.toml")).unwrap();
    std::fs::write(dir.path().join("elsewhere.toml"), &level).unwrap();
    std::fs::write(root.join("d/in.toml"), &level).unwrap();
    std::os::unix::fs::symlink("../../elsewhere.toml", root.join("d/out.toml")).unwrap();
    let big = std::fs::File::create(root.join("big.toml")).unwrap();
    big.set_len((16 << 20) + 1).unwrap();
    // Inside, it loads.
    let answer = load_in(&root, "d/in.toml").unwrap();
    assert_eq!(answer["frame"], 0, "{answer}");
    let why = load_in(&root, "d/out.toml").unwrap_err();
    assert!(
        why.contains("d/out.toml") && why.contains("outside the server's directory"),
        "{why}"
    );
    let why = load_in(&root, "big.toml").unwrap_err();
    assert!(why.contains("larger than 16777216 bytes"), "{why}");
}
