//! The kinetic energy a step reports (`FrameStats::kinetic_energy`) is, every frame, the sum
//! of `½ m v²` over the dynamic bodies in id order, summed here from the world's public
//! columns: whatever the step did (impulses, contacts, gravity, spawns, removals, a restore),
//! and though the step keeps its last sum while no velocity changes.

use ricochet_sim::{Action, BodyKind, Simulation, Vec2, load_scenario};

fn sim(name: &str) -> Simulation {
    let path = format!("{}/../../scenarios/{name}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).expect("scenario file");
    Simulation::new(&load_scenario(&text, name).expect("scenario loads"))
}

/// `½ m |v|²` of every dynamic body, in id (dense) order.
fn summed(sim: &Simulation) -> f64 {
    let w = sim.world();
    (0..w.len())
        .filter(|&i| w.kind[i] == BodyKind::Dynamic)
        .map(|i| 0.5 * w.mass(i) * w.velocity(i).length_squared())
        .sum()
}

#[test]
fn every_frames_kinetic_energy_is_the_sum_of_its_bodies() {
    for name in [
        "asteroids.toml",
        "platformer.toml",
        "arcade.toml",
        "shapes.toml",
        "level.toml",
    ] {
        let mut s = sim(name);
        for _ in 0..400 {
            let out = s.step();
            let e = out.stats.kinetic_energy;
            assert_eq!(
                e.to_bits(),
                summed(&s).to_bits(),
                "{name} frame {}",
                out.frame
            );
        }
    }
}

#[test]
fn a_restored_run_reports_the_restored_bodies_energy() {
    // Nothing changes a velocity in this scene (no force, no response but reports): the
    // sum is kept frame to frame, until the impulse below.
    let mut s = Simulation::new(&ricochet_scenes::bench::asteroids(200, 300));
    for _ in 0..30 {
        s.step();
    }
    let before = s.snapshot();
    let w = s.world();
    let dynamic = (0..w.len())
        .find(|&i| w.kind[i] == BodyKind::Dynamic)
        .expect("a dynamic body");
    let e = w.entity[dynamic];
    s.apply(e, Action::ApplyImpulse(Vec2::new(50.0, 0.0)))
        .unwrap();
    let pushed = s.step().stats.kinetic_energy;
    for _ in 0..20 {
        assert_eq!(s.step().stats.kinetic_energy.to_bits(), pushed.to_bits());
    }
    s.restore(&before).unwrap();
    for _ in 0..20 {
        let out = s.step();
        let e = out.stats.kinetic_energy;
        assert_eq!(e.to_bits(), summed(&s).to_bits(), "frame {}", out.frame);
        assert_ne!(e.to_bits(), pushed.to_bits(), "frame {}", out.frame);
    }
}
