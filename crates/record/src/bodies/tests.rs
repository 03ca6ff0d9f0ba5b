//! `/bodies` read back against the simulation's own states.

use std::path::Path;

use ricochet_log::{BodyStates, LogFile, read_log_file};
use ricochet_scenes::bench::Scene;
use ricochet_sim::{Simulation, World};

use super::{KEYFRAME_BYTES_PER_FRAME, KEYFRAME_INTERVAL};
use crate::Recorder;
use crate::channels::Channels;

/// A body's id, generation and the bits of its position, angle, velocity and angular
/// velocity.
type State = (u64, u64, [u64; 6]);

/// Every body's state in `w`, sorted.
fn states_of(w: &World) -> Vec<State> {
    let mut states: Vec<State> = (0..w.len())
        .map(|i| {
            let (p, v) = (w.position[i], w.velocity(i));
            let e = w.entity[i];
            let bits = [p.x, p.y, w.angle[i], v.x, v.y, w.angular_velocity(i)].map(f64::to_bits);
            (u64::from(e.index), u64::from(e.generation), bits)
        })
        .collect();
    states.sort_unstable();
    states
}

/// `name` recorded for `frames` frames with only `/bodies` into `path`: the world's
/// states at every frame.
fn record(name: &str, frames: u64, path: &Path) -> Vec<Vec<State>> {
    let scenario = Scene::parse(name).unwrap().build(frames);
    let only = Channels::parse("bodies").unwrap();
    let mut recorder = Recorder::create(path, scenario.world.dt, only).unwrap();
    let mut sim = Simulation::new(&scenario);
    let mut want = Vec::new();
    for _ in 0..=frames {
        let out = sim.step();
        recorder.record(&sim, &out).unwrap();
        want.push(states_of(sim.world()));
    }
    recorder.finish().unwrap();
    want
}

/// The log's `/bodies`, rebuilt with [`BodyStates`], frame by frame, sorted.
fn rebuilt(path: &Path) -> Vec<Vec<State>> {
    let log = read_log_file(path).unwrap();
    let mut states = BodyStates::default();
    let num = |v: &serde_json::Value| v.as_f64().unwrap().to_bits();
    log.iter()
        .filter(|m| m.topic == "/bodies")
        .map(|m| {
            let full = states.apply(&m.data);
            let mut got: Vec<State> = full["bodies"]
                .as_array()
                .unwrap()
                .iter()
                .map(|b| {
                    let bits = [
                        num(&b["position"][0]),
                        num(&b["position"][1]),
                        num(&b["angle"]),
                        num(&b["velocity"][0]),
                        num(&b["velocity"][1]),
                        num(&b["angular_velocity"]),
                    ];
                    let id = b["id"].as_u64().unwrap();
                    (id, b["generation"].as_u64().unwrap_or(0), bits)
                })
                .collect();
            got.sort_unstable();
            got
        })
        .collect()
}

/// `/bodies`, rebuilt with [`BodyStates`], gives every body's exact state (bit for bit)
/// at every frame, against the simulation itself: rain (everything falling, landing,
/// wrapping: the `falling` prediction), a platformer (walkers on tiles, gravity, rests)
/// and asteroids (straight lines, spins, bullets spawned and removed).
#[test]
fn bodies_rebuilt_are_the_worlds_states_bit_for_bit() {
    for name in ["rain-300", "platformer-300-60", "asteroids-200"] {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("b.mcap");
        let want = record(name, 150, &path);
        let got = rebuilt(&path);
        assert_eq!(got.len(), 151, "{name}: a /bodies message per frame");
        for (frame, (got, want)) in got.iter().zip(&want).enumerate() {
            assert_eq!(got, want, "{name}, frame {frame}");
        }
    }
}

/// A big scene's keyframes wait for their bytes ([`KEYFRAME_BYTES_PER_FRAME`]), and every
/// frame's bodies are still exact from the keyframe before it.
#[test]
fn a_big_scenes_keyframes_wait_for_their_bytes_and_every_frame_stays_exact() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("k.mcap");
    // 4,000 asteroids: a keyframe of about 700 KB, past the 240 KiB that 60 frames allow,
    // so the next one is at frame 180.
    let want = record("asteroids-4000", 200, &path);
    let file = LogFile::open(&path).unwrap();
    let mut first = file.topic_messages("/bodies").unwrap();
    let bytes = first.next_raw().unwrap().unwrap().bytes().len() as u64;
    let keyframes: Vec<u64> = read_log_file(&path)
        .unwrap()
        .iter()
        .filter(|m| m.data["keyframe"] == true)
        .map(|m| m.data["frame"].as_u64().unwrap())
        .collect();
    let wait = bytes.div_ceil(KEYFRAME_BYTES_PER_FRAME);
    assert!(wait > KEYFRAME_INTERVAL, "{bytes} bytes: a big keyframe");
    assert_eq!(keyframes, [0, wait.next_multiple_of(KEYFRAME_INTERVAL)]);
    let got = rebuilt(&path);
    assert_eq!(got.len(), want.len());
    for (frame, (got, want)) in got.iter().zip(&want).enumerate() {
        assert!(got == want, "frame {frame}: rebuilt states differ");
    }
}
