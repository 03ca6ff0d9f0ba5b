//! Signals in the middle of a run (`SIGINT`, `SIGTERM`, `SIGHUP`) finish the log; a killed
//! or size-limited run leaves the old log intact. Every wait bounded.

use super::*;

/// Waits for `child`, at most `limit`; kills it and fails past that.
fn wait_bounded(mut child: Child, limit: Duration) -> Output {
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > limit {
            let _ = child.kill();
            panic!("ricochet did not stop within {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

/// Starts a long run into `out` and waits until its temporary file holds `bytes` bytes.
fn start_long_run(out: &Path, bytes: u64) -> Child {
    let child = ricochet()
        .args([
            "run",
            "scenarios/asteroids.toml",
            "--frames",
            "1000000",
            "-o",
        ])
        .arg(out)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    let dir = out.parent().unwrap();
    while start.elapsed() < Duration::from_secs(60) {
        let size = temp_files(dir)
            .iter()
            .filter_map(|p| std::fs::metadata(p).ok())
            .map(|m| m.len())
            .max()
            .unwrap_or(0);
        if size >= bytes {
            break;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    child
}

fn kill(child: &Child, signal: &str) {
    let status = Command::new("kill")
        .args([&format!("-{signal}"), &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
}

#[test]
fn sigint_sigterm_and_sighup_at_random_frames_finish_the_log() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("long.mcap");
    // An old, good log is there first: it must be replaced by a complete one, never cut.
    record("scenarios/asteroids.toml", 30, &out);
    let old = std::fs::read(&out).unwrap();
    // Pseudo-random sizes (hence frames) at which to stop, different for each signal.
    let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
    for signal in ["INT", "TERM", "HUP", "INT", "TERM", "HUP"] {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        let bytes = 1_000 + x % 400_000;
        let child = start_long_run(&out, bytes);
        kill(&child, signal);
        let o = wait_bounded(child, Duration::from_secs(60));
        assert_no_panic(signal, &o);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(0), "SIG{signal}: {stderr}");
        assert!(stderr.contains("interrupted"), "SIG{signal}: {stderr}");
        let log =
            read_log_file(&out).unwrap_or_else(|e| panic!("SIG{signal} after {bytes} bytes: {e}"));
        assert!(
            log.iter().any(|m| m.topic == "/stats"),
            "SIG{signal}: frames were written"
        );
        assert_ne!(std::fs::read(&out).unwrap(), old, "SIG{signal}");
        assert!(temp_files(dir.path()).is_empty(), "SIG{signal}");
        // And `ricochet diff` reads it.
        let d = ricochet()
            .args(["diff", s(&out), s(&out)])
            .output()
            .unwrap();
        assert_eq!(
            d.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&d.stderr)
        );
    }
}

#[test]
fn a_killed_or_size_limited_run_leaves_the_old_log_intact() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("keep.mcap");
    record("scenarios/asteroids.toml", 30, &out);
    let old = std::fs::read(&out).unwrap();

    // SIGKILL can't be caught: the old log stays, the temporary file is left behind.
    let child = start_long_run(&out, 100_000);
    kill(&child, "KILL");
    let o = wait_bounded(child, Duration::from_secs(30));
    assert_eq!(o.status.code(), None, "killed by a signal");
    assert_eq!(
        std::fs::read(&out).unwrap(),
        old,
        "SIGKILL: the old log is intact"
    );
    for t in temp_files(dir.path()) {
        std::fs::remove_file(t).unwrap();
    }

    // A file size limit (`ulimit -f`, 64 KiB) stops the run: SIGXFSZ, or a write error.
    let o = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -f 128; exec '{}' run scenarios/asteroids.toml --frames 100000 -o '{}'",
            env!("CARGO_BIN_EXE_ricochet"),
            s(&out)
        ))
        .current_dir(root())
        .output()
        .unwrap();
    assert_no_panic("ulimit -f", &o);
    assert_ne!(o.status.code(), Some(0));
    assert_eq!(
        std::fs::read(&out).unwrap(),
        old,
        "ulimit -f: the old log is intact"
    );
    assert!(read_log_file(&out).is_ok());
}
