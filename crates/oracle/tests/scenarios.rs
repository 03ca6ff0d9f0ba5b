//! Every scenario in `scenarios/*.toml` validates against rapier: no unexplained
//! difference, and free flight within its bounds, over the scenario's own frame count.

use ricochet_oracle::{Tolerances, summary_table, validate};

#[test]
fn every_scenario_validates() {
    let dir = format!("{}/../../scenarios", env!("CARGO_MANIFEST_DIR"));
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{dir}: {e}"))
        .map(|entry| entry.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    assert!(files.len() >= 3, "scenarios not found in {dir}");
    let mut failed = Vec::new();
    for path in &files {
        let text = std::fs::read_to_string(path).unwrap();
        let name = path.display().to_string();
        // A scenario may take its level from a Tiled map, as `ricochet validate` reads it.
        let (mut scenario, tiled) =
            ricochet_sim::load_scenario_and_map(&text, &name).unwrap_or_else(|e| panic!("{e}"));
        if let Some(def) = tiled {
            ricochet_tiled::add_map(&mut scenario, &def, path).unwrap_or_else(|e| panic!("{e}"));
        }
        let summary = validate(&scenario, scenario.frames, Tolerances::default());
        let table = summary_table(&summary);
        println!("{table}");
        if !summary.passed() {
            failed.push(table);
        }
    }
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}
