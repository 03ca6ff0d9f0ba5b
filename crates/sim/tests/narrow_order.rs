//! `detect` tests its pairs in order at the poses each pair meets: a pair whose body an
//! earlier pair of the same pass pushed sees it where it was pushed to (the parallel narrow
//! phase computes contacts ahead of the pass, `parallel.rs`, and must test such a pair
//! again). Expected positions by hand.

use ricochet_sim::{Simulation, load_scenario};

const CHAIN: &str = r#"
layers = ["ball"]
[world]
gravity = [0, 0]
[[collide]]
a = "ball"
b = "ball"
response = "separate"
[[bodies]]
name = "a"
layer = "ball"
kind = "static"
shape = { kind = "circle", radius = 1 }
position = [0, 0]
[[bodies]]
name = "b"
layer = "ball"
shape = { kind = "circle", radius = 1 }
position = [1.5, 0]
[[bodies]]
name = "c"
layer = "ball"
shape = { kind = "circle", radius = 1 }
position = [3, 0]
"#;

#[test]
fn a_pair_sees_the_push_of_an_earlier_pair_in_the_same_pass() {
    for threads in [1, 2] {
        let mut sim = Simulation::new(&load_scenario(CHAIN, "chain.toml").unwrap());
        sim.set_threads(threads);
        let out = sim.step();
        // (a, b): depth 0.5, b (the only dynamic body) moves out by all of it, to x = 2.
        // (b, c): then depth 2 - (3 - 2) = 1. Statics win (`push.rs`): b is flush on the
        // static a, so it stays at 2 and c takes the whole depth, to 4. Tested at the poses
        // the pass started from, it would be depth 0.5 (c to 3.5).
        let depths: Vec<f64> = out.contacts.iter().map(|c| c.depth).collect();
        assert_eq!(depths, [0.5, 1.0], "{threads} threads");
        let w = sim.world();
        let x = |name: &str| w.position[w.find(name).unwrap()].x;
        assert_eq!((x("b"), x("c")), (2.0, 4.0), "{threads} threads");
    }
}
