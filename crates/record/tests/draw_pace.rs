//! The drawing's pace (`src/pace.rs`), read back from logs: a big scene's drawing waits
//! `ceil(bytes / DRAW_BYTES_PER_FRAME)` frames after a drawing of `bytes` encoded bytes, a
//! small one is drawn every frame, and `/bodies` is in every frame either way. The bytes
//! are the sizes of the messages in the file, as any reader sees them.

use std::collections::BTreeMap;
use std::path::Path;

use ricochet_log::LogFile;
use ricochet_record::{Channels, DRAW_BYTES_PER_FRAME, Recorder};
use ricochet_scenes::bench::Scene;
use ricochet_sim::Simulation;

const SCENE_TOPICS: [&str; 4] = ["/scene", "/scene/static", "/tf", "/scene/contacts"];

/// Frame → (scene-channel bytes, `/scene` messages, `/bodies` messages, `/scene/static`
/// messages), for each frame of `name` recorded for `frames` frames.
fn record(name: &str, frames: u64, every_frame: bool, path: &Path) -> BTreeMap<u64, [u64; 4]> {
    let scenario = Scene::parse(name).unwrap().build(frames);
    let mut recorder = Recorder::create(path, scenario.world.dt, Channels::default()).unwrap();
    if every_frame {
        recorder.draw_every_frame();
    }
    let mut sim = Simulation::new(&scenario);
    for _ in 0..=frames {
        let out = sim.step();
        recorder.record(&sim, &out).unwrap();
    }
    let dt_ns = recorder.dt_ns();
    recorder.finish().unwrap();
    let log = LogFile::open(path).unwrap();
    let mut messages = log.messages().unwrap();
    let mut by_frame: BTreeMap<u64, [u64; 4]> = BTreeMap::new();
    while let Some(m) = messages.next_raw() {
        let m = m.unwrap();
        assert_eq!(m.log_time() % dt_ns, 0);
        let row = by_frame.entry(m.log_time() / dt_ns).or_default();
        if SCENE_TOPICS.contains(&m.topic()) {
            row[0] += m.bytes().len() as u64;
        }
        row[1] += u64::from(m.topic() == "/scene");
        row[2] += u64::from(m.topic() == "/bodies");
        row[3] += u64::from(m.topic() == "/scene/static");
    }
    by_frame
}

#[test]
fn a_big_scene_is_drawn_after_its_bytes_and_its_bodies_every_frame() {
    let dir = tempfile::tempdir().unwrap();
    // 2,000 asteroids, every one moving every frame: about 300 KB a drawing, every 25th
    // frame.
    let frames = 300;
    let log = record("asteroids-2000", frames, false, &dir.path().join("a.mcap"));
    assert_eq!(log.len() as u64, frames + 1);
    assert!(
        log.values().all(|row| row[2] == 1),
        "/bodies in every frame"
    );
    let drawn: Vec<(u64, u64)> = log
        .iter()
        .filter(|(_, row)| row[0] > 0)
        .map(|(&f, row)| (f, row[0]))
        .collect();
    assert_eq!(drawn[0].0, 0, "frame 0 is drawn");
    for pair in drawn.windows(2) {
        let ((f, bytes), (next, _)) = (pair[0], pair[1]);
        let wait = bytes.div_ceil(DRAW_BYTES_PER_FRAME).max(1);
        assert!(wait > 1, "frame {f}: {bytes} bytes is a big drawing");
        // Every asteroid moves every frame: the drawing is due as soon as it may be.
        assert_eq!(next, f + wait, "frame {f} drew {bytes} bytes");
    }
    assert!(
        drawn.len() > 10,
        "{} drawings in {frames} frames",
        drawn.len()
    );
    let scenes: u64 = log.values().map(|row| row[1]).sum();
    assert_eq!(scenes, drawn.len() as u64, "one whole /scene per drawing");
}

#[test]
fn a_big_scenes_static_bodies_are_drawn_once_when_none_changes() {
    let dir = tempfile::tempdir().unwrap();
    // 300 static tiles and 100 actors (batched: over 256 bodies), drawn at frame 0 and
    // again as the budget allows; the tiles never move.
    let log = record("platformer-300-100", 120, false, &dir.path().join("p.mcap"));
    let drawings = log.values().filter(|row| row[1] > 0).count();
    assert!(drawings > 2, "{drawings} drawings of /scene");
    let statics: Vec<u64> = log
        .iter()
        .filter(|(_, row)| row[3] > 0)
        .map(|(&f, _)| f)
        .collect();
    assert_eq!(statics, [0], "/scene/static at the first frame only");
}

#[test]
fn drawing_every_frame_draws_the_big_scene_in_every_frame() {
    let dir = tempfile::tempdir().unwrap();
    let log = record("asteroids-2000", 30, true, &dir.path().join("a.mcap"));
    assert!(log.values().all(|row| row[1] == 1), "/scene in every frame");
}

#[test]
fn a_scene_drawn_per_body_is_drawn_every_frame_the_same_bytes_either_way() {
    let dir = tempfile::tempdir().unwrap();
    let (paced, every) = (dir.path().join("p.mcap"), dir.path().join("e.mcap"));
    let log = record("asteroids-100", 60, false, &paced);
    // 201 bodies, drawn one entity each with its metadata: more than the budget a frame,
    // drawn every frame all the same (a scene of at most 256 bodies is small).
    let biggest = log.values().map(|row| row[0]).max().unwrap();
    assert!(biggest > DRAW_BYTES_PER_FRAME, "{biggest} bytes");
    assert!(log.values().all(|row| row[1] == 1), "/scene in every frame");
    record("asteroids-100", 60, true, &every);
    assert!(std::fs::read(&paced).unwrap() == std::fs::read(&every).unwrap());
}
