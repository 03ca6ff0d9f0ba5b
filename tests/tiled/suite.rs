//! `ricochet test` golden-checks a scenario that takes its level from a Tiled map, as it
//! does the others: the golden it blesses is the log `ricochet run` writes of the same level
//! (so the map's bodies are in it), and a changed map fails the check.

use crate::util::{ricochet_in, root};

/// A folder holding `scenarios/tiled_level.toml` and its map, as a game's repository would.
fn level_copy() -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("a temporary folder");
    std::fs::create_dir_all(dir.path().join("levels/maps")).unwrap();
    let from = root().join("scenarios");
    std::fs::copy(
        from.join("tiled_level.toml"),
        dir.path().join("levels/tiled_level.toml"),
    )
    .unwrap();
    std::fs::copy(
        from.join("maps/level1.tmx"),
        dir.path().join("levels/maps/level1.tmx"),
    )
    .unwrap();
    dir
}

fn stdout(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr)
}

#[test]
fn test_blesses_a_tiled_level_as_run_records_it_and_fails_when_the_map_changes() {
    let dir = level_copy();
    let o = ricochet_in(
        dir.path(),
        &["test", "levels", "--golden", "golden", "--bless"],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
    let o = ricochet_in(
        dir.path(),
        &["run", "levels/tiled_level.toml", "-o", "run.mcap"],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
    let golden = std::fs::read(dir.path().join("golden/tiled_level.mcap")).unwrap();
    assert!(
        golden == std::fs::read(dir.path().join("run.mcap")).unwrap(),
        "the golden is not the log `ricochet run` writes of the level"
    );
    let o = ricochet_in(dir.path(), &["test", "levels", "--golden", "golden"]);
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));

    // The ramp polygon of the "Terrain" layer moved one pixel right: the level changed.
    let map = dir.path().join("levels/maps/level1.tmx");
    let text = std::fs::read_to_string(&map).unwrap();
    let moved = move_ramp(&text);
    assert_ne!(moved, text);
    std::fs::write(&map, moved).unwrap();
    let o = ricochet_in(dir.path(), &["test", "levels", "--golden", "golden"]);
    assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
    assert!(stdout(&o).contains("0 passed, 1 failed"), "{}", stdout(&o));
}

/// The map's text with the object named "ramp" moved one pixel in x.
fn move_ramp(text: &str) -> String {
    let start = text
        .find("name=\"ramp\"")
        .expect("the ramp object in the map");
    let x_at = start + text[start..].find(" x=\"").expect("its x") + 4;
    let end = x_at + text[x_at..].find('"').unwrap();
    let x: f64 = text[x_at..end].parse().unwrap();
    format!("{}{}{}", &text[..x_at], x + 1.0, &text[end..])
}
