//! Snapshots (issue #22): a restored simulation steps exactly like the original, equal
//! checksums, another scene refused, damaged bytes refused.

use ricochet_sim::{Action, BodyKind, Simulation, Snapshot, Vec2, load_scenario};

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

/// A constant force set during a run is part of the state a snapshot holds: restored, it
/// acts again (the forces stage runs), and a restored zero force stops acting.
#[test]
fn a_restored_force_acts_and_a_restored_zero_force_does_not() {
    let mut a = sim("asteroids.toml");
    a.step();
    let w = a.world();
    let dynamic = (w.movers().iter().map(|&i| i as usize))
        .find(|&i| w.kind[i] == BodyKind::Dynamic)
        .expect("a dynamic body");
    let e = w.entity[dynamic];
    a.set_force(e, Vec2::new(3000.0, -2000.0)).unwrap();
    a.step();
    let with_force = a.snapshot();
    let run = |a: &mut Simulation| -> Vec<_> { (0..5).map(|_| (a.step(), a.checksum())).collect() };
    let pushed = run(&mut a);
    a.set_force(e, Vec2::ZERO).unwrap();
    let without = a.snapshot();
    let coasting = run(&mut a);
    assert_ne!(
        pushed[4].0.stats.kinetic_energy,
        coasting[4].0.stats.kinetic_energy
    );
    a.restore(&with_force).unwrap();
    assert_eq!(run(&mut a), pushed);
    a.restore(&without).unwrap();
    assert_eq!(run(&mut a), coasting);
}

/// A ship's thrust input is part of the state a snapshot holds: restored on, the engine
/// pushes again (the forces stage runs); restored off, it stops.
#[test]
fn a_restored_thrust_input_pushes_and_a_restored_idle_engine_does_not() {
    let mut a = sim("asteroids.toml");
    a.step();
    let w = a.world();
    let ship = w.entity[w.find("ship").expect("the ship")];
    a.apply(ship, Action::Thrust(true)).unwrap();
    a.step();
    let thrusting = a.snapshot();
    let run = |a: &mut Simulation| -> Vec<_> { (0..5).map(|_| (a.step(), a.checksum())).collect() };
    let pushed = run(&mut a);
    a.apply(ship, Action::Thrust(false)).unwrap();
    a.step();
    let idle = a.snapshot();
    let coasting = run(&mut a);
    let energy =
        |frames: &[(ricochet_sim::FrameOutput, u64)], k: usize| frames[k].0.stats.kinetic_energy;
    // The engine adds energy while on; nothing else here does (the rocks drift).
    assert!(energy(&pushed, 4) > energy(&pushed, 0), "the engine pushes");
    assert_eq!(
        energy(&coasting, 4),
        energy(&coasting, 0),
        "an idle engine does not"
    );
    a.restore(&thrusting).unwrap();
    assert_eq!(run(&mut a), pushed);
    a.restore(&idle).unwrap();
    assert_eq!(run(&mut a), coasting);
}

/// The snapshot format's checksum (module docs: XXH3-64 of every byte before it, with the
/// format's fixed seed, "RCSN" and version 2), recomputed after an edit as an attacker can.
fn resealed(mut bytes: Vec<u8>) -> Vec<u8> {
    let n = bytes.len() - 8;
    let sum = xxhash_rust::xxh3::xxh3_64_with_seed(&bytes[..n], 0x5243_534e_0000_0002);
    bytes[n..].copy_from_slice(&sum.to_le_bytes());
    bytes
}

/// Issue #34: one bit flipped in the ship's `bullet_speed` (30 → 30 · 2^64 ≈ 5.5e20, the
/// exponent's 64s bit) with the checksum recomputed restored, and then each step took about
/// a second. The loader refuses a `bullet_speed` past ±1e15; so does `restore`, naming the
/// field, and the simulation is unchanged.
#[test]
fn a_restored_bullet_speed_past_the_loaders_limit_is_refused_and_nothing_changes() {
    let mut a = sim("asteroids.toml");
    for _ in 0..60 {
        a.step();
    }
    let bytes = a.snapshot().to_bytes();
    let thirty = 30f64.to_le_bytes();
    let at: Vec<usize> = (0..bytes.len() - 8)
        .filter(|&k| bytes[k..k + 8] == thirty)
        .collect();
    assert_eq!(
        at.len(),
        1,
        "one 30.0 in the state: the ship's bullet_speed"
    );
    let mut flipped = bytes.clone();
    // Bit 58 of the little-endian u64: bit 2 of its last byte.
    flipped[at[0] + 7] ^= 1 << 2;
    let speed = f64::from_le_bytes(flipped[at[0]..at[0] + 8].try_into().unwrap());
    assert_eq!(speed, 30.0 * 2f64.powi(64));
    let s = Snapshot::from_bytes(&resealed(flipped)).expect("the checksum holds");
    let mut b = sim("asteroids.toml");
    for _ in 0..10 {
        b.step();
    }
    let (frame, sum) = (b.frame(), b.checksum());
    match b.restore(&s) {
        Err(ricochet_sim::SnapshotError::Malformed { what }) => {
            assert!(what.contains("bullet_speed"), "{what}");
        }
        other => panic!("restored: {other:?}"),
    }
    assert_eq!((b.frame(), b.checksum()), (frame, sum));
    // The same snapshot unflipped restores.
    b.restore(&Snapshot::from_bytes(&bytes).unwrap()).unwrap();
    assert_eq!(b.checksum(), a.checksum());
}

#[test]
fn a_bullet_speed_past_1e15_is_refused_at_load_by_name() {
    let path = format!(
        "{}/../../scenarios/asteroids.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).expect("scenario file");
    let text = text.replacen("bullet_speed = 30", "bullet_speed = 5.5e20", 1);
    let e = load_scenario(&text, "asteroids.toml")
        .expect_err("refused")
        .to_string();
    assert!(e.contains("controller.bullet_speed"), "{e}");
    let ok = text.replacen("bullet_speed = 5.5e20", "bullet_speed = 1e15", 1);
    assert!(load_scenario(&ok, "asteroids.toml").is_ok());
}
