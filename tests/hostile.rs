//! The binary against a hostile environment: standard output and error on `/dev/full`,
//! pipes closed early, signals in the middle of a run, output files that already exist or are
//! the input, names with terminal escapes, values that overflow. Every test checks the exit
//! code, the message, that nothing panicked, and what is left on disk. The signals are in
//! `hostile/signals.rs`; `diff` against damaged, foreign, huge and piped logs is in
//! `hostile_diff.rs`, with these helpers.

use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use ricochet_log::read_log_file;

use crate::util::{data, root};

mod signals;

/// The binary, run from the project root.
pub(crate) fn ricochet() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_ricochet"));
    c.current_dir(root()).stdin(Stdio::null());
    c
}

/// `/dev/full`: every write fails with "No space left on device".
fn full() -> Stdio {
    File::options()
        .write(true)
        .open("/dev/full")
        .expect("/dev/full exists")
        .into()
}

/// Exit code 101 is a Rust panic; the message says so when stderr works.
pub(crate) fn assert_no_panic(what: &str, o: &Output) {
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_ne!(o.status.code(), Some(101), "{what} panicked: {stderr}");
    assert!(!stderr.contains("panicked"), "{what} panicked: {stderr}");
}

/// Records `scenario` for `frames` frames into `out` (must succeed).
pub(crate) fn record(scenario: &str, frames: u64, out: &Path) {
    let o = ricochet()
        .args(["run", scenario, "--frames", &frames.to_string(), "-o"])
        .arg(out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// Two short logs that differ (600 and 10 frames), made once per test.
pub(crate) fn two_logs(dir: &Path) -> (PathBuf, PathBuf) {
    let (a, b) = (dir.join("a.mcap"), dir.join("b.mcap"));
    record("scenarios/asteroids.toml", 600, &a);
    record("scenarios/asteroids.toml", 10, &b);
    (a, b)
}

pub(crate) fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn a_full_stdout_is_an_error_with_a_message_for_every_subcommand() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = two_logs(dir.path());
    let cases_file = data("collision-cases.json");
    let cases: [(&[&str], i32); 7] = [
        (&["check", "scenarios/asteroids.toml"], 1),
        (&["dump", s(&a)], 2),
        (&["diff", s(&a), s(&b)], 2),
        (&["diff", "--json", s(&a), s(&b)], 2),
        (&["diff", s(&a), s(&a)], 2),
        (&["collide", s(&cases_file)], 1),
        (&["validate", "scenarios/shapes.toml", "--frames", "5"], 1),
    ];
    for (args, code) in cases {
        let o = ricochet().args(args).stdout(full()).output().unwrap();
        assert_no_panic(&format!("{args:?}"), &o);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(code), "{args:?}: {stderr}");
        assert!(
            stderr.contains("cannot write to standard output: No space left on device"),
            "{args:?}: {stderr}"
        );
    }
}

#[test]
fn a_full_stderr_is_an_exit_code_not_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let (a, _) = two_logs(dir.path());
    let out = dir.path().join("run.mcap");
    let bad = data("bad-scenarios/clockwise-polygon.toml");
    // (arguments, exit code): error paths keep their code; a lost run summary is exit 1, but
    // the log itself is complete.
    let cases: [(&[&str], i32); 7] = [
        (
            &[
                "run",
                "scenarios/asteroids.toml",
                "--frames",
                "20",
                "-o",
                s(&out),
            ],
            1,
        ),
        (&["check", "no/such/scenario.toml"], 2),
        (&["check", s(&bad)], 2),
        (&["collide", "no/such/cases.json"], 2),
        (&["collide", "-"], 2),
        (&["diff", s(&a), "no/such/log.mcap"], 2),
        (&["run", "no/such/scenario.toml", "-o", s(&out)], 2),
    ];
    for (args, code) in cases {
        let o = ricochet()
            .args(args)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(full())
            .spawn()
            .and_then(|mut c| {
                // `collide -` reads a bad case from stdin.
                use std::io::Write;
                let mut stdin = c.stdin.take().unwrap();
                let _ = stdin.write_all(b"{\"id\": 1}\n");
                drop(stdin);
                c.wait_with_output()
            })
            .unwrap();
        assert_no_panic(&format!("{args:?}"), &o);
        assert_eq!(o.status.code(), Some(code), "{args:?}");
        assert!(o.stdout.is_empty(), "{args:?}");
    }
    let log = read_log_file(&out).expect("the run's log is complete even without a summary");
    assert_eq!(log.iter().filter(|m| m.topic == "/stats").count(), 21);
}

/// Spawns `args` with stdout piped, reads `lines` lines, closes the pipe, and waits.
fn close_after(args: &[&str], lines: usize) -> (Output, Vec<String>) {
    let mut child = ricochet()
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut read = Vec::new();
    {
        let mut stdout = BufReader::new(child.stdout.take().unwrap());
        for _ in 0..lines {
            let mut line = String::new();
            stdout.read_line(&mut line).unwrap();
            read.push(line);
        }
        // Dropped here: the read end is closed, as `| head -N` does.
    }
    (child.wait_with_output().unwrap(), read)
}

#[test]
fn a_closed_pipe_ends_quietly_with_the_commands_own_exit_code() {
    let cases = data("collision-cases.json");
    // 3000 lines are far more than a pipe holds: collide meets the closed pipe mid-way.
    let (o, lines) = close_after(&["collide", s(&cases)], 1);
    assert_no_panic("collide | head -1", &o);
    assert_eq!(o.status.code(), Some(0));
    assert!(
        o.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(lines[0].starts_with("{\"id\":0,"), "{lines:?}");

    // Closed before the first write: the verdict of `diff` is still its exit code.
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = two_logs(dir.path());
    for (args, code) in [
        (vec!["diff", s(&a), s(&b)], 1),
        (vec!["diff", "--json", s(&a), s(&a)], 0),
        (vec!["check", "scenarios/asteroids.toml"], 0),
        (
            vec!["validate", "scenarios/shapes.toml", "--frames", "5"],
            0,
        ),
    ] {
        let (o, _) = close_after(&args, 0);
        assert_no_panic(&format!("{args:?}"), &o);
        assert_eq!(o.status.code(), Some(code), "{args:?}");
        assert!(
            o.stderr.is_empty(),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
}

/// The hidden temporary files a run leaves in `dir` (`.NAME.XXXXXX.tmp`).
fn temp_files(dir: &Path) -> Vec<PathBuf> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "tmp"))
        .collect()
}

#[test]
fn run_refuses_to_write_its_log_over_its_scenario_or_to_a_file_named_dash() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = dir.path().join("x.toml");
    std::fs::copy(root().join("scenarios/asteroids.toml"), &scenario).unwrap();
    let text = std::fs::read(&scenario).unwrap();
    let link = dir.path().join("link.mcap");
    std::os::unix::fs::symlink(&scenario, &link).unwrap();
    let cwd_name = dir.path().join(".").join("x.toml");
    for output in [&scenario, &link, &cwd_name] {
        let o = ricochet()
            .args(["run", s(&scenario), "-o", s(output)])
            .output()
            .unwrap();
        assert_no_panic("run x.toml -o x.toml", &o);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{stderr}");
        assert!(
            stderr.contains("that is the scenario being run"),
            "{stderr}"
        );
        assert_eq!(
            std::fs::read(&scenario).unwrap(),
            text,
            "the scenario is intact"
        );
    }
    let o = ricochet()
        .args(["run", s(&scenario), "-o", "-"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert_no_panic("run -o -", &o);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("standard output"));
    assert!(o.stdout.is_empty());
    assert!(!dir.path().join("-").exists(), "no file named -");
}

#[test]
fn names_with_terminal_escapes_are_printed_escaped() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(root().join("scenarios/asteroids.toml")).unwrap();
    let name_line = text
        .lines()
        .find(|l| l.starts_with("name"))
        .expect("the scenario has a name");
    let evil = text.replacen(
        name_line,
        r#"name = "evil\u001b[2J\u001b]0;pwned\u0007\nok""#,
        1,
    );
    let path = dir.path().join("evil.toml");
    std::fs::write(&path, evil).unwrap();
    let o = ricochet().args(["check", s(&path)]).output().unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let stdout = String::from_utf8(o.stdout).unwrap();
    assert!(
        !stdout.contains('\u{1b}') && !stdout.contains('\u{7}'),
        "{stdout:?}"
    );
    assert!(
        stdout.contains(r#""evil\u{1b}[2J\u{1b}]0;pwned\u{7}\nok""#),
        "{stdout:?}"
    );
    assert_eq!(stdout.lines().count(), 1, "{stdout:?}");
    let out = dir.path().join("evil.mcap");
    let o = ricochet()
        .args(["run", s(&path), "--frames", "2", "-o", s(&out)])
        .output()
        .unwrap();
    let stderr = String::from_utf8(o.stderr).unwrap();
    assert_eq!(o.status.code(), Some(0), "{stderr}");
    assert!(stderr.starts_with(r"evil\u{1b}[2J"), "{stderr:?}");
    assert!(!stderr.contains('\u{1b}'), "{stderr:?}");
}

#[test]
fn help_and_version_into_a_full_or_closed_stdout_do_not_panic() {
    for args in [&["--help"][..], &["--version"], &["run", "--help"]] {
        let o = ricochet().args(args).stdout(full()).output().unwrap();
        assert_no_panic(&format!("{args:?}"), &o);
        let (o, _) = close_after(args, 0);
        assert_no_panic(&format!("{args:?}"), &o);
    }
    // Reading stdin that is closed at once is fine too.
    let mut child = ricochet()
        .args(["collide", "-"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdin.take());
    let mut stdout = String::new();
    child
        .stdout
        .take()
        .unwrap()
        .read_to_string(&mut stdout)
        .unwrap();
    let o = child.wait_with_output().unwrap();
    assert_no_panic("collide - < /dev/null", &o);
    assert_eq!(o.status.code(), Some(0));
}

#[test]
fn run_writes_through_a_link_and_refuses_dev_null() {
    let dir = tempfile::tempdir().unwrap();
    // /dev/null is refused, and stays the device (a rename onto it would replace it with a
    // file; mcap's writer, seeking in it, panicked).
    let o = ricochet()
        .args([
            "run",
            "scenarios/shapes.toml",
            "--frames",
            "3",
            "-o",
            "/dev/null",
        ])
        .output()
        .unwrap();
    assert_no_panic("run -o /dev/null", &o);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("not a regular file"), "{stderr}");
    use std::os::unix::fs::FileTypeExt;
    assert!(
        std::fs::metadata("/dev/null")
            .unwrap()
            .file_type()
            .is_char_device()
    );
    // A link to a log: the log it points to is replaced, the link stays a link.
    let real = dir.path().join("real.mcap");
    std::fs::write(&real, b"old").unwrap();
    let link = dir.path().join("link.mcap");
    std::os::unix::fs::symlink(&real, &link).unwrap();
    record("scenarios/shapes.toml", 3, &link);
    assert!(
        std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert!(read_log_file(&real).is_ok());
    assert!(temp_files(dir.path()).is_empty());
}

/// Issue 11, item 2: gravity 1e308 times a scale of 1e308 overflows in the first step. The
/// run stops with an error naming the frame, the body and the field; the log it leaves is
/// complete and holds the frames before (frame 0 only); validate fails instead of passing.
#[test]
fn an_overflowing_body_stops_the_run_with_its_frame_body_and_field() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = dir.path().join("overflow.toml");
    std::fs::write(
        &scenario,
        "layers = [\"a\"]\nframes = 5\nworld.gravity = [0, -1e308]\n[[bodies]]\nname = \
         \"rock\"\nlayer = \"a\"\nshape = { kind = \"circle\", radius = 1 }\ngravity_scale = \
         1e308\n",
    )
    .unwrap();
    let log = dir.path().join("overflow.mcap");
    let o = ricochet()
        .args(["run", s(&scenario), "-o", s(&log)])
        .output()
        .unwrap();
    assert_no_panic("run", &o);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    for part in [
        "frame 1",
        "rock #0:0",
        "non-finite position",
        "-inf",
        "frames 0 to 0",
    ] {
        assert!(stderr.contains(part), "{part:?} in {stderr}");
    }
    let messages = read_log_file(&log).expect("the log is complete");
    let bodies: Vec<_> = messages.iter().filter(|m| m.topic == "/bodies").collect();
    assert_eq!(bodies.len(), 1, "frame 0 only");
    assert!(
        !serde_json::to_string(&bodies[0].data)
            .unwrap()
            .contains("null")
    );
    let o = ricochet()
        .args(["validate", s(&scenario)])
        .output()
        .unwrap();
    assert_no_panic("validate", &o);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("non-finite position"), "{stderr}");
    assert!(!String::from_utf8_lossy(&o.stdout).contains("PASS"));
}

/// Issue 11, item 9: `--frames` obeys the file's limit (100,000,000) and the log's time
/// limit (the last frame within 2^64 ns); nothing is written.
#[test]
fn frames_beyond_the_limits_are_refused_before_anything_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let slow = dir.path().join("slow.toml");
    // 2e9 s a step: 5 frames fit (1e19 ns), 10 do not (2e19 > 2^64).
    std::fs::write(&slow, "dt = 2e9\nframes = 5\nlayers = [\"a\"]\n").unwrap();
    let cases = [
        (
            "scenarios/asteroids.toml",
            "200000000",
            "must be 0 to 100000000",
        ),
        (s(&slow), "10", "2^64 ns"),
    ];
    for (scenario, frames, says) in cases {
        let log = dir.path().join("never.mcap");
        let o = ricochet()
            .args(["run", scenario, "--frames", frames, "-o", s(&log)])
            .output()
            .unwrap();
        assert_no_panic(scenario, &o);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{stderr}");
        assert!(stderr.contains(says), "{stderr}");
        assert!(!log.exists());
        assert!(temp_files(dir.path()).is_empty());
    }
    let ok = dir.path().join("slow.mcap");
    let o = ricochet()
        .args(["run", s(&slow), "-o", s(&ok)])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let last = read_log_file(&ok).unwrap().last().unwrap().log_time;
    assert_eq!(last, 5 * 2_000_000_000_000_000_000);
}

/// Issue 11, item 10: an output path that can't be written fails before the work (the
/// accuracy study takes seconds), with nothing printed to stdout.
#[test]
fn an_unwritable_output_fails_before_the_work() {
    for args in [
        ["accuracy", "--csv", "no/such/dir/a.csv"],
        ["bench", "--csv", "no/such/dir/b.csv"],
    ] {
        let o = ricochet().args(args).output().unwrap();
        assert_no_panic(args[0], &o);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{stderr}");
        assert!(stderr.contains("no/such/dir"), "{stderr}");
        assert!(o.stdout.is_empty(), "nothing was measured");
        assert!(
            !stderr.contains("accuracy: ") && !stderr.contains("bench: "),
            "{stderr}"
        );
    }
}
