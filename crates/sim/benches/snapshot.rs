//! Snapshot micro-benchmarks on the `asteroids-10000` bench scene at frame 300: each part of
//! the round trip (`snapshot`, `to_bytes`, `from_bytes`, `restore` onto the same bodies) and
//! the `checksum`, one at a time, so a profile of one names its own bound. `ricochet bench
//! --snapshots` gives the same figures beside rapier's serde snapshot; this is the one to run
//! under `perf record` (it links no rapier).
//!
//! Run: `cargo bench -p ricochet-sim --bench snapshot`

use divan::{Bencher, black_box};
use ricochet_sim::{Simulation, Snapshot};

fn main() {
    divan::main();
}

/// The scene stepped to frame 300, and a snapshot of it there.
fn scene() -> (Simulation, Snapshot) {
    let mut sim = Simulation::new(&ricochet_scenes::bench::asteroids(10_000, 600));
    for _ in 0..300 {
        sim.step();
    }
    let snap = sim.snapshot();
    (sim, snap)
}

#[divan::bench]
fn snapshot(b: Bencher) {
    let (sim, _) = scene();
    b.bench(|| black_box(sim.snapshot()));
}

#[divan::bench]
fn to_bytes(b: Bencher) {
    let (_, snap) = scene();
    b.bench(|| black_box(snap.to_bytes()));
}

#[divan::bench]
fn from_bytes(b: Bencher) {
    let (_, snap) = scene();
    let bytes = snap.to_bytes();
    b.bench(|| black_box(Snapshot::from_bytes(&bytes).unwrap()));
}

/// Restored onto the same bodies 8 frames later: the rollback case.
#[divan::bench]
fn restore(b: Bencher) {
    let (mut sim, snap) = scene();
    for _ in 0..8 {
        sim.step();
    }
    b.bench_local(|| sim.restore(black_box(&snap)).unwrap());
}

#[divan::bench]
fn checksum(b: Bencher) {
    let (sim, _) = scene();
    b.bench(|| black_box(sim.checksum()));
}
