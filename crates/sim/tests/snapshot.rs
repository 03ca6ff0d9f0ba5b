//! Snapshots (issue #22): a restored simulation steps exactly like the original, equal
//! checksums, another scene refused, damaged bytes refused.

use ricochet_sim::{Simulation, Snapshot, load_scenario};

fn sim(name: &str) -> Simulation {
    let path = format!("{}/../../scenarios/{name}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).expect("scenario file");
    Simulation::new(&load_scenario(&text, name).expect("scenario loads"))
}

/// Snapshots at `at`, runs on, restores a fresh simulation from the bytes, and compares
/// every later frame's output and checksum.
fn restored_steps_identically(name: &str, at: u64, frames: u64) {
    let mut a = sim(name);
    for _ in 0..at {
        a.step();
    }
    let bytes = a.snapshot().to_bytes();
    let mut b = sim(name);
    b.restore(&Snapshot::from_bytes(&bytes).unwrap()).unwrap();
    assert_eq!(b.frame(), at);
    assert_eq!(b.checksum(), a.checksum());
    for _ in 0..frames {
        let (oa, ob) = (a.step(), b.step());
        assert_eq!(oa, ob, "{name} frame {}", oa.frame);
        assert_eq!(a.world().digest(), b.world().digest());
        assert_eq!(a.checksum(), b.checksum(), "{name} frame {}", oa.frame);
    }
}

#[test]
fn a_restored_asteroids_run_steps_like_the_original() {
    restored_steps_identically("asteroids.toml", 40, 400);
}

#[test]
fn a_restored_level_run_steps_like_the_original() {
    restored_steps_identically("level.toml", 120, 400);
}

#[test]
fn restoring_onto_another_scene_is_an_error() {
    let s = sim("asteroids.toml").snapshot();
    let mut other = sim("level.toml");
    assert!(matches!(
        other.restore(&s),
        Err(ricochet_sim::SnapshotError::OtherScene { .. })
    ));
}

#[test]
fn every_truncation_and_bit_flip_is_an_error() {
    let mut a = sim("asteroids.toml");
    for _ in 0..60 {
        a.step();
    }
    let bytes = a.snapshot().to_bytes();
    for n in 0..bytes.len() {
        assert!(
            Snapshot::from_bytes(&bytes[..n]).is_err(),
            "truncated to {n}"
        );
    }
    for bit in (0..bytes.len() * 8).step_by(7) {
        let mut b = bytes.clone();
        b[bit / 8] ^= 1 << (bit % 8);
        assert!(Snapshot::from_bytes(&b).is_err(), "bit {bit}");
    }
}

/// A rollback onto the same bodies (patched in place) at frame 300 of a drifting-asteroids
/// bench scene: the bytes hold little more than each asteroid's position and angle (the
/// issue's bound: 48 bytes a moving body), and the run steps on as it did.
#[test]
fn a_rollback_patches_in_place_and_costs_at_most_48_bytes_a_moving_body() {
    let scene = ricochet_scenes::bench::asteroids(1000, 400);
    let mut a = Simulation::new(&scene);
    for _ in 0..300 {
        a.step();
    }
    let bytes = a.snapshot().to_bytes();
    let moving = a.world().movers().len();
    assert!(
        bytes.len() <= 48 * moving,
        "{} bytes for {moving} moving bodies",
        bytes.len()
    );
    let sum = a.checksum();
    let first: Vec<_> = (0..40).map(|_| a.step()).collect();
    a.restore(&Snapshot::from_bytes(&bytes).unwrap()).unwrap();
    assert_eq!((a.frame(), a.checksum()), (300, sum));
    let again: Vec<_> = (0..40).map(|_| a.step()).collect();
    assert_eq!(first, again);
}
