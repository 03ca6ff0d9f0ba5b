//! A big scene's drawing: the 10,000 moving bodies of the `asteroids-10000` bench scene at
//! frame 300, drawn as `/scene` is (batched), three ways: the message built
//! (`scene::snapshot`), built then encoded by prost (what recording did before
//! `scene/encoded.rs`), and encoded as it is drawn (`scene::snapshot_encoded`, what the
//! recorder writes). The last two give the same bytes (the crate's tests compare them).
//!
//! Run: `cargo bench -p ricochet-record --bench drawing`

use divan::{Bencher, black_box};
use prost::Message;
use ricochet_log::messages::fox::Timestamp;
use ricochet_record::scene::{Style, snapshot, snapshot_encoded};
use ricochet_sim::Simulation;

fn main() {
    divan::main();
}

/// The scene stepped to frame 300.
fn scene() -> Simulation {
    let mut sim = Simulation::new(&ricochet_scenes::bench::asteroids(10_000, 600));
    for _ in 0..300 {
        sim.step();
    }
    sim
}

const AT: Timestamp = Timestamp::MIN;

#[divan::bench]
fn built(b: Bencher) {
    let sim = scene();
    let (w, layers) = (sim.world(), &sim.scenario().world.layers);
    b.bench(|| black_box(snapshot(w, layers, false, Style::Batched, AT)));
}

#[divan::bench]
fn built_then_encoded(b: Bencher) {
    let sim = scene();
    let (w, layers) = (sim.world(), &sim.scenario().world.layers);
    b.bench(|| black_box(snapshot(w, layers, false, Style::Batched, AT).encode_to_vec()));
}

#[divan::bench]
fn encoded_as_drawn(b: Bencher) {
    let sim = scene();
    let (w, layers) = (sim.world(), &sim.scenario().world.layers);
    b.bench(|| black_box(snapshot_encoded(w, layers, false, Style::Batched, AT)));
}
