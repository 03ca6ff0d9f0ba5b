//! Fast bodies never pass through what they hit: swept tests (time of impact) for pairs in
//! `fast_layers`, checked at 10,000 units/s against a 0.5-unit asteroid and a thin wall.

use ricochet_sim::{Phase, Simulation, load_scenario};

/// A bullet (radius 0.05) at 10,000 units/s along +x, 60 Hz: 166.7 units a frame.
fn scene(fast: bool, targets: &str) -> Simulation {
    let fast = if fast {
        r#"fast_layers = ["bullet"]"#
    } else {
        ""
    };
    let text = format!(
        r#"
        hz = 60
        layers = ["bullet", "rock", "wall"]
        {fast}
        [[collide]]
        a = "bullet"
        b = "rock"
        response = "destroy"
        [[collide]]
        a = "bullet"
        b = "wall"
        response = "report"
        [[bodies]]
        name = "bullet"
        layer = "bullet"
        shape = {{ kind = "circle", radius = 0.05 }}
        position = [-30, 0.2]
        velocity = [10000, 0]
        {targets}
        "#
    );
    Simulation::new(&load_scenario(&text, "tunnel.toml").unwrap_or_else(|e| panic!("{e}")))
}

const ROCK: &str = r#"
    [[bodies]]
    name = "rock"
    layer = "rock"
    shape = { kind = "circle", radius = 0.5 }
    position = [40, 0]
"#;

fn alive(sim: &Simulation, name: &str) -> bool {
    sim.world.find(name).is_some()
}

#[test]
fn without_sweeping_the_bullet_tunnels_through_the_rock() {
    // The control: proves the scene really is a tunnelling case.
    let mut sim = scene(false, ROCK);
    for _ in 0..3 {
        sim.step();
    }
    assert!(
        alive(&sim, "rock"),
        "an unswept bullet skips over a 0.5-unit rock"
    );
    assert!(sim.world.position[0].x > 300.0);
}

#[test]
fn a_swept_bullet_at_10000_units_per_second_hits_a_half_unit_rock() {
    let mut sim = scene(true, ROCK);
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
    let rocks: String = [60.0, 20.0, 100.0]
        .iter()
        .enumerate()
        .map(|(k, x)| {
            format!(
                "[[bodies]]\nname = \"rock{k}\"\nlayer = \"rock\"\nshape = {{ kind = \"circle\", radius = 0.5 }}\nposition = [{x}, 0]\n"
            )
        })
        .collect();
    let mut sim = scene(true, &rocks);
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
    let wall = r#"
        [[bodies]]
        name = "wall"
        layer = "wall"
        kind = "static"
        shape = { kind = "obb", half_extents = [0.01, 5] }
        position = [50, 0]
        angle = 0.3
    "#;
    let mut unswept = scene(false, wall);
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
    let text = format!(
        r#"
        hz = 60
        layers = ["bullet", "rock"]
        fast_layers = ["bullet"]
        [[collide]]
        a = "bullet"
        b = "rock"
        response = "report"
        [[bodies]]
        layer = "bullet"
        shape = {{ kind = "circle", radius = 0.5 }}
        position = [-5, {miss:?}]
        velocity = [600, 0]
        [[bodies]]
        layer = "rock"
        shape = {{ kind = "circle", radius = 0.5 }}
        "#
    );
    let mut sim = Simulation::new(&load_scenario(&text, "graze.toml").unwrap());
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
