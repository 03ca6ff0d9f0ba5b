//! Writing logs and reading them back: determinism, round trip, and refusal
//! of truncated or damaged files.

mod common;

use std::path::Path;

use common::{STEP_NS, STEPS, deletion_scene, full_scene, log_line, write_sample_log};
use ricochet_log::{LogError, LogWriter, read_log, read_log_file};

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
fn written_log_reads_back_unchanged() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.mcap");
    write_sample_log(&path);
    let messages = read_log_file(&path).unwrap();

    let mut expected = Vec::new();
    for step in 0..STEPS {
        let time_ns = step * STEP_NS;
        let scene = serde_json::to_value(full_scene(time_ns)).unwrap();
        let log = serde_json::to_value(log_line(time_ns)).unwrap();
        expected.push((
            "/scene",
            "foxglove.SceneUpdate",
            time_ns,
            step as u32,
            scene,
        ));
        expected.push(("/log", "foxglove.Log", time_ns, step as u32, log));
    }
    let end_ns = STEPS * STEP_NS;
    let deletion = serde_json::to_value(deletion_scene(end_ns)).unwrap();
    expected.push((
        "/scene",
        "foxglove.SceneUpdate",
        end_ns,
        STEPS as u32,
        deletion,
    ));

    assert_eq!(messages.len(), expected.len());
    for (got, (topic, schema_name, time_ns, sequence, data)) in messages.iter().zip(&expected) {
        assert_eq!(got.topic, *topic);
        assert_eq!(got.schema_name, *schema_name);
        assert_eq!(got.log_time, *time_ns);
        assert_eq!(got.publish_time, *time_ns);
        assert_eq!(got.sequence, *sequence);
        assert_eq!(got.data, *data);
    }
}

#[test]
fn log_finished_early_is_complete() {
    // What the binary does on Ctrl-C: stop writing and finish.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("interrupted.mcap");
    let mut writer = LogWriter::create(&path, "ricochet-log tests").unwrap();
    let scene = writer.add_scene_channel("/scene").unwrap();
    let _unused = writer.add_log_channel("/log").unwrap();
    writer.write(scene, 5, &full_scene(5)).unwrap();
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
