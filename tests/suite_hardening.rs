//! `ricochet test` against hostile use (issue #34): `--keep` onto the goldens, one name in
//! two folders, a golden shared through `..`, FIFOs, a stopped item, a 250-byte name, a low
//! descriptor limit, files too large to read whole, and the goldens' mode.

use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use crate::util::{ricochet_in, root, suite_copy};

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// `ricochet ARGS` in `dir`, through `sh -c 'PREFIX; exec ricochet ARGS'` when `prefix` is
/// given (a `ulimit`), ended (and the test failed) if it runs past `limit`: a run that
/// waits forever fails the test instead of hanging it.
fn bounded(dir: &Path, prefix: Option<&str>, args: &[&str], limit: Duration) -> Output {
    let exe = env!("CARGO_BIN_EXE_ricochet");
    let mut command = match prefix {
        Some(p) => {
            let mut c = Command::new("sh");
            c.arg("-c")
                .arg(format!("{p} && exec \"$0\" \"$@\""))
                .arg(exe);
            c
        }
        None => Command::new(exe),
    };
    let mut child = command
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let deadline = Instant::now() + limit;
    while child.try_wait().unwrap().is_none() {
        if Instant::now() > deadline {
            let _ = child.kill();
            let o = child.wait_with_output().unwrap();
            panic!(
                "`ricochet {}` still running after {limit:?}: {}{}",
                args.join(" "),
                stdout(&o),
                stderr(&o)
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

const LIMIT: Duration = Duration::from_secs(60);

fn mkfifo(path: &Path) {
    let made = Command::new("mkfifo").arg(path).status().unwrap();
    assert!(made.success());
}

/// A scenario's text with `frames = N`.
fn with_frames(name: &str, frames: u64) -> String {
    std::fs::read_to_string(root().join("scenarios").join(name))
        .unwrap()
        .lines()
        .map(|l| {
            if l.starts_with("frames = ") {
                format!("frames = {frames}")
            } else {
                l.to_owned()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn suite_keep_onto_the_golden_folder_is_refused_and_the_golden_left_alone() {
    let dir = suite_copy();
    let path = dir.path().join("scenarios/asteroids.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("name = \"rock_a\""));
    std::fs::write(
        &path,
        text.replace("name = \"rock_a\"", "name = \"rock_z\""),
    )
    .unwrap();
    let golden = dir.path().join("recordings/asteroids.mcap");
    let shipped = std::fs::read(root().join("recordings/asteroids.mcap")).unwrap();
    std::os::unix::fs::symlink("recordings", dir.path().join("link")).unwrap();
    for keep in ["recordings", "./scenarios/../recordings/", "link"] {
        let o = ricochet_in(dir.path(), &["test", "scenarios", "--keep", keep]);
        assert_eq!(o.status.code(), Some(2), "--keep {keep}: {}", stdout(&o));
        assert!(
            stderr(&o).contains(&format!("--keep {keep} is the golden folder")),
            "{}",
            stderr(&o)
        );
        assert!(std::fs::read(&golden).unwrap() == shipped, "--keep {keep}");
    }
    // One item alone (as a cluster worker runs it), onto its own golden: an error line.
    for out in ["recordings", "link", "nowhere/../recordings"] {
        let o = ricochet_in(
            dir.path(),
            &["test", "--item", "scenarios/asteroids.toml", "--out", out],
        );
        assert_eq!(o.status.code(), Some(1), "--out {out}");
        assert!(
            stdout(&o).contains("the fresh log would replace the golden"),
            "{}",
            stdout(&o)
        );
        assert!(std::fs::read(&golden).unwrap() == shipped, "--out {out}");
    }
    // The renamed body is still found, against the golden.
    let o = ricochet_in(dir.path(), &["test", "scenarios/asteroids.toml"]);
    assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
    assert!(
        stdout(&o).contains("name \"rock_a\" → \"rock_z\""),
        "{}",
        stdout(&o)
    );
}

/// `g1/scenarios/level.toml` an asteroids scene, `g2/scenarios/level.toml` a platformer,
/// each with its own golden folder.
fn one_name_in_two_folders(dir: &Path) {
    for (g, from) in [("g1", "asteroids"), ("g2", "platformer")] {
        std::fs::create_dir_all(dir.join(g).join("scenarios")).unwrap();
        std::fs::create_dir_all(dir.join(g).join("recordings")).unwrap();
        std::fs::copy(
            root().join(format!("scenarios/{from}.toml")),
            dir.join(g).join("scenarios/level.toml"),
        )
        .unwrap();
    }
}

#[test]
fn suite_one_name_in_two_folders_is_each_judged_against_its_own_golden() {
    let dir = tempfile::tempdir().unwrap();
    one_name_in_two_folders(dir.path());
    let args = ["test", "g1/scenarios", "g2/scenarios", "-j", "2"];
    let o = ricochet_in(dir.path(), &[&args[..], &["--bless"]].concat());
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(
        stdout(&o),
        "g1/scenarios/level.toml: blessed (new)\ng2/scenarios/level.toml: blessed (new)\n\
         2 passed, 0 failed\n"
    );
    // Each golden is its own scenario's, as shipped.
    for (g, from) in [("g1", "asteroids"), ("g2", "platformer")] {
        for ext in ["mcap", "digest"] {
            assert!(
                std::fs::read(dir.path().join(format!("{g}/recordings/level.{ext}"))).unwrap()
                    == std::fs::read(root().join(format!("recordings/{from}.{ext}"))).unwrap(),
                "{g}/recordings/level.{ext}"
            );
        }
    }
    let o = ricochet_in(dir.path(), &args);
    assert_eq!(
        stdout(&o),
        "g1/scenarios/level.toml: ok\ng2/scenarios/level.toml: ok\n2 passed, 0 failed\n"
    );
    // Kept, the two would be one file: refused before any runs.
    let o = ricochet_in(dir.path(), &[&args[..], &["--keep", "fresh"]].concat());
    assert_eq!(o.status.code(), Some(2), "{}", stdout(&o));
    assert!(
        stderr(&o).contains("would both be kept as fresh/level.mcap"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn suite_a_golden_shared_through_dot_dot_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("s1")).unwrap();
    std::fs::create_dir_all(dir.path().join("s2/sub")).unwrap();
    std::fs::copy(
        root().join("scenarios/shapes.toml"),
        dir.path().join("s1/x.toml"),
    )
    .unwrap();
    std::fs::copy(
        root().join("scenarios/platformer.toml"),
        dir.path().join("s2/x.toml"),
    )
    .unwrap();
    // s1/x.toml's golden is recordings/x.mcap (beside s1); s2/x.toml's too (beside s2).
    let o = ricochet_in(
        dir.path(),
        &["test", "s1/x.toml", "s2/sub/../x.toml", "--bless"],
    );
    assert_eq!(o.status.code(), Some(2), "{}", stdout(&o));
    assert!(
        stderr(&o).contains("s1/x.toml and s2/sub/../x.toml would share the golden"),
        "{}",
        stderr(&o)
    );
    assert!(!dir.path().join("recordings").exists());
}

#[test]
fn suite_a_fifo_as_scenario_or_golden_is_a_named_error_not_a_wait() {
    let dir = suite_copy();
    mkfifo(&dir.path().join("fifo.toml"));
    let o = bounded(dir.path(), None, &["test", "fifo.toml"], LIMIT);
    assert_eq!(o.status.code(), Some(2), "{}", stdout(&o));
    assert!(
        stderr(&o).contains("fifo.toml: not a regular file"),
        "{}",
        stderr(&o)
    );
    let o = bounded(dir.path(), None, &["test", "--item", "fifo.toml"], LIMIT);
    assert_eq!(o.status.code(), Some(1));
    assert!(stdout(&o).contains("not a regular file"), "{}", stdout(&o));

    for ext in ["mcap", "digest"] {
        let golden = dir.path().join(format!("recordings/shapes.{ext}"));
        let kept = dir.path().join(format!("shapes.{ext}"));
        std::fs::rename(&golden, &kept).unwrap();
        mkfifo(&golden);
        for bless in [&[][..], &["--bless"][..]] {
            let args = [&["test", "scenarios/shapes.toml"][..], bless].concat();
            let o = bounded(dir.path(), None, &args, LIMIT);
            assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
            assert_eq!(
                stdout(&o),
                format!(
                    "scenarios/shapes.toml: error: the golden recordings/shapes.{ext}: not a \
                     regular file (a FIFO, a device, a socket or a folder)\n0 passed, 1 failed\n"
                )
            );
        }
        assert!(
            !std::fs::metadata(&golden).unwrap().is_file(),
            "left as it was"
        );
        std::fs::remove_file(&golden).unwrap();
        std::fs::rename(&kept, &golden).unwrap();
    }
}

/// The PIDs of `parent`'s children, from `/proc/PID/stat` (its 4th field).
fn children(parent: u32) -> Vec<u32> {
    let mut found = Vec::new();
    for entry in std::fs::read_dir("/proc").unwrap().flatten() {
        let Ok(pid) = entry.file_name().to_string_lossy().parse::<u32>() else {
            continue;
        };
        let Ok(stat) = std::fs::read_to_string(entry.path().join("stat")) else {
            continue;
        };
        // After the command's `(name)`, which may hold spaces: state, then ppid.
        let ppid = stat
            .rsplit_once(')')
            .and_then(|(_, rest)| rest.split_whitespace().nth(1))
            .and_then(|p| p.parse::<u32>().ok());
        if ppid == Some(parent) {
            found.push(pid);
        }
    }
    found
}

fn send(pid: u32, signal: &str) {
    let sent = Command::new("kill")
        .args([signal, &pid.to_string()])
        .status()
        .unwrap();
    assert!(sent.success());
}

#[test]
fn suite_sigterm_ends_a_run_whose_item_cannot_see_the_signal() {
    // One long item, which the test stops (SIGSTOP): a process that can't act on the
    // runner's SIGINT, as one blocked in a system call can't.
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("long")).unwrap();
    std::fs::write(
        dir.path().join("long/p1.toml"),
        with_frames("platformer.toml", 200_000),
    )
    .unwrap();
    let mut runner = Command::new(env!("CARGO_BIN_EXE_ricochet"))
        .args(["test", "long", "--golden", "golden", "--bless", "-j", "1"])
        .current_dir(dir.path())
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let deadline = Instant::now() + LIMIT;
    let item = loop {
        if let Some(&pid) = children(runner.id()).first() {
            break pid;
        }
        assert!(Instant::now() < deadline, "no item process started");
        std::thread::sleep(Duration::from_millis(20));
    };
    send(item, "-STOP");
    send(runner.id(), "-TERM");
    let deadline = Instant::now() + LIMIT;
    while runner.try_wait().unwrap().is_none() {
        if Instant::now() > deadline {
            let _ = runner.kill();
            send(item, "-KILL");
            panic!("SIGTERM did not end `ricochet test` within {LIMIT:?}");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let o = runner.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(130), "{}{}", stdout(&o), stderr(&o));
    let out = stdout(&o);
    assert!(
        out.starts_with("long/p1.toml: interrupted") && out.ends_with("\n0 passed, 1 failed\n"),
        "{out}"
    );
    assert!(!dir.path().join("golden").exists(), "no golden written");
}

#[test]
fn suite_a_250_byte_scenario_name_is_tested_blessed_and_kept() {
    let dir = tempfile::tempdir().unwrap();
    let name = "n".repeat(245);
    std::fs::create_dir_all(dir.path().join("long")).unwrap();
    std::fs::write(
        dir.path().join(format!("long/{name}.toml")),
        with_frames("shapes.toml", 600),
    )
    .unwrap();
    assert_eq!(format!("{name}.toml").len(), 250);
    let o = ricochet_in(dir.path(), &["test", "long", "--golden", "g", "--bless"]);
    assert_eq!(
        stdout(&o),
        format!("long/{name}.toml: blessed (new)\n1 passed, 0 failed\n")
    );
    let o = ricochet_in(
        dir.path(),
        &["test", "long", "--golden", "g", "--keep", "k"],
    );
    assert_eq!(
        stdout(&o),
        format!("long/{name}.toml: ok\n1 passed, 0 failed\n")
    );
    assert!(
        std::fs::read(dir.path().join(format!("k/{name}.mcap"))).unwrap()
            == std::fs::read(dir.path().join(format!("g/{name}.mcap"))).unwrap()
    );
    let left: Vec<_> = std::fs::read_dir(dir.path().join("k")).unwrap().collect();
    assert_eq!(left.len(), 1, "no scratch folder left: {left:?}");
    // 255 bytes, the most a file name may have: its golden NAME.digest could not be, which
    // its line says.
    std::fs::remove_dir_all(dir.path().join("long")).unwrap();
    std::fs::create_dir_all(dir.path().join("long")).unwrap();
    let name = "n".repeat(250);
    std::fs::write(
        dir.path().join(format!("long/{name}.toml")),
        with_frames("shapes.toml", 600),
    )
    .unwrap();
    let o = ricochet_in(dir.path(), &["test", "long", "--golden", "g", "--bless"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stdout(&o).contains("shorten it to 248 bytes at most"),
        "{}",
        stdout(&o)
    );
}

#[test]
fn suite_a_low_descriptor_limit_makes_items_wait_for_a_slot() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("many")).unwrap();
    let text = with_frames("shapes.toml", 600);
    let count = 40;
    for k in 0..count {
        std::fs::write(dir.path().join(format!("many/s{k:02}.toml")), &text).unwrap();
    }
    // 40 items at once would hold 80 pipes, past a limit of 64.
    let o = bounded(
        dir.path(),
        Some("ulimit -n 64"),
        &["test", "many", "--golden", "g", "--bless", "-j", "256"],
        Duration::from_secs(300),
    );
    let out = stdout(&o);
    assert_eq!(o.status.code(), Some(0), "{out}{}", stderr(&o));
    assert_eq!(out.matches(": blessed (new)\n").count(), count, "{out}");
}

#[test]
fn suite_a_scenario_over_the_cap_is_refused() {
    let dir = suite_copy();
    // The cap: 16 MiB, `serve`'s `/load` limit (README).
    let big = std::fs::File::create(dir.path().join("big.toml")).unwrap();
    big.set_len((16 << 20) + 1).unwrap();
    let o = ricochet_in(dir.path(), &["test", "big.toml"]);
    assert_eq!(
        stdout(&o),
        "big.toml: error: big.toml: larger than 16777216 bytes, the most a scenario may \
         have\n0 passed, 1 failed\n"
    );
}

#[test]
fn suite_a_huge_golden_is_compared_without_being_read_whole() {
    let dir = suite_copy();
    // An 8 GiB golden (sparse) under a 2 GB address-space limit: compared without being
    // read into memory.
    let golden = std::fs::File::create(dir.path().join("recordings/shapes.mcap")).unwrap();
    golden.set_len(8 << 30).unwrap();
    let o = bounded(
        dir.path(),
        Some("ulimit -v 2000000"),
        &["test", "scenarios/shapes.toml"],
        LIMIT,
    );
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stdout(&o).starts_with("scenarios/shapes.toml: differs: the golden log can't be compared"),
        "{}",
        stdout(&o)
    );
}

#[cfg(unix)]
#[test]
fn suite_goldens_are_created_with_the_umasks_mode() {
    use std::os::unix::fs::PermissionsExt;
    let dir = suite_copy();
    let o = ricochet_in(
        dir.path(),
        &[
            "test",
            "scenarios/shapes.toml",
            "--golden",
            "new",
            "--bless",
        ],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
    // The umask can be read only by setting it: compare with a file made the usual way.
    let usual = dir.path().join("usual");
    std::fs::File::create(&usual).unwrap();
    let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
    for ext in ["mcap", "digest"] {
        assert_eq!(
            format!("{:o}", mode(&dir.path().join(format!("new/shapes.{ext}")))),
            format!("{:o}", mode(&usual)),
            "new/shapes.{ext}"
        );
    }
}
