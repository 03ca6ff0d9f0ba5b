//! `ricochet diff` against hostile logs: an unknown topic, a damaged summary, a foreign MCAP,
//! a log too long to decode whole under a memory cap, bodies whose slot was reused, a log
//! read from a pipe. Every test checks the exit code, the message and that nothing
//! panicked (the helpers are `hostile.rs`'s).

use std::fs::File;
use std::path::Path;
use std::process::{Command, Stdio};

use ricochet_log::LogWriter;
use serde_json::json;

use crate::hostile::{assert_no_panic, record, ricochet, s, two_logs};

#[test]
fn diff_of_an_unknown_topic_is_an_error_naming_the_topics_there_are() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = two_logs(dir.path());
    for topic in ["/bodys", "bodies"] {
        let o = ricochet()
            .args(["diff", "--topic", topic, s(&a), s(&b)])
            .output()
            .unwrap();
        assert_no_panic(topic, &o);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{topic}: {stderr}");
        assert!(o.stdout.is_empty());
        assert!(
            stderr.contains(
                "/bodies, /contacts, /events, /scene, /scene/contacts, /scene/static, /stats, /tf"
            ),
            "{stderr}"
        );
    }
    let o = ricochet()
        .args(["diff", "--topic", "bodies", s(&a), s(&b)])
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&o.stderr).contains("did you mean /bodies?"));
    // A topic that is there still compares.
    let o = ricochet()
        .args(["diff", "--topic", "/bodies", s(&a), s(&b)])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stdout).contains("590 / 601, 11"));
}

#[test]
fn diff_of_a_log_with_a_damaged_summary_is_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let (a, _) = two_logs(dir.path());
    let bytes = std::fs::read(&a).unwrap();
    let footer = bytes.len() - 8 - 29;
    let start = u64::from_le_bytes(bytes[footer + 9..footer + 17].try_into().unwrap()) as usize;
    let damaged = dir.path().join("damaged.mcap");
    for i in [start, start + 40, (start + footer) / 2, footer - 1] {
        let mut copy = bytes.clone();
        copy[i] ^= 0x20;
        std::fs::write(&damaged, &copy).unwrap();
        let o = ricochet()
            .args(["diff", s(&a), s(&damaged)])
            .output()
            .unwrap();
        assert_no_panic("diff damaged", &o);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "byte {i}: {stderr}");
        assert!(
            stderr.contains("damaged.mcap") && stderr.contains("summary"),
            "{stderr}"
        );
    }
}

#[test]
fn diff_of_a_foreign_mcap_is_exit_2_not_a_ricochet_log() {
    let dir = tempfile::tempdir().unwrap();
    let (a, _) = two_logs(dir.path());
    // JSON on other topics, from another writer.
    let other = dir.path().join("other.mcap");
    let mut w = LogWriter::create(&other, "some other tool 1.0").unwrap();
    let ch = w.add_json_channel("/bodies", "x.Bodies", "{}").unwrap();
    w.write_json(ch, 0, &json!({"frame": 0})).unwrap();
    w.finish().unwrap();
    // Ricochet's name, but messages in another encoding (ROS 2 CDR).
    let proto = dir.path().join("proto.mcap");
    {
        let mut w = mcap::WriteOptions::new()
            .library("ricochet 0.1.0")
            .create(std::io::BufWriter::new(File::create(&proto).unwrap()))
            .unwrap();
        let schema = w.add_schema("x/Pose", "ros2msg", b"float64 x").unwrap();
        let ch = w
            .add_channel(schema, "/bodies", "cdr", &Default::default())
            .unwrap();
        let header = mcap::records::MessageHeader {
            channel_id: ch,
            sequence: 0,
            log_time: 0,
            publish_time: 0,
        };
        w.write_to_known_channel(&header, b"\x08\x01").unwrap();
        w.finish().unwrap();
    }
    for (file, why) in [(&other, "some other tool"), (&proto, "cdr")] {
        for args in [[s(&a), s(file)], [s(file), s(&a)]] {
            let o = ricochet().arg("diff").args(args).output().unwrap();
            assert_no_panic("diff foreign", &o);
            let stderr = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(2), "{args:?}: {stderr}");
            assert!(
                stderr.contains("not a Ricochet log") && stderr.contains(why),
                "{stderr}"
            );
        }
    }
}

#[test]
fn diff_memory_does_not_grow_with_the_log() {
    // 3000 frames of asteroids is a 1.8 MB log. Decoded whole, as diff once did, two copies
    // took 575 MB; streamed, diff needs about 15 MB whatever the length. Under a 160 MB cap
    // on address space, the old diff aborts; this one finishes.
    let dir = tempfile::tempdir().unwrap();
    let long = dir.path().join("long.mcap");
    record("scenarios/asteroids.toml", 3000, &long);
    let copy = dir.path().join("copy.mcap");
    std::fs::copy(&long, &copy).unwrap();
    let o = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v 160000; exec '{}' diff '{}' '{}'",
            env!("CARGO_BIN_EXE_ricochet"),
            s(&long),
            s(&copy)
        ))
        .output()
        .unwrap();
    assert_no_panic("diff under a memory cap", &o);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{stdout}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(stdout.contains("0 / 3001, 3001"), "{stdout}");
}

/// A log of one `/bodies` message per list, written by "ricochet" (the diff reads it as ours).
fn bodies_log(path: &Path, frames: &[serde_json::Value]) {
    let mut w = LogWriter::create(path, "ricochet test").unwrap();
    let ch = w
        .add_json_channel("/bodies", "ricochet.Bodies", "{}")
        .unwrap();
    for (i, bodies) in frames.iter().enumerate() {
        let msg = json!({"frame": i, "bodies": bodies});
        w.write_json(ch, i as u64 * 1000, &msg).unwrap();
    }
    w.finish().unwrap();
}

#[test]
fn diff_matches_bodies_by_id_and_generation() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a.mcap"), dir.path().join("b.mcap"));
    // Slot 5 holds rock_a (generation 0) in A, and a later body, rock_b (generation 1), in
    // B: they are two bodies, not one that moved.
    let rock = |generation: u64, name: &str| json!({"id": 5, "generation": generation, "name": name, "position": [1.0, 2.0]});
    let ship = json!({"id": 0, "generation": 0, "name": "ship", "position": [0.0, 0.0]});
    bodies_log(&a, &[json!([ship.clone(), rock(0, "rock_a")])]);
    bodies_log(&b, &[json!([ship.clone(), rock(1, "rock_b")])]);
    let o = ricochet().args(["diff", s(&a), s(&b)]).output().unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "{stdout}");
    assert!(stdout.contains("body 5:0 (rock_a)"), "{stdout}");
    assert!(stdout.contains("field bodies[id=5:0]"), "{stdout}");
    assert!(stdout.contains("B: missing"), "{stdout}");
    // Without generations (older logs), bodies are matched by id alone.
    let old = |x: f64| json!([{"id": 5, "name": "rock", "position": [x, 2.0]}]);
    bodies_log(&a, &[old(1.0)]);
    bodies_log(&b, &[old(1.5)]);
    let o = ricochet().args(["diff", s(&a), s(&b)]).output().unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains("body 5 (rock)") && stdout.contains("bodies[id=5].position[0]"),
        "{stdout}"
    );
}

#[test]
fn diff_reads_a_log_from_a_pipe() {
    // `ricochet diff <(zcat a.mcap.gz) b.mcap`: a pipe is read once, into a temporary copy.
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = two_logs(dir.path());
    for (piped, code) in [(std::fs::read(&a).unwrap(), 1), (b"not a log".to_vec(), 2)] {
        let mut child = ricochet()
            .args(["diff", "/dev/stdin", s(&b)])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut stdin = child.stdin.take().unwrap();
        let feeder = std::thread::spawn(move || {
            use std::io::Write;
            let _ = stdin.write_all(&piped);
        });
        let o = child.wait_with_output().unwrap();
        feeder.join().unwrap();
        assert_no_panic("diff /dev/stdin", &o);
        let stdout = String::from_utf8_lossy(&o.stdout);
        assert_eq!(
            o.status.code(),
            Some(code),
            "{stdout}{}",
            String::from_utf8_lossy(&o.stderr)
        );
        if code == 1 {
            assert!(stdout.contains("590 / 601, 11"), "{stdout}");
        }
    }
}
