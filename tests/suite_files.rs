//! `ricochet test` and the files around it: a JUnit report that an XML parser reads whatever
//! the names and messages hold, a `--junit` that would replace a device or one of the run's
//! own files refused before any item, a golden digest with CRLF line ends, and scenario
//! paths that start with `-`; the report created with the umask's mode.

use std::path::Path;
use std::process::{Command, Output};

use crate::util::{ricochet_in, suite_copy};

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Python's minidom (expat, a conforming XML 1.0 parser) on `path`: each testcase's name
/// and each failure's message, one a line, or the parser's error.
fn minidom(path: &Path) -> Output {
    let script = "import sys, xml.dom.minidom as m\n\
        d = m.parse(sys.argv[1])\n\
        for c in d.getElementsByTagName('testcase'): print('case', c.getAttribute('name'))\n\
        for f in d.getElementsByTagName('failure'): print('failure', f.getAttribute('message'))\n";
    Command::new("python3")
        .args(["-c", script])
        .arg(path)
        .env("PYTHONIOENCODING", "utf-8")
        .output()
        .expect("python3 runs (CI installs it)")
}

#[test]
fn suite_junit_with_noncharacters_in_names_and_messages_parses() {
    let dir = suite_copy();
    let scenarios = dir.path().join("scenarios");
    for entry in std::fs::read_dir(&scenarios).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            // `maps/`: the Tiled level's map.
            std::fs::remove_dir_all(path).unwrap();
        } else {
            std::fs::remove_file(path).unwrap();
        }
    }
    // U+FFFE and U+FFFF are valid UTF-8 and legal in a file name, and XML 1.0 forbids them.
    std::fs::copy(
        crate::util::root().join("scenarios/shapes.toml"),
        scenarios.join("a\u{fffe}b.toml"),
    )
    .unwrap();
    // Does not load: the message names the file, U+FFFF and all; \u{1} is a control.
    std::fs::write(scenarios.join("c\u{ffff}\u{1}.toml"), "frames = \"x\"\n").unwrap();
    let o = ricochet_in(dir.path(), &["test", "--junit", "report.xml"]);
    assert_eq!(o.status.code(), Some(1), "{}{}", stdout(&o), stderr(&o));
    let parsed = minidom(&dir.path().join("report.xml"));
    let xml = std::fs::read_to_string(dir.path().join("report.xml")).unwrap();
    assert!(parsed.status.success(), "{}\n{xml}", stderr(&parsed));
    let lines = stdout(&parsed);
    // The characters XML can't hold are written as on the terminal, as Rust escapes.
    assert!(lines.contains("case a\\u{fffe}b\n"), "{lines}");
    assert!(lines.contains("case c\\u{ffff}\\u{1}\n"), "{lines}");
    assert!(
        lines.contains("failure error: scenarios/c\\u{ffff}\\u{1}.toml:1:"),
        "{lines}"
    );
}

/// A device node like `/dev/null` (character device 1:3) made in `dir` when this is root,
/// else a FIFO: not a regular file either, and a rename onto it would replace it all the
/// same. Never the machine's own `/dev/null`, which a regression would replace.
fn special_file(dir: &Path) -> (std::path::PathBuf, bool) {
    let null = dir.join("null");
    let made = Command::new("mknod")
        .arg(&null)
        .args(["c", "1", "3"])
        .status()
        .is_ok_and(|s| s.success());
    if made {
        return (null, true);
    }
    let fifo = dir.join("fifo");
    let made = Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(made.success(), "mkfifo works");
    (fifo, false)
}

#[test]
fn suite_junit_to_a_device_is_refused_before_any_item() {
    use std::os::unix::fs::FileTypeExt;
    let dir = suite_copy();
    let (device, is_char) = special_file(dir.path());
    let path = device.display().to_string();
    let o = ricochet_in(
        dir.path(),
        &["test", "scenarios/level.toml", "--junit", &path],
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains(&format!("--junit {path}")),
        "{}",
        stderr(&o)
    );
    assert!(stderr(&o).contains("not a regular file"), "{}", stderr(&o));
    assert!(o.stdout.is_empty(), "no item ran: {}", stdout(&o));
    let kind = std::fs::symlink_metadata(&device).unwrap().file_type();
    assert!(
        if is_char {
            kind.is_char_device()
        } else {
            kind.is_fifo()
        },
        "{path} is still what it was"
    );
}

#[test]
fn suite_junit_onto_a_scenario_or_a_golden_is_refused_and_leaves_it_whole() {
    let dir = suite_copy();
    for (target, args) in [
        ("scenarios/level.toml", &["test"][..]),
        (
            "scenarios/level.toml",
            &["test", "scenarios/level.toml"][..],
        ),
        ("recordings/level.mcap", &["test"][..]),
        ("recordings/level.digest", &["test", "scenarios"][..]),
        (
            "goldens/level.digest",
            &["test", "scenarios/level.toml", "--golden", "goldens"][..],
        ),
    ] {
        if let Some(folder) = Path::new(target).parent() {
            std::fs::create_dir_all(dir.path().join(folder)).unwrap();
        }
        let path = dir.path().join(target);
        if !path.exists() {
            std::fs::write(&path, b"frames 1\n").unwrap();
        }
        let before = std::fs::read(&path).unwrap();
        let mut args = args.to_vec();
        args.extend(["--junit", target]);
        let o = ricochet_in(dir.path(), &args);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
        assert!(
            e.contains(&format!("--junit {target} is ")) && e.contains("an input of this run"),
            "{args:?}: {e}"
        );
        assert!(o.stdout.is_empty(), "{args:?}: no item ran: {}", stdout(&o));
        assert_eq!(std::fs::read(&path).unwrap(), before, "{target} untouched");
    }
}

#[test]
fn suite_junit_onto_a_kept_log_is_refused() {
    let dir = suite_copy();
    // The folder of an earlier run's kept logs; this run's log is not there yet.
    std::fs::create_dir(dir.path().join("kept")).unwrap();
    let o = ricochet_in(
        dir.path(),
        &[
            "test",
            "scenarios/level.toml",
            "--keep",
            "kept",
            "--junit",
            "kept/../kept/level.mcap",
        ],
    );
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains("is where --keep keeps the fresh log of scenarios/level.toml"),
        "{e}"
    );
    assert!(o.stdout.is_empty(), "no item ran: {}", stdout(&o));
}

#[test]
fn suite_a_golden_digest_with_crlf_line_ends_is_the_same_digest() {
    let dir = suite_copy();
    let digest = dir.path().join("recordings/level.digest");
    let text = std::fs::read_to_string(&digest).unwrap();
    assert!(!text.contains('\r'));
    std::fs::write(&digest, text.replace('\n', "\r\n")).unwrap();
    let o = ricochet_in(dir.path(), &["test", "scenarios/level.toml"]);
    assert_eq!(
        stdout(&o),
        "scenarios/level.toml: ok\n1 passed, 0 failed\n",
        "{}",
        stderr(&o)
    );
    assert_eq!(o.status.code(), Some(0));
}

#[test]
fn suite_scenario_and_folder_paths_that_start_with_a_dash_are_paths() {
    let dir = suite_copy();
    let d = dir.path();
    // shapes.toml as `-a.toml`, with shapes' goldens as its own: `ok` only if it ran.
    std::fs::copy(d.join("scenarios/shapes.toml"), d.join("-a.toml")).unwrap();
    std::fs::create_dir(d.join("-g")).unwrap();
    for ext in ["mcap", "digest"] {
        std::fs::copy(
            d.join(format!("recordings/shapes.{ext}")),
            d.join(format!("-g/-a.{ext}")),
        )
        .unwrap();
    }
    let o = ricochet_in(
        d,
        &["test", "--golden=-g", "--keep=-fresh", "--", "-a.toml"],
    );
    assert_eq!(
        stdout(&o),
        "-a.toml: ok\n1 passed, 0 failed\n",
        "{}",
        stderr(&o)
    );
    assert_eq!(o.status.code(), Some(0));
    assert_eq!(
        std::fs::read(d.join("-fresh/-a.mcap")).unwrap(),
        std::fs::read(d.join("recordings/shapes.mcap")).unwrap(),
        "the fresh log is kept in -fresh"
    );
}

#[test]
fn suite_the_junit_report_is_created_with_the_umasks_mode() {
    use std::os::unix::fs::PermissionsExt;
    let dir = suite_copy();
    // What `touch`, a shell redirect or `File::create` give under umask 022: rw-r--r--.
    let o = Command::new("sh")
        .args(["-c", "umask 022 && exec \"$0\" \"$@\""])
        .arg(env!("CARGO_BIN_EXE_ricochet"))
        .args(["test", "scenarios/level.toml", "--junit", "report.xml"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let mode = std::fs::metadata(dir.path().join("report.xml"))
        .unwrap()
        .permissions()
        .mode();
    assert_eq!(mode & 0o777, 0o644, "{mode:o}");
}
