//! The per-axis passes name the static box a body was pushed out of, even when other static
//! bodies (not boxes, so not in their grid) come before it in id order.

use ricochet_sim::{Phase, Simulation, load_scenario};

const SCENE: &str = r#"
layers = ["solid"]
[world]
gravity = [0, -10]
[[collide]]
a = "solid"
b = "solid"
response = "separate"
[[bodies]]
name = "rock"
layer = "solid"
kind = "static"
shape = { kind = "circle", radius = 1 }
position = [50, 50]
[[bodies]]
name = "pebble"
layer = "solid"
kind = "static"
shape = { kind = "circle", radius = 0.5 }
position = [-50, 50]
[[bodies]]
name = "floor"
layer = "solid"
kind = "static"
shape = { kind = "aabb", half_extents = [5, 0.5] }
position = [0, 0]
[[bodies]]
name = "crate"
layer = "solid"
shape = { kind = "aabb", half_extents = [0.5, 0.5] }
position = [0, 1.5]
"#;

#[test]
fn a_box_landing_on_a_tile_names_the_tile() {
    let mut sim = Simulation::new(&load_scenario(SCENE, "scene.toml").unwrap());
    let floor = sim.world().entity[sim.world().find("floor").unwrap()];
    let crate_ = sim.world().entity[sim.world().find("crate").unwrap()];
    let mut landed = 0;
    for _ in 0..30 {
        for c in sim.step().contacts {
            assert_eq!(
                (c.a, c.b, c.phase),
                (floor, crate_, Phase::Y),
                "on the floor"
            );
            assert!(c.resolved.y > 0.0, "pushed up by the floor");
            landed += 1;
        }
    }
    assert!(landed > 0, "the crate lands");
}
