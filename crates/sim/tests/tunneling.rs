//! Fast bodies never pass through what they hit: swept tests (time of impact) for pairs in
//! `fast_layers`, checked at 10,000 units/s against a 0.5-unit asteroid and a thin wall.

use ricochet_geom::{Shape, Vec2};
use ricochet_scenes::{layers, scenario};
use ricochet_sim::{BodyDef, BodyKind, Doomed, Phase, Response, Simulation, WorldDef};

const BULLET: u8 = 0;
const ROCK: u8 = 1;
const WALL: u8 = 2;

/// A body of `layer` named `name`: a circle of `radius` at `at`.
fn disc(name: &str, layer: u8, radius: f64, at: Vec2) -> BodyDef {
    BodyDef {
        name: name.to_owned(),
        layer,
        shape: Shape::circle(radius).unwrap(),
        position: at,
        ..BodyDef::default()
    }
}

/// A bullet (radius 0.05) at 10,000 units/s along +x, 60 Hz: 166.7 units a frame. Rocks
/// destroy it (and it them); walls report.
fn scene(fast: bool, targets: Vec<BodyDef>) -> Simulation {
    let mut l = layers(
        &["bullet", "rock", "wall"],
        &[
            (BULLET, ROCK, Response::Destroy(Doomed::Both)),
            (BULLET, WALL, Response::Report),
        ],
    );
    if fast {
        l.set_fast(BULLET);
    }
    let world = WorldDef {
        layers: l,
        ..WorldDef::default()
    };
    let mut bullet = disc("bullet", BULLET, 0.05, Vec2::new(-30.0, 0.2));
    bullet.velocity = Vec2::new(10_000.0, 0.0);
    let bodies = std::iter::once(bullet).chain(targets).collect();
    Simulation::new(&scenario("tunnel", world, bodies, 600))
}

/// The rock of radius 0.5 at x = 40, on the bullet's path.
fn rock() -> Vec<BodyDef> {
    vec![disc("rock", ROCK, 0.5, Vec2::new(40.0, 0.0))]
}

fn alive(sim: &Simulation, name: &str) -> bool {
    sim.world().find(name).is_some()
}

#[test]
fn without_sweeping_the_bullet_tunnels_through_the_rock() {
    // The control: proves the scene really is a tunnelling case.
    let mut sim = scene(false, rock());
    for _ in 0..3 {
        sim.step();
    }
    assert!(
        alive(&sim, "rock"),
        "an unswept bullet skips over a 0.5-unit rock"
    );
    assert!(sim.world().position[0].x > 300.0);
}

#[test]
fn a_swept_bullet_at_10000_units_per_second_hits_a_half_unit_rock() {
    let mut sim = scene(true, rock());
    sim.step();
    let out = sim.step();
    assert!(
        !alive(&sim, "rock") && !alive(&sim, "bullet"),
        "{:?}",
        out.events
    );
    let hit = &out.contacts[0];
    assert_eq!(hit.phase, Phase::Swept);
    // First touch: the bullet's centre 0.55 short of the rock's, on the line y = 0.2.
    let touch_x = 40.0 - (0.55f64 * 0.55 - 0.2 * 0.2).sqrt();
    assert!(
        (hit.pose_a.position.x - touch_x).abs() < 1e-6,
        "{:?}",
        hit.pose_a
    );
    assert!(
        hit.depth > -1e-6 && hit.depth < 1e-6,
        "touching, not deep: {}",
        hit.depth
    );
}

#[test]
fn a_swept_bullet_hits_only_the_first_rock_on_its_path() {
    let rocks = [60.0, 20.0, 100.0]
        .iter()
        .enumerate()
        .map(|(k, &x)| disc(&format!("rock{k}"), ROCK, 0.5, Vec2::new(x, 0.0)))
        .collect();
    let mut sim = scene(true, rocks);
    sim.step();
    let out = sim.step();
    assert_eq!(out.contacts.len(), 1, "{:?}", out.contacts);
    assert!(
        !alive(&sim, "rock1"),
        "the rock at x = 20 is first on the path"
    );
    assert!(alive(&sim, "rock0") && alive(&sim, "rock2"));
}

#[test]
fn a_swept_bullet_never_passes_a_thin_wall() {
    let wall = vec![BodyDef {
        name: "wall".to_owned(),
        layer: WALL,
        kind: BodyKind::Static,
        shape: Shape::obb(Vec2::new(0.01, 5.0)).unwrap(),
        position: Vec2::new(50.0, 0.0),
        angle: 0.3,
        ..BodyDef::default()
    }];
    let mut unswept = scene(false, wall.clone());
    let mut swept = scene(true, wall);
    let (mut missed, mut hits) = (0, Vec::new());
    for _ in 0..4 {
        missed += unswept.step().contacts.len();
        hits.extend(swept.step().contacts);
    }
    assert_eq!(missed, 0, "the control tunnels");
    assert_eq!(hits.len(), 1, "{hits:?}");
    assert_eq!(hits[0].phase, Phase::Swept);
    // The wall's normal is (cos 0.3, sin 0.3). The bullet's centre touches when it is 0.01 +
    // 0.05 behind the wall's centre plane: (x - 50) cos 0.3 + 0.2 sin 0.3 = -0.06.
    let (s, c) = (libm::sin(0.3), libm::cos(0.3));
    let touch = 50.0 - 0.2 * s / c - 0.06 / c;
    assert!(
        (hits[0].pose_a.position.x - touch).abs() < 1e-6,
        "{:?} vs {touch}",
        hits[0].pose_a
    );
}

/// A grazing path: the bullet's path passes `miss` between centres of a rock of radius 0.5,
/// the bullet itself radius 0.5, at 600 units/s (10 units a frame).
fn graze(miss: f64) -> Vec<ricochet_sim::ContactRecord> {
    let mut l = layers(&["bullet", "rock"], &[(BULLET, ROCK, Response::Report)]);
    l.set_fast(BULLET);
    let world = WorldDef {
        layers: l,
        ..WorldDef::default()
    };
    let mut bullet = disc("body", BULLET, 0.5, Vec2::new(-5.0, miss));
    bullet.velocity = Vec2::new(600.0, 0.0);
    let rock = disc("body", ROCK, 0.5, Vec2::ZERO);
    let mut sim = Simulation::new(&scenario("graze", world, vec![bullet, rock], 600));
    (0..3).flat_map(|_| sim.step().contacts).collect()
}

#[test]
fn a_grazing_swept_hit_is_found_at_its_first_touch() {
    // 0.01 deep at the closest approach: a hit, at x = -sqrt(1 - 0.99^2).
    let hits = graze(0.99);
    assert_eq!(hits.len(), 1, "{hits:?}");
    let want = -(1.0f64 - 0.99 * 0.99).sqrt();
    assert!(
        (hits[0].pose_a.position.x - want).abs() < 1e-6,
        "{:?} vs {want}",
        hits[0].pose_a
    );
    assert!(hits[0].depth.abs() < 1e-6);
    // 1e-6 clear of touching: no hit.
    assert!(graze(1.0 + 1e-6).is_empty());
}
