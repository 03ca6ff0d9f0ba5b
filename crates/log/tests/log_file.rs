//! Writing logs and reading them back: determinism, round trip, and refusal
//! of truncated or damaged files.

mod common;

use std::path::Path;

use common::{STEP_NS, STEPS, deletion_scene, full_scene, log_line, write_sample_log};
use ricochet_log::{LogError, LogFile, LogWriter, read_log, read_log_file};

fn sample_bytes(dir: &Path) -> Vec<u8> {
    let path = dir.join("run.mcap");
    write_sample_log(&path);
    std::fs::read(path).unwrap()
}

#[test]
fn same_calls_give_byte_identical_files() {
    let first_dir = tempfile::tempdir().unwrap();
    let second_dir = tempfile::tempdir().unwrap();
    let first = sample_bytes(first_dir.path());
    let second = sample_bytes(second_dir.path());
    assert!(
        first.len() > 100,
        "suspiciously small log: {} bytes",
        first.len()
    );
    assert!(
        first == second,
        "two runs of the same calls gave different files"
    );
}

#[test]
fn the_writer_thread_and_inline_encoding_give_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let (thread, inline) = (dir.path().join("t.mcap"), dir.path().join("i.mcap"));
    common::write_sample_log_with(&thread, ricochet_log::Threading::Thread);
    common::write_sample_log_with(&inline, ricochet_log::Threading::Inline);
    let (t, i) = (
        std::fs::read(thread).unwrap(),
        std::fs::read(inline).unwrap(),
    );
    assert!(t.len() > 1000 && t == i, "{} vs {} bytes", t.len(), i.len());
}

/// The caller encoding every message (from 0 jobs queued), or those written while one job
/// or more waits (some here, some on the writer thread, as the threads' timing falls):
/// the same bytes as inline.
#[test]
fn encoding_shared_with_the_caller_gives_the_same_bytes() {
    use ricochet_log::Threading;
    let dir = tempfile::tempdir().unwrap();
    let inline = dir.path().join("i.mcap");
    common::write_sample_log_with(&inline, Threading::Inline);
    let want = std::fs::read(inline).unwrap();
    for from in [0, 1, 2] {
        let shared = dir.path().join(format!("s{from}.mcap"));
        common::write_sample_log_sharing(&shared, Threading::Thread, from);
        let got = std::fs::read(shared).unwrap();
        assert!(
            want.len() > 1000 && got == want,
            "from {from}: {} vs {} bytes",
            got.len(),
            want.len()
        );
    }
}

#[test]
fn written_log_reads_back_unchanged() {
    use prost::Message;
    use ricochet_log::messages::fox::{Log, SceneUpdate};
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.mcap");
    write_sample_log(&path);
    let log = LogFile::open(&path).unwrap();
    let mut messages = log.messages().unwrap();
    let mut expected_scenes = (0..STEPS)
        .map(|s| full_scene(s * STEP_NS))
        .collect::<Vec<_>>();
    expected_scenes.push(deletion_scene(STEPS * STEP_NS));
    let (mut scenes, mut lines) = (0, 0);
    while let Some(raw) = messages.next_raw() {
        let raw = raw.unwrap();
        // The payload decodes, with prost, to the very message written.
        match raw.topic() {
            "/scene" => {
                let got = SceneUpdate::decode(raw.bytes()).unwrap();
                assert_eq!(got, expected_scenes[scenes]);
                assert_eq!(raw.log_time(), scenes as u64 * STEP_NS);
                scenes += 1;
            }
            "/log" => {
                let got = Log::decode(raw.bytes()).unwrap();
                assert_eq!(got, log_line(lines as u64 * STEP_NS));
                lines += 1;
            }
            other => panic!("unexpected topic {other}"),
        }
    }
    assert_eq!((scenes, lines), (STEPS as usize + 1, STEPS as usize));
    // And to JSON, from the schema the log embeds: the protobuf JSON mapping, with the
    // .proto field names and every field.
    let all = read_log_file(&path).unwrap();
    let line = all
        .iter()
        .find(|m| m.topic == "/log" && m.sequence == 1)
        .unwrap();
    assert_eq!(line.schema_name, "foxglove.Log");
    assert_eq!((line.log_time, line.publish_time), (STEP_NS, STEP_NS));
    assert_eq!(
        line.data,
        serde_json::json!({
            "timestamp": "1970-01-01T00:00:00.016666667Z",
            "level": "INFO",
            "message": "step at 16666667 ns",
            "name": "ricochet",
            "file": "src/main.rs",
            "line": 42
        })
    );
}

#[test]
fn log_finished_early_is_complete() {
    // What the binary does on Ctrl-C: stop writing and finish.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("interrupted.mcap");
    let mut writer = LogWriter::create(&path, "ricochet-log tests").unwrap();
    let scene = writer
        .add_foxglove_channel::<ricochet_log::messages::fox::SceneUpdate>("/scene")
        .unwrap();
    let _unused = writer
        .add_foxglove_channel::<ricochet_log::messages::fox::Log>("/log")
        .unwrap();
    writer.write(scene, 5, full_scene(5)).unwrap();
    writer.finish().unwrap();
    let messages = read_log_file(&path).unwrap();
    assert_eq!(messages.len(), 1);
    assert_eq!(messages[0].log_time, 5);

    let empty = dir.path().join("empty.mcap");
    LogWriter::create(&empty, "ricochet-log tests")
        .unwrap()
        .finish()
        .unwrap();
    assert_eq!(read_log_file(&empty).unwrap(), Vec::new());
}

fn assert_refused(bytes: &[u8], what: &str) {
    match read_log(bytes) {
        Err(LogError::Truncated { .. } | LogError::Corrupt { .. }) => {}
        Err(other) => panic!("{what}: expected Truncated or Corrupt, got {other:?}"),
        Ok(messages) => panic!("{what}: read as Ok with {} messages", messages.len()),
    }
}

#[test]
fn truncated_log_is_reported_truncated() {
    let dir = tempfile::tempdir().unwrap();
    let bytes = sample_bytes(dir.path());
    let half = &bytes[..bytes.len() / 2];
    assert!(
        matches!(read_log(half), Err(LogError::Truncated { .. })),
        "cut at half: {:?}",
        read_log(half).map(|m| m.len())
    );
    let one_short = &bytes[..bytes.len() - 1];
    assert!(
        matches!(read_log(one_short), Err(LogError::Truncated { .. })),
        "cut by one byte: {:?}",
        read_log(one_short).map(|m| m.len())
    );
    let error = read_log(one_short).unwrap_err().to_string();
    assert!(error.contains("cut short"), "unclear message: {error}");
}

#[test]
fn no_strict_prefix_of_a_log_reads_ok() {
    let dir = tempfile::tempdir().unwrap();
    let bytes = sample_bytes(dir.path());
    for len in 0..bytes.len() {
        assert_refused(
            &bytes[..len],
            &format!("prefix of {len} of {} bytes", bytes.len()),
        );
    }
    assert!(read_log(&bytes).is_ok());
}

#[test]
fn damaged_chunk_is_reported_corrupt() {
    let dir = tempfile::tempdir().unwrap();
    let mut bytes = sample_bytes(dir.path());
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let chunk = &summary.chunk_indexes[0];
    let middle = chunk.chunk_start_offset + chunk.chunk_length / 2;
    bytes[middle as usize] ^= 0x55;
    assert_refused(&bytes, "byte flipped in the middle of the chunk");

    assert_refused(b"not an mcap file at all, just text", "text file");
}

#[test]
fn create_in_missing_directory_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("no/such/dir/run.mcap");
    match LogWriter::create(&path, "ricochet-log tests") {
        Err(LogError::Create { path: reported, .. }) => assert_eq!(reported, path),
        Err(other) => panic!("expected Create, got {other:?}"),
        Ok(_) => panic!("created a log in a missing directory"),
    }
    let missing = read_log_file(&path).unwrap_err();
    assert!(matches!(missing, LogError::Read { .. }), "{missing:?}");
}

/// Every byte the summary CRC covers: from the summary's start to the footer's CRC field.
fn summary_range(bytes: &[u8]) -> std::ops::Range<usize> {
    let footer = bytes.len() - 8 - 29;
    let start = u64::from_le_bytes(bytes[footer + 9..footer + 17].try_into().unwrap());
    start as usize..bytes.len() - 8 - 4
}

#[test]
fn damaged_summary_is_reported_corrupt() {
    // The summary lists the channels, schemas, statistics and chunk indexes: a flipped byte
    // there once read as a good log (or a different one). Its CRC is checked now.
    let dir = tempfile::tempdir().unwrap();
    let bytes = sample_bytes(dir.path());
    let range = summary_range(&bytes);
    assert!(range.len() > 100, "{range:?}");
    let damaged = dir.path().join("damaged.mcap");
    // About 40 bytes spread over the whole summary, its first and last included.
    let step = (range.len() / 40).max(1);
    for i in range.clone().step_by(step).chain([range.end - 1]) {
        let mut copy = bytes.clone();
        copy[i] ^= 0x01;
        assert_refused(&copy, &format!("byte {i} of the summary flipped"));
        std::fs::write(&damaged, &copy).unwrap();
        match LogFile::open(&damaged) {
            Err(LogError::Corrupt { detail }) => {
                assert!(detail.contains("damaged.mcap"), "{detail}")
            }
            other => panic!("byte {i} of the summary flipped: opened as {other:?}"),
        }
    }
}

#[test]
fn a_log_file_streams_the_messages_read_log_reads() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.mcap");
    write_sample_log(&path);
    let all = read_log(&std::fs::read(&path).unwrap()).unwrap();
    let log = LogFile::open(&path).unwrap();
    assert_eq!(log.library(), "ricochet-log tests");
    assert_eq!(log.message_count(), all.len() as u64);
    let streamed: Vec<_> = log.messages().unwrap().map(Result::unwrap).collect();
    assert_eq!(streamed, all);
    let topics: Vec<&str> = log.channels().map(|c| c.topic.as_str()).collect();
    assert_eq!(topics, ["/scene", "/log"]);
    let scene: Vec<_> = log
        .topic_messages("/scene")
        .unwrap()
        .map(Result::unwrap)
        .collect();
    let expected: Vec<_> = all
        .iter()
        .filter(|m| m.topic == "/scene")
        .cloned()
        .collect();
    assert_eq!(scene, expected);
    assert_eq!(
        log.channels().next().unwrap().messages,
        expected.len() as u64
    );
}

#[test]
fn a_log_file_refuses_prefixes_and_damaged_chunks() {
    let dir = tempfile::tempdir().unwrap();
    let bytes = sample_bytes(dir.path());
    let path = dir.path().join("cut.mcap");
    let read = |bytes: &[u8]| {
        std::fs::write(&path, bytes).unwrap();
        LogFile::open(&path).and_then(|l| l.messages()?.collect::<Result<Vec<_>, _>>())
    };
    for len in (0..bytes.len()).step_by(7).chain([bytes.len() - 1]) {
        match read(&bytes[..len]) {
            Err(LogError::Truncated { .. } | LogError::Corrupt { .. }) => {}
            other => panic!("prefix of {len} bytes: {other:?}"),
        }
    }
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let chunk = &summary.chunk_indexes[0];
    let mut damaged = bytes.clone();
    damaged[(chunk.chunk_start_offset + chunk.chunk_length / 2) as usize] ^= 0x55;
    assert!(matches!(read(&damaged), Err(LogError::Corrupt { .. })));
    assert!(read(&bytes).is_ok());
}

/// The files in `dir`, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn an_existing_log_is_replaced_only_by_a_finished_one() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.mcap");
    std::fs::write(&path, b"the old log").unwrap();
    // Written, not finished, dropped: the old file is untouched and no temporary file is left.
    let mut writer = LogWriter::create(&path, "ricochet-log tests").unwrap();
    let channel = writer
        .add_foxglove_channel::<ricochet_log::messages::fox::Log>("/log")
        .unwrap();
    writer.write(channel, 0, log_line(0)).unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), b"the old log");
    let during = listing(dir.path());
    assert_eq!(during.len(), 2, "{during:?}");
    assert!(
        during[0].starts_with(".run.mcap.") && during[0].ends_with(".tmp"),
        "{during:?}"
    );
    drop(writer);
    assert_eq!(std::fs::read(&path).unwrap(), b"the old log");
    assert_eq!(listing(dir.path()), ["run.mcap"]);
    // Finished: the new log replaces it, whole.
    write_sample_log(&path);
    assert_eq!(listing(dir.path()), ["run.mcap"]);
    assert!(read_log_file(&path).is_ok());
    // A directory is not a log file.
    assert!(matches!(
        LogWriter::create(dir.path(), "ricochet-log tests"),
        Err(LogError::Create { .. })
    ));
}
