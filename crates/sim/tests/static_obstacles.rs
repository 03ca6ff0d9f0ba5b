//! The per-axis passes name the static box a body was pushed out of, even when other static
//! bodies (not boxes, so not in their grid) come before it in id order.

use ricochet_sim::{GameEvent, Simulation, load_scenario};

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
    let mut landed = 0;
    for _ in 0..30 {
        for e in sim.step().events {
            if let GameEvent::PushedOut { obstacle, axis, .. } = e {
                assert_eq!((obstacle, axis), (floor, 1), "pushed up by the floor");
                landed += 1;
            }
        }
    }
    assert!(landed > 0, "the crate lands");
}
