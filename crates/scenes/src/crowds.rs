//! The broad-phase study's scenes (`ricochet bench --broad-phases`, issue #24), named and
//! parsed with the others in [`bench`](crate::bench): one layer of bodies of all five shape
//! kinds that `report` against each other (nothing moves anything), drifting without gravity
//! in a wrap-around world, at three densities:
//!
//! - `crowded-N`: bodies about one unit across, one per square unit: every body overlaps a
//!   few neighbours, and a tenth of them overlap five or more.
//! - `sparse-N`: the same bodies a hundred times more spread out: pairs are rare, and a
//!   structure's cost is all upkeep.
//! - `mixed-N`: `N` small bodies (a unit across) with `max(4, N / 2000)` huge ones (a tenth of
//!   the world across), the case that breaks a uniform grid (a huge body covers thousands of
//!   cells, or the cells grow to its size) and sort and sweep (a huge body spans the sorted
//!   order along x).

use ricochet_geom::{Shape, Vec2};
use ricochet_sim::{BodyDef, LayerId, Response, Scenario};

use crate::bench::{any_shape, wrapping_world};
use crate::{Rng, layers, scenario};

/// The one layer.
const BODY: LayerId = 0;

/// `n` bodies of about `size` across, drifting at up to `speed` units a second, in a world
/// of side `side`, and `huge` bodies of a tenth of the world across.
fn drift(
    name: &str,
    n: usize,
    size: f64,
    side: f64,
    speed: f64,
    huge: usize,
    frames: u64,
) -> Scenario {
    let mut rng = Rng::new(0xb0a0_0024 ^ n as u64 ^ (huge as u64) << 40);
    let mut bodies = Vec::with_capacity(n + huge);
    for k in 0..huge {
        let r = side * 0.05;
        let shape = if k % 2 == 0 {
            Shape::circle(r).expect("a positive radius")
        } else {
            Shape::aabb(Vec2::splat(r)).expect("positive half extents")
        };
        bodies.push(BodyDef {
            name: "huge".to_owned(),
            layer: BODY,
            shape,
            position: Vec2::new(rng.range(0.0, side), rng.range(0.0, side)),
            velocity: rng.velocity(speed * 0.5),
            ..BodyDef::default()
        });
    }
    for k in 0..n {
        bodies.push(BodyDef {
            name: "body".to_owned(),
            layer: BODY,
            shape: any_shape(&mut rng, k, size * 0.5),
            position: Vec2::new(rng.range(0.0, side), rng.range(0.0, side)),
            angle: rng.range(0.0, std::f64::consts::TAU),
            velocity: {
                let v = rng.range(0.1, speed);
                rng.velocity(v)
            },
            angular_velocity: rng.range(-1.0, 1.0),
            ..BodyDef::default()
        });
    }
    let world = wrapping_world(
        Vec2::ZERO,
        Vec2::ZERO,
        Vec2::splat(side),
        layers(&["body"], &[(BODY, BODY, Response::Report)]),
    );
    scenario(name, world, bodies, frames)
}

/// `crowded-N`: see the module docs.
#[must_use]
pub fn crowded(n: usize, frames: u64) -> Scenario {
    let side = (n as f64).sqrt().max(4.0);
    drift(&format!("crowded-{n}"), n, 1.0, side, 2.0, 0, frames)
}

/// `sparse-N`: see the module docs.
#[must_use]
pub fn sparse(n: usize, frames: u64) -> Scenario {
    let side = (n as f64).sqrt() * 10.0;
    drift(&format!("sparse-{n}"), n, 1.0, side, 5.0, 0, frames)
}

/// `mixed-N`: see the module docs.
#[must_use]
pub fn mixed(n: usize, frames: u64) -> Scenario {
    let side = (n as f64).sqrt() * 4.0;
    drift(
        &format!("mixed-{n}"),
        n,
        1.0,
        side,
        3.0,
        (n / 2000).max(4),
        frames,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn study_scenes_have_the_asked_sizes() {
        assert_eq!(crowded(100, 1).bodies.len(), 100);
        assert_eq!(sparse(100, 1).bodies.len(), 100);
        assert_eq!(mixed(100, 1).bodies.len(), 104);
        assert_eq!(mixed(20_000, 1).bodies.len(), 20_010);
        assert_eq!(mixed(300, 1), mixed(300, 1));
    }
}
