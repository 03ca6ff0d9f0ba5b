//! `ricochet test`, the golden-log runner, on a temporary copy of `scenarios/*.toml` and
//! `recordings/` (as a game's repository holds them): verdicts, the first divergence of a
//! one-ulp change, `--bless`, the JUnit report read back by an XML reader, shards, `-j`,
//! and bad input.

use std::path::Path;
use std::process::Output;

use ricochet_sim::load_scenario;

use crate::util::{one_ulp_up, ricochet_in, scenarios, suite_copy};

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// `scenarios/NAME.toml` for every shipped scenario, sorted: the lines' order.
fn names() -> Vec<String> {
    scenarios()
        .iter()
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .collect()
}

/// The verdict lines (without the summary) of an output.
fn verdicts(out: &str) -> Vec<&str> {
    out.lines()
        .filter(|l| l.starts_with("scenarios/"))
        .collect()
}

/// Raises the x velocity of asteroids.toml's first moving body by one ulp; its expected
/// line from the edit alone: the body's id and name from the scenario, both values as
/// written.
fn nudge_asteroids(dir: &Path) -> String {
    let path = dir.join("scenarios/asteroids.toml");
    let original = std::fs::read_to_string(&path).unwrap();
    let (text, index) = one_ulp_up(&original);
    let body = &load_scenario(&text, "asteroids.toml").unwrap().bodies[index];
    let was = load_scenario(&original, "asteroids.toml").unwrap().bodies[index].velocity[0];
    std::fs::write(&path, &text).unwrap();
    format!(
        "scenarios/asteroids.toml: differs: frame 0, /bodies, body {index}:0 ({}), velocity[0] {was:?} → {:?}",
        body.name, body.velocity[0]
    )
}

#[test]
fn suite_every_shipped_scenario_is_ok_against_a_copy_of_its_goldens() {
    let dir = suite_copy();
    let o = ricochet_in(dir.path(), &["test"]);
    let out = stdout(&o);
    assert_eq!(o.status.code(), Some(0), "{out}");
    let expected: Vec<String> = names()
        .iter()
        .map(|n| format!("scenarios/{n}.toml: ok"))
        .collect();
    assert_eq!(verdicts(&out), expected);
    assert!(
        out.ends_with(&format!("\n{} passed, 0 failed\n", expected.len())),
        "{out}"
    );
}

#[test]
fn suite_a_one_ulp_change_fails_with_its_first_divergence_then_bless_passes() {
    let dir = suite_copy();
    let line = nudge_asteroids(dir.path());
    let n = names().len();
    let o = ricochet_in(dir.path(), &["test", "-j", "2"]);
    let out = stdout(&o);
    assert_eq!(o.status.code(), Some(1), "{out}");
    assert!(out.lines().any(|l| l == line), "{line}\nnot in\n{out}");
    assert!(
        out.ends_with(&format!("\n{} passed, 1 failed\n", n - 1)),
        "{out}"
    );

    let golden = dir.path().join("recordings/asteroids.mcap");
    let before = std::fs::read(&golden).unwrap();
    let o = ricochet_in(dir.path(), &["test", "--bless"]);
    let out = stdout(&o);
    assert_eq!(o.status.code(), Some(0), "{out}");
    assert!(
        out.contains("scenarios/asteroids.toml: blessed (changed)\n"),
        "{out}"
    );
    assert_eq!(
        out.matches(": unchanged\n").count(),
        n - 1,
        "the others are left alone: {out}"
    );
    assert_ne!(std::fs::read(&golden).unwrap(), before);
    // No temporary file is left beside the goldens.
    let leftovers: Vec<_> = std::fs::read_dir(dir.path().join("recordings"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|f| f.starts_with('.'))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");

    let o = ricochet_in(dir.path(), &["test"]);
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
}

#[test]
fn suite_a_missing_golden_says_so_and_bless_writes_it_new() {
    let dir = suite_copy();
    for ext in ["mcap", "digest"] {
        std::fs::remove_file(dir.path().join(format!("recordings/shapes.{ext}"))).unwrap();
    }
    let o = ricochet_in(dir.path(), &["test", "scenarios/shapes.toml"]);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(
        stdout(&o),
        "scenarios/shapes.toml: no golden (run with --bless)\n0 passed, 1 failed\n"
    );
    let o = ricochet_in(dir.path(), &["test", "scenarios/shapes.toml", "--bless"]);
    assert_eq!(
        stdout(&o),
        "scenarios/shapes.toml: blessed (new)\n1 passed, 0 failed\n"
    );
    // The new goldens are the shipped ones.
    for ext in ["mcap", "digest"] {
        let name = format!("recordings/shapes.{ext}");
        assert!(
            std::fs::read(dir.path().join(&name)).unwrap()
                == std::fs::read(crate::util::root().join(&name)).unwrap(),
            "{name}"
        );
    }
}

#[test]
fn suite_a_changed_digest_alone_fails() {
    let dir = suite_copy();
    let digest = dir.path().join("recordings/level.digest");
    let text = std::fs::read_to_string(&digest).unwrap();
    let hash = text.lines().find_map(|l| l.strip_prefix("hash ")).unwrap();
    let other = format!("{:016x}", u64::from_str_radix(hash, 16).unwrap() ^ 1);
    std::fs::write(&digest, text.replace(hash, &other)).unwrap();
    let o = ricochet_in(dir.path(), &["test", "scenarios/level.toml"]);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(
        stdout(&o),
        format!(
            "scenarios/level.toml: differs: digest hash {other} → {hash}\n0 passed, 1 failed\n"
        )
    );
}

/// Attribute `name` of an element, unescaped.
fn attribute(e: &quick_xml::events::BytesStart, name: &str) -> Option<String> {
    e.try_get_attribute(name).unwrap().map(|a| {
        a.normalized_value(quick_xml::XmlVersion::Implicit1_0)
            .unwrap()
            .into_owned()
    })
}

#[test]
fn suite_the_junit_report_parses_and_counts_right() {
    use quick_xml::events::Event;
    let dir = suite_copy();
    let line = nudge_asteroids(dir.path());
    // A name that needs escaping in XML.
    std::fs::copy(
        dir.path().join("scenarios/shapes.toml"),
        dir.path().join("scenarios/a&<b>.toml"),
    )
    .unwrap();
    let o = ricochet_in(dir.path(), &["test", "--junit", "report.xml"]);
    assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
    let xml = std::fs::read_to_string(dir.path().join("report.xml")).unwrap();
    let mut reader = quick_xml::Reader::from_str(&xml);
    let (mut suite, mut cases, mut failures) = (None, Vec::new(), Vec::new());
    loop {
        match reader.read_event().unwrap() {
            Event::Start(e) | Event::Empty(e) => match e.name().0 {
                "testsuite" => {
                    suite = Some((attribute(&e, "tests"), attribute(&e, "failures")));
                }
                "testcase" => cases.push(attribute(&e, "name").unwrap()),
                "failure" => failures.push(attribute(&e, "message").unwrap()),
                _ => {}
            },
            Event::Eof => break,
            _ => {}
        }
    }
    let n = names().len() + 1;
    assert_eq!(
        suite,
        Some((Some(n.to_string()), Some("2".to_owned()))),
        "{xml}"
    );
    assert_eq!(cases.len(), n);
    assert!(cases.iter().any(|c| c == "a&<b>"), "{cases:?}");
    // The copy has no golden: a failure too.
    assert_eq!(failures.len(), 2, "{xml}");
    let divergence = line.split_once(": ").unwrap().1;
    assert!(failures.iter().any(|f| f == divergence), "{failures:?}");
    assert!(
        failures.iter().any(|f| f == "no golden (run with --bless)"),
        "{failures:?}"
    );
}

#[test]
fn suite_three_shards_are_the_whole_suite_with_no_overlap_and_jobs_change_no_byte() {
    let dir = suite_copy();
    nudge_asteroids(dir.path());
    let one = ricochet_in(dir.path(), &["test", "-j", "1"]);
    let two = ricochet_in(dir.path(), &["test", "-j", "2"]);
    assert_eq!(
        stdout(&one),
        stdout(&two),
        "-j 1 and -j 2 print the same bytes"
    );
    let whole = stdout(&one);
    let whole: Vec<&str> = verdicts(&whole);
    assert_eq!(whole.len(), names().len());
    let mut seen: Vec<String> = Vec::new();
    for k in 0..3 {
        let o = ricochet_in(dir.path(), &["test", "--shard", &format!("{k}/3")]);
        let out = stdout(&o);
        let mine: Vec<String> = verdicts(&out).into_iter().map(str::to_owned).collect();
        assert!(!mine.is_empty(), "shard {k}/3 has items: {out}");
        let failed = usize::from(mine.iter().any(|l| l.contains("differs")));
        assert!(
            out.ends_with(&format!(
                "\n{} passed, {failed} failed\n",
                mine.len() - failed
            )),
            "{out}"
        );
        seen.extend(mine);
    }
    let count = seen.len();
    seen.sort();
    seen.dedup();
    assert_eq!(seen.len(), count, "no scenario in two shards");
    let mut whole_sorted: Vec<String> = whole.iter().map(|s| (*s).to_owned()).collect();
    whole_sorted.sort();
    assert_eq!(seen, whole_sorted, "the shards together are the suite");
}

#[test]
fn suite_bad_paths_exit_2_with_the_path_named_and_a_broken_scenario_is_a_failed_line() {
    let dir = suite_copy();
    let o = ricochet_in(dir.path(), &["test", "nowhere"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("nowhere"));
    assert!(o.stdout.is_empty());

    std::fs::create_dir(dir.path().join("empty")).unwrap();
    let o = ricochet_in(dir.path(), &["test", "empty"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("empty: no scenario files"));

    let o = ricochet_in(dir.path(), &["test", "--shard", "3/3"]);
    assert_eq!(o.status.code(), Some(2));
    let o = ricochet_in(dir.path(), &["test", "--golden", "nowhere"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--golden nowhere"));

    std::fs::write(
        dir.path().join("scenarios/broken.toml"),
        "frames = \"many\"\n",
    )
    .unwrap();
    let o = ricochet_in(dir.path(), &["test"]);
    assert_eq!(o.status.code(), Some(1));
    let out = stdout(&o);
    let broken = out
        .lines()
        .find(|l| l.starts_with("scenarios/broken.toml: error: scenarios/broken.toml:1:"))
        .unwrap_or_else(|| panic!("{out}"));
    assert!(broken.contains("frames"), "{broken}");
}

#[test]
fn suite_an_item_prints_one_json_result_line_with_the_golden_digest() {
    let dir = suite_copy();
    let fresh = dir.path().join("fresh");
    std::fs::create_dir(&fresh).unwrap();
    let o = ricochet_in(
        dir.path(),
        &[
            "test",
            "--item",
            "scenarios/platformer.toml",
            "--golden",
            "recordings",
            "--out",
            "fresh",
        ],
    );
    assert_eq!(o.status.code(), Some(0));
    let out = stdout(&o);
    assert_eq!(out.lines().count(), 1, "{out}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["format"], 1);
    assert_eq!(v["scenario"], "scenarios/platformer.toml");
    assert_eq!(v["name"], "platformer");
    assert_eq!(v["verdict"], "ok");
    assert_eq!(v["line"], "ok");
    assert!(v["first"].is_null());
    assert_eq!(v["log"], "fresh/platformer.mcap");
    let d = &v["digest"];
    let text = format!(
        "frames {}\nbodies {}\nhash {}\n",
        d["frames"],
        d["bodies"],
        d["hash"].as_str().unwrap()
    );
    assert_eq!(
        text,
        std::fs::read_to_string(dir.path().join("recordings/platformer.digest")).unwrap()
    );
    assert_eq!(
        std::fs::read(fresh.join("platformer.mcap")).unwrap(),
        std::fs::read(dir.path().join("recordings/platformer.mcap")).unwrap()
    );
}

/// The verdict lines of running `docs/examples/` as a scheduler would, once per task index
/// `0..n`, with `env(k)` set; each task's output is checked to end with its summary.
fn run_example(
    dir: &Path,
    n: usize,
    command: &[&str],
    env: impl Fn(usize) -> Vec<(String, String)>,
) -> Vec<String> {
    let bin = Path::new(env!("CARGO_BIN_EXE_ricochet")).parent().unwrap();
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let mut lines = Vec::new();
    for k in 0..n {
        let o = std::process::Command::new(command[0])
            .args(&command[1..])
            .current_dir(dir)
            .env("PATH", &path)
            .envs(env(k))
            .output()
            .unwrap();
        let out = stdout(&o);
        assert_eq!(
            o.status.code(),
            Some(0),
            "task {k}: {out}{}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(
            out.lines().last().unwrap().ends_with(" passed, 0 failed"),
            "{out}"
        );
        lines.extend(verdicts(&out).into_iter().map(str::to_owned));
    }
    lines.sort();
    lines
}

#[test]
fn suite_the_slurm_and_kubernetes_examples_run_every_scenario_once() {
    let dir = suite_copy();
    let all: Vec<String> = names()
        .iter()
        .map(|n| format!("scenarios/{n}.toml: ok"))
        .collect();
    let script = crate::util::root().join("docs/examples/slurm-golden.sh");
    let slurm = run_example(dir.path(), 3, &["bash", script.to_str().unwrap()], |k| {
        vec![
            ("SLURM_ARRAY_TASK_ID".into(), k.to_string()),
            ("SLURM_ARRAY_TASK_COUNT".into(), "3".into()),
            ("SLURM_CPUS_PER_TASK".into(), "1".into()),
        ]
    });
    assert_eq!(slurm, all);
    for k in 0..3 {
        assert!(dir.path().join(format!("reports/golden-{k}.xml")).is_file());
    }
    // The Job's container command, as its shell runs it, with each completion index.
    let yaml =
        std::fs::read_to_string(crate::util::root().join("docs/examples/k8s-golden.yaml")).unwrap();
    let completions: usize = yaml
        .lines()
        .find_map(|l| l.trim().strip_prefix("completions:"))
        .and_then(|v| v.split('#').next())
        .unwrap()
        .trim()
        .parse()
        .unwrap();
    let command = yaml
        .lines()
        .find_map(|l| l.trim().strip_prefix("- ricochet test"))
        .map(|rest| format!("ricochet test{rest}"))
        .unwrap();
    assert!(
        command.contains(&format!("--shard \"$JOB_COMPLETION_INDEX/{completions}\"")),
        "{command}"
    );
    let k8s = run_example(dir.path(), completions, &["sh", "-c", &command], |k| {
        vec![("JOB_COMPLETION_INDEX".into(), k.to_string())]
    });
    assert_eq!(k8s, all);
}

#[test]
fn suite_ctrl_c_stops_the_run_and_leaves_every_golden_whole() {
    // Scenarios long enough to be under way when the signal comes (tens of seconds each
    // in a debug build), so that their blessing is what a stop must not tear.
    let dir = tempfile::tempdir().unwrap();
    let long = dir.path().join("long");
    let golden = dir.path().join("golden");
    std::fs::create_dir_all(&long).unwrap();
    std::fs::create_dir_all(&golden).unwrap();
    let text = std::fs::read_to_string(crate::util::root().join("scenarios/platformer.toml"))
        .unwrap()
        .lines()
        .map(|l| {
            if l.starts_with("frames = ") {
                "frames = 200000".to_owned()
            } else {
                l.to_owned()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    for n in ["p1", "p2", "p3"] {
        std::fs::write(long.join(format!("{n}.toml")), &text).unwrap();
    }
    // An old golden, which the stopped bless must leave as it was.
    let old = std::fs::read(crate::util::root().join("recordings/platformer.mcap")).unwrap();
    std::fs::write(golden.join("p1.mcap"), &old).unwrap();
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_ricochet"))
        .args(["test", "long", "--golden", "golden", "--bless", "-j", "2"])
        .current_dir(dir.path())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    let kill = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    // Bounded: a run the signal did not stop ends the test, not the CI job.
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(120);
    while child.try_wait().unwrap().is_none() {
        if std::time::Instant::now() > deadline {
            let _ = child.kill();
            panic!("Ctrl-C did not stop `ricochet test` within 120 s");
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    let o = child.wait_with_output().unwrap();
    let out = stdout(&o);
    assert_eq!(
        o.status.code(),
        Some(130),
        "{out}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert_eq!(
        out,
        "long/p1.toml: interrupted\nlong/p2.toml: interrupted\n0 passed, 2 failed\n"
    );
    assert!(String::from_utf8_lossy(&o.stderr).contains("1 of 3 scenarios not started"));
    let mut left: Vec<String> = std::fs::read_dir(&golden)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(left, ["p1.mcap"], "no new golden, no temporary file");
    assert!(std::fs::read(golden.join("p1.mcap")).unwrap() == old);
}
