//! The parallel stages change the time, never a byte: every shipped scenario, and a crowd
//! big enough for `detect`'s narrow phase to go to the workers (pairs pushed apart by earlier
//! pairs of the same pass included), gives the same log with 1 and 2 threads.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

/// 1600 balls and rocks piled into a box on a floor: every one `separate`s from its
/// neighbours, so a pass pushes bodies that later pairs of the same pass meet again.
fn crowd() -> String {
    let mut text = String::from(
        "hz = 60\nlayers = [\"ball\", \"wall\"]\nframes = 90\n[world]\ngravity = [0, -9.81]\n\
         [[collide]]\na = \"ball\"\nb = \"ball\"\nresponse = \"separate\"\n\
         [[collide]]\na = \"ball\"\nb = \"wall\"\nresponse = \"separate\"\n\
         [[bodies]]\nlayer = \"wall\"\nkind = \"static\"\n\
         shape = { kind = \"aabb\", half_extents = [30, 1] }\nposition = [0, -1]\n",
    );
    let mut rng = ricochet_scenes::Rng::new(15);
    for k in 0..1600 {
        let (x, y) = (rng.range(-20.0, 20.0), rng.range(0.0, 40.0));
        let shape = if k % 2 == 0 {
            format!(
                "{{ kind = \"circle\", radius = {:.3} }}",
                rng.range(0.3, 0.7)
            )
        } else {
            "{ kind = \"polygon\", vertices = [[-0.5, -0.4], [0.5, -0.4], [0.1, 0.5]] }".to_owned()
        };
        writeln!(
            text,
            "[[bodies]]\nlayer = \"ball\"\nshape = {shape}\nposition = [{x:.3}, {y:.3}]"
        )
        .unwrap();
    }
    text
}

fn run(scenario: &Path, out: &Path, threads: &str) -> Vec<u8> {
    let o = Command::new(env!("CARGO_BIN_EXE_ricochet"))
        .args([
            "run",
            scenario.to_str().unwrap(),
            "--threads",
            threads,
            "-o",
        ])
        .arg(out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::read(out).unwrap()
}

#[test]
fn the_crowd_sends_its_narrow_phase_to_the_workers() {
    // The premise of the byte comparison below: enough pairs for the pool (256), and pushes.
    let scenario = ricochet_sim::load_scenario(&crowd(), "crowd.toml").unwrap();
    let mut sim = ricochet_sim::Simulation::new(&scenario);
    sim.set_threads(2);
    assert_eq!(sim.threads(), 2);
    let mut busy = 0;
    for _ in 0..30 {
        let out = sim.step();
        let pushes = out
            .contacts
            .iter()
            .filter(|c| {
                use ricochet_sim::{Phase, Response};
                c.response == Response::Separate && matches!(c.phase, Phase::All | Phase::Swept)
            })
            .count();
        if out.stats.narrow_tests >= 256 && pushes >= 50 {
            busy += 1;
        }
    }
    assert!(
        busy >= 20,
        "{busy} of 30 frames with 256 tests and 50 pushes"
    );
}

#[test]
fn one_and_two_threads_write_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let crowd_path = dir.path().join("crowd.toml");
    std::fs::write(&crowd_path, crowd()).unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut scenarios: Vec<PathBuf> = vec![crowd_path];
    for sub in ["scenarios", "scenarios/stress"] {
        let mut found: Vec<PathBuf> = std::fs::read_dir(root.join(sub))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .collect();
        found.sort();
        scenarios.extend(found);
    }
    assert!(scenarios.len() >= 8, "the shipped scenarios and the crowd");
    for s in &scenarios {
        let one = run(s, &dir.path().join("one.mcap"), "1");
        let two = run(s, &dir.path().join("two.mcap"), "2");
        assert!(one.len() > 10_000, "{}: a real log", s.display());
        assert!(one == two, "{}: 1 and 2 threads differ", s.display());
    }
}
