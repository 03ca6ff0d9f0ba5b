//! Every broad phase, forced by the scenario, gives the same simulation: the choice changes
//! speed only. Each shipped scenario runs under all seven settings and every frame's state,
//! contacts, events and removals are compared with brute force (the O(n²) reference).

use ricochet_sim::broad_phase::BroadPhaseKind;
use ricochet_sim::{Simulation, load_scenario};

const SCENARIOS: [&str; 7] = [
    "asteroids.toml",
    "level.toml",
    "platformer.toml",
    "shapes.toml",
    "validation.toml",
    "stress/stack-50.toml",
    "stress/extreme-sizes.toml",
];

const KINDS: [BroadPhaseKind; 7] = [
    BroadPhaseKind::BruteForce,
    BroadPhaseKind::SortAndSweep,
    BroadPhaseKind::Grid,
    BroadPhaseKind::Strips,
    BroadPhaseKind::Quadtree,
    BroadPhaseKind::Tree,
    BroadPhaseKind::Auto,
];

#[test]
fn every_broad_phase_gives_the_same_simulation() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios");
    for name in SCENARIOS {
        let text = std::fs::read_to_string(dir.join(name)).unwrap();
        let scenario = load_scenario(&text, name).unwrap();
        let mut sims: Vec<Simulation> = KINDS
            .iter()
            .map(|&kind| {
                let mut s = scenario.clone();
                s.world.broad_phase = kind;
                Simulation::new(&s)
            })
            .collect();
        let mut ran = [false; KINDS.len()];
        for frame in 0..=200 {
            let outs: Vec<_> = sims.iter_mut().map(Simulation::step).collect();
            let reference = &outs[0];
            for (k, out) in outs.iter().enumerate() {
                let kind = KINDS[k];
                let what = format!("{name} frame {frame} {kind:?}");
                assert_eq!(sims[k].world().digest(), sims[0].world().digest(), "{what}");
                assert_eq!(out.contacts, reference.contacts, "{what}");
                assert_eq!(out.events, reference.events, "{what}");
                assert_eq!(out.removed, reference.removed, "{what}");
                assert_eq!(out.stats.broad_pairs, reference.stats.broad_pairs, "{what}");
                // The forced algorithm is the one that ran.
                if out.stats.broad_phase.is_some() && kind != BroadPhaseKind::Auto {
                    assert_eq!(out.stats.broad_phase, Some(kind), "{what}");
                    ran[k] = true;
                }
            }
        }
        assert!(
            ran[..KINDS.len() - 1].iter().all(|r| *r),
            "{name}: detect ran under every kind"
        );
    }
}
