//! Logs rewritten by another MCAP writer with one thing damaged (issue 20): `diff` must never
//! call them equal to the good log, and `replay` must never pick one of two scenarios.

use std::fs::File;
use std::io::BufWriter;
use std::path::Path;
use std::process::Output;

use ricochet_log::LogWriter;

use crate::util::{one_ulp_up, record, ricochet, root};

/// What a rewrite does to one channel's schema: its name and data, by topic.
type Damage = fn(&str, &mut String, &mut Vec<u8>);

/// Copies the log `from` to `to` with the `mcap` crate (messages, times and attachments as
/// they were), passing each channel's schema through `damage` first.
fn rewrite(from: &Path, to: &Path, damage: Damage) {
    let bytes = std::fs::read(from).unwrap();
    let mut w = mcap::WriteOptions::new()
        .library("ricochet 0.1.0")
        .profile("")
        .create(BufWriter::new(File::create(to).unwrap()))
        .unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let mut ids = std::collections::BTreeMap::new();
    for (id, channel) in &summary.channels {
        let schema = channel.schema.as_ref().unwrap();
        let (mut name, mut data) = (schema.name.clone(), schema.data.to_vec());
        damage(&channel.topic, &mut name, &mut data);
        let sid = w.add_schema(&name, &schema.encoding, &data).unwrap();
        let cid = w
            .add_channel(
                sid,
                &channel.topic,
                &channel.message_encoding,
                &channel.metadata,
            )
            .unwrap();
        ids.insert(*id, cid);
    }
    for index in &summary.attachment_indexes {
        let a = mcap::read::attachment(&bytes, index).unwrap();
        w.attach(&a).unwrap();
    }
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        let header = mcap::records::MessageHeader {
            channel_id: ids[&m.channel.id],
            sequence: m.sequence,
            log_time: m.log_time,
            publish_time: m.publish_time,
        };
        w.write_to_known_channel(&header, &m.data).unwrap();
    }
    w.finish().unwrap();
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// `/bodies` only, in the given way.
fn on_bodies(topic: &str, f: impl FnOnce()) {
    if topic == "/bodies" {
        f();
    }
}

#[test]
fn diff_refuses_a_log_whose_schema_is_unreadable_where_dump_does() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("good.mcap");
    record(&root().join("scenarios/asteroids.toml"), &good);
    let damages: [(&str, Damage, &str); 3] = [
        (
            "empty descriptor",
            |t, _, data| on_bodies(t, || data.clear()),
            "ricochet.Bodies: its descriptor does not define it",
        ),
        (
            "schema name ricochet.Bodiez",
            |t, name, _| on_bodies(t, || *name = "ricochet.Bodiez".to_owned()),
            "ricochet.Bodiez: its descriptor does not define it",
        ),
        (
            "descriptor cut short",
            |t, _, data| on_bodies(t, || data.truncate(data.len() / 2)),
            "channel /bodies: schema ricochet.Bodies",
        ),
    ];
    for (what, damage, why) in damages {
        let bad = dir.path().join("bad.mcap");
        rewrite(&good, &bad, damage);
        let dump = ricochet(&["dump", s(&bad)], b"");
        assert_eq!(
            dump.status.code(),
            Some(2),
            "{what}: dump: {}",
            stderr(&dump)
        );
        for args in [[s(&good), s(&bad)], [s(&bad), s(&good)]] {
            let o = ricochet(&["diff", args[0], args[1]], b"");
            let err = stderr(&o);
            assert_eq!(o.status.code(), Some(2), "{what}: diff {args:?}: {err}");
            assert!(
                err.contains("corrupt log") && err.contains(why),
                "{what}: {err}"
            );
        }
    }
    // The same rewrite with nothing damaged is equal: the refusals are the damage's.
    let copy = dir.path().join("copy.mcap");
    rewrite(&good, &copy, |_, _, _| {});
    let o = ricochet(&["diff", s(&good), s(&copy)], b"");
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

#[test]
fn diff_reports_a_schema_that_differs_between_the_logs() {
    // `position` renamed `positiom` (same length, so the descriptor stays valid): the bytes
    // of every message are equal, but they no longer mean the same fields.
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("good.mcap");
    record(&root().join("scenarios/asteroids.toml"), &good);
    let renamed = dir.path().join("renamed.mcap");
    rewrite(&good, &renamed, |t, _, data| {
        on_bodies(t, || {
            let at = data
                .windows(9)
                .position(|w| w == b"\x08position")
                .expect("the descriptor names the field `position`");
            data[at + 8] = b'm';
        })
    });
    let o = ricochet(&["diff", s(&good), s(&renamed)], b"");
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "{out}{}", stderr(&o));
    assert!(
        out.contains("first difference: the schema of topic /bodies"),
        "{out}"
    );
    // Only /bodies is named; `--topic /stats` compares a topic whose schema is the same.
    let o = ricochet(&["diff", s(&good), s(&renamed), "--topic", "/stats"], b"");
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

/// A log of one message, `payload`, on `topic` with Ricochet's schema `schema` (a valid
/// schema: whether the payload is one of its messages is what the tests ask).
fn one_message_log(path: &Path, schema: &str, topic: &str, payload: &[u8]) {
    let mut w = mcap::WriteOptions::new()
        .library("ricochet 0.1.0")
        .create(BufWriter::new(File::create(path).unwrap()))
        .unwrap();
    let schema = ricochet_log::Schema::ricochet(schema);
    let sid = w
        .add_schema(&schema.name, &schema.encoding, &schema.data)
        .unwrap();
    let ch = w
        .add_channel(sid, topic, "protobuf", &Default::default())
        .unwrap();
    let header = mcap::records::MessageHeader {
        channel_id: ch,
        sequence: 0,
        log_time: 0,
        publish_time: 0,
    };
    w.write_to_known_channel(&header, payload).unwrap();
    w.finish().unwrap();
}

#[test]
fn diff_refuses_equal_messages_that_their_schema_cannot_decode() {
    // Two logs with the same valid schema and the same payload, which is not a
    // `ricochet.Stats` (field 1 as a length running past the end): byte for byte equal,
    // but neither log is readable. Equal bytes are not decoded whole, but their top level
    // (keys, lengths, the fields that are not nested messages) is checked.
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a.mcap"), dir.path().join("b.mcap"));
    for path in [&a, &b] {
        one_message_log(path, "ricochet.Stats", "/stats", b"\x0a\x7f\x01");
    }
    let o = ricochet(&["diff", s(&a), s(&b)], b"");
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("corrupt log") && err.contains("not a ricochet.Stats message"),
        "{err}"
    );
}

#[test]
fn diff_takes_equal_bytes_as_equal_and_decodes_those_that_differ() {
    // A `ricochet.Bodies` whose top level is sound (field 4, `bodies`, 3 bytes long) but
    // whose body is not a `ricochet.Body` (its field 1 a length running past the end).
    let nested_damage: &[u8] = b"\x22\x03\x0a\x7f\x01";
    // The same message with a sound body: `id` 1.
    let sound: &[u8] = b"\x22\x02\x08\x01";
    let dir = tempfile::tempdir().unwrap();
    let (a, b, c) = (
        dir.path().join("a.mcap"),
        dir.path().join("b.mcap"),
        dir.path().join("c.mcap"),
    );
    one_message_log(&a, "ricochet.Bodies", "/bodies", nested_damage);
    one_message_log(&b, "ricochet.Bodies", "/bodies", nested_damage);
    one_message_log(&c, "ricochet.Bodies", "/bodies", sound);
    // Where the bytes differ, the message is decoded, and the damage found, in either order.
    for (x, y) in [(&a, &c), (&c, &a)] {
        let o = ricochet(&["diff", s(x), s(y)], b"");
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(
            err.contains("corrupt log")
                && err.contains("a.mcap")
                && err.contains("not a ricochet.Bodies message"),
            "{err}"
        );
    }
    // Equal bytes under the same valid schema are equal messages: what is nested in them is
    // not decoded by `diff` (that is what keeps big logs fast); `dump` decodes it.
    let o = ricochet(&["diff", s(&a), s(&b)], b"");
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let dump = ricochet(&["dump", s(&a)], b"");
    assert_eq!(dump.status.code(), Some(2), "{}", stderr(&dump));
    assert!(stderr(&dump).contains("not a ricochet.Bodies message"));
}

#[test]
fn diff_prints_the_first_difference_before_damage_found_later() {
    // A velocity one ulp off in frame 0, and a data section CRC that does not match, which
    // only the end of the data section shows: the first difference is printed as soon as it
    // is found, then the damage is an error (exit code 2, no counts).
    let dir = tempfile::tempdir().unwrap();
    let scenario = root().join("scenarios/asteroids.toml");
    let (text, _) = one_ulp_up(&std::fs::read_to_string(&scenario).unwrap());
    let nudged = dir.path().join("nudged.toml");
    std::fs::write(&nudged, text).unwrap();
    let (good, bad) = (dir.path().join("good.mcap"), dir.path().join("bad.mcap"));
    record(&scenario, &good);
    record(&nudged, &bad);
    let mut bytes = std::fs::read(&bad).unwrap();
    // The footer (before the closing magic) starts with the summary's offset; the data
    // end record (opcode 0x0f, length 4, the CRC) ends right before it.
    let n = bytes.len();
    let summary = u64::from_le_bytes(bytes[n - 8 - 20..n - 8 - 12].try_into().unwrap()) as usize;
    assert_eq!(bytes[summary - 13], 0x0f, "a data end record");
    assert_ne!(
        bytes[summary - 4..summary],
        [0; 4],
        "a data section CRC to damage"
    );
    bytes[summary - 4] ^= 1;
    std::fs::write(&bad, bytes).unwrap();
    let o = ricochet(&["diff", s(&good), s(&bad)], b"");
    let (out, err) = (String::from_utf8_lossy(&o.stdout), stderr(&o));
    assert_eq!(o.status.code(), Some(2), "{out}{err}");
    assert!(
        out.contains("differ\nfirst difference: frame 0") && !out.contains("per topic"),
        "{out}"
    );
    assert!(
        err.contains("corrupt log") && err.contains("bad.mcap") && err.contains("data section"),
        "{err}"
    );
}

#[test]
fn replay_refuses_a_session_with_two_scenarios() {
    let dir = tempfile::tempdir().unwrap();
    let session = dir.path().join("session.mcap");
    let text = std::fs::read(root().join("scenarios/asteroids.toml")).unwrap();
    let mut w = LogWriter::create(&session, "ricochet 0.1.0").unwrap();
    w.attach("scenario.toml", "application/toml", &text)
        .unwrap();
    w.attach("scenario.toml", "application/toml", b"frames = 1\n")
        .unwrap();
    w.finish().unwrap();
    let o = ricochet(&["replay", s(&session)], b"");
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("2 scenario.toml attachments") && err.contains(s(&session)),
        "{err}"
    );
    assert!(
        !dir.path().join("session.replay.mcap").exists(),
        "nothing is replayed"
    );
}
