//! How long a scenario with a `[tiled]` map takes to load, map included (the figure README's
//! "Your level from Tiled" quotes): `cargo run --release -p ricochet-tiled --example load_time
//! -- SCENARIO.toml`.

use std::path::Path;
use std::time::Instant;

fn main() {
    let Some(path) = std::env::args().nth(1) else {
        eprintln!("usage: load_time SCENARIO.toml");
        std::process::exit(2);
    };
    let path = Path::new(&path);
    let start = Instant::now();
    let text = std::fs::read_to_string(path).expect("the scenario reads");
    let (mut scenario, def) =
        ricochet_sim::load_scenario_and_map(&text, &path.display().to_string())
            .unwrap_or_else(|e| panic!("{e}"));
    let def = def.expect("a [tiled] table");
    let summary =
        ricochet_tiled::add_map(&mut scenario, &def, path).unwrap_or_else(|e| panic!("{e}"));
    let loaded = start.elapsed();
    let sim = ricochet_sim::Simulation::new(&scenario);
    println!(
        "{}: {} static tiles in {} tile rows, {} bodies in the simulation; loaded in {:.3} s, \
         simulation built in {:.3} s more",
        path.display(),
        summary.tiles,
        scenario.tiles.iter().map(|t| t.rows.len()).sum::<usize>(),
        sim.world().len(),
        loaded.as_secs_f64(),
        (start.elapsed() - loaded).as_secs_f64()
    );
}
