//! `ricochet dump` prints a log as JSON lines, and `ricochet run --channels` records only the
//! channels asked for. Expected values come from the log reader (`read_log_file`), which
//! reads the whole file its own way.

use std::path::Path;

use ricochet_log::read_log_file;
use serde_json::Value;

use crate::util::{record, ricochet, root};

fn dump(args: &[&str]) -> (Option<i32>, Vec<Value>, String) {
    let mut all = vec!["dump"];
    all.extend_from_slice(args);
    let o = ricochet(&all, b"");
    let lines = String::from_utf8(o.stdout)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).expect("every line is JSON"))
        .collect();
    (
        o.status.code(),
        lines,
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

#[test]
fn dump_prints_every_message_as_the_reader_reads_it() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("asteroids.mcap");
    record(&root().join("scenarios/asteroids.toml"), &log);
    let want = read_log_file(&log).unwrap();
    let (code, lines, err) = dump(&[log.to_str().unwrap()]);
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(lines.len(), want.len());
    for (line, m) in lines.iter().zip(&want) {
        assert_eq!(line["topic"], m.topic.as_str());
        assert_eq!(line["log_time"], m.log_time);
        assert_eq!(line["sequence"], m.sequence);
        assert_eq!(line["data"], m.data);
    }
    // One topic, one frame: frame 49's contacts, as the reader has them.
    let (code, lines, err) = dump(&[
        log.to_str().unwrap(),
        "--topic",
        "/contacts",
        "--frames",
        "49..49",
    ]);
    assert_eq!(code, Some(0), "{err}");
    let frame49: Vec<_> = want
        .iter()
        .filter(|m| m.topic == "/contacts" && m.data["frame"] == 49)
        .collect();
    assert_eq!(lines.len(), 1);
    assert_eq!(lines[0]["data"], frame49[0].data);
    // A range: frames 10 to 12 of every topic are the messages at those three times.
    let (_, lines, _) = dump(&[log.to_str().unwrap(), "--frames", "10..12"]);
    let times: Vec<u64> = want
        .iter()
        .filter(|m| m.topic == "/bodies")
        .filter(|m| (10..=12).contains(&m.data["frame"].as_u64().unwrap()))
        .map(|m| m.log_time)
        .collect();
    let expected = want.iter().filter(|m| times.contains(&m.log_time)).count();
    assert_eq!(lines.len(), expected);
    assert!(
        lines.len() >= 3 * 3,
        "bodies, contacts and stats each frame"
    );
}

#[test]
fn dump_refuses_an_unknown_topic_and_bad_frames() {
    let golden = root().join("recordings/asteroids.mcap");
    let golden = golden.to_str().unwrap();
    let (code, lines, err) = dump(&[golden, "--topic", "bodies"]);
    assert_eq!(code, Some(2));
    assert!(lines.is_empty());
    assert!(
        err.contains(
            "/scene, /scene/static, /tf, /scene/contacts, /bodies, /contacts, /stats, /events"
        ),
        "{err}"
    );
    let (code, _, err) = dump(&[golden, "--frames", "9..2"]);
    assert_eq!(code, Some(2), "{err}");
    let (code, _, err) = dump(&["no/such.mcap"]);
    assert_eq!(code, Some(2), "{err}");
}

fn topics(log: &Path) -> Vec<String> {
    let mut t: Vec<String> = read_log_file(log)
        .unwrap()
        .into_iter()
        .map(|m| m.topic)
        .collect();
    t.sort();
    t.dedup();
    t
}

#[test]
fn run_records_only_the_channels_asked_for() {
    let dir = tempfile::tempdir().unwrap();
    let (full, some) = (dir.path().join("full.mcap"), dir.path().join("some.mcap"));
    record(&root().join("scenarios/platformer.toml"), &full);
    let o = ricochet(
        &[
            "run",
            "scenarios/platformer.toml",
            "--channels",
            "bodies,/events",
            "-o",
            some.to_str().unwrap(),
        ],
        b"",
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(topics(&some), ["/bodies", "/events"]);
    // What it recorded is what the full log has on those channels.
    for topic in ["/bodies", "/events"] {
        let o = ricochet(
            &[
                "diff",
                "--topic",
                topic,
                full.to_str().unwrap(),
                some.to_str().unwrap(),
            ],
            b"",
        );
        assert_eq!(
            o.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&o.stdout)
        );
    }
    let o = ricochet(&["run", "--channels", "bodys", "-o", "never.mcap"], b"");
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("scene, bodies, contacts, stats, events"));
    assert!(!root().join("never.mcap").exists());
}
