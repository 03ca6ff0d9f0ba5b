//! rapier's serde snapshot of a bench scene, for `ricochet bench --snapshots`: what a rapier
//! game saves for a rollback (rapier#991 measured 988.7 KB and 0.404 ms at 800 bodies).
//!
//! The scene is the one a rapier game would build: a [`PhysicsWorld`] (rapier's bundle of
//! every set a step reads: bodies, colliders, broad phase, narrow phase, islands, joints,
//! integration parameters) with a dynamic rigid body per moving body (its velocity and
//! angular velocity, no gravity) and a fixed one per static body, each with the body's
//! collider, stepped once so that the broad and narrow phases hold the contacts. The
//! snapshot is `bincode::serialize(&world)`, rapier's `serde-serialize` feature, as its
//! testbed's snapshots are; restoring it is `bincode::deserialize`.

use std::time::Instant;

use rapier2d_f64::prelude::{ColliderBuilder, PhysicsWorld, RigidBodyBuilder};
use ricochet_geom::Pose;
use ricochet_sim::{BodyKind, Simulation};

use super::scene::collider_pose;
use crate::OracleError;
use crate::convert::{place, to_vector};

/// rapier's snapshot of a scene: its size and median times, in microseconds.
#[derive(Clone, Copy, Debug)]
pub struct RapierSnapshot {
    /// `bincode::serialize(&PhysicsWorld)`'s length.
    pub bytes: usize,
    /// Serialising.
    pub serialize_us: f64,
    /// Deserialising (the restore: a new world).
    pub deserialize_us: f64,
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn micros<T>(f: impl FnOnce() -> T) -> (f64, T) {
    let t = Instant::now();
    let x = std::hint::black_box(f());
    (t.elapsed().as_secs_f64() * 1e6, x)
}

/// The rapier world of `sim`'s bodies at their current poses and velocities (module docs).
///
/// # Errors
/// A shape rapier's bench scene cannot take (a compound).
pub fn rapier_world(sim: &Simulation) -> Result<PhysicsWorld, OracleError> {
    let w = sim.world();
    let mut world = PhysicsWorld {
        gravity: to_vector(ricochet_geom::Vec2::ZERO),
        ..PhysicsWorld::default()
    };
    for i in 0..w.len() {
        let pose = collider_pose(w.shape(i), &w.pose(i))?;
        let (_, shape) = place(w.shape(i), &Pose::default(), ricochet_geom::Vec2::ZERO)?;
        let body = if w.kind[i] == BodyKind::Static {
            RigidBodyBuilder::fixed().pose(pose)
        } else {
            RigidBodyBuilder::dynamic()
                .pose(pose)
                .linvel(to_vector(w.velocity(i)))
                .angvel(w.angular_velocity(i))
        };
        world.insert(body, ColliderBuilder::new(shape));
    }
    world.step();
    Ok(world)
}

/// Serialises and deserialises `sim`'s rapier world `passes` times (`PhysicsWorld` is not
/// `Clone`: a rollback with rapier goes through bytes).
///
/// # Errors
/// A shape rapier's bench scene cannot take, or bytes bincode does not read back.
pub fn rapier_snapshot(sim: &Simulation, passes: usize) -> Result<RapierSnapshot, OracleError> {
    let world = rapier_world(sim)?;
    let (mut s, mut d) = (Vec::new(), Vec::new());
    let mut bytes = 0;
    for _ in 0..passes.max(1) {
        let (t, b) = micros(|| bincode::serialize(&world));
        let b = b.map_err(|_| OracleError::Conversion("bincode could not serialise the world"))?;
        bytes = b.len();
        s.push(t);
        let (t, back) = micros(|| bincode::deserialize::<PhysicsWorld>(&b));
        back.map_err(|_| OracleError::Conversion("bincode could not read the world back"))?;
        d.push(t);
    }
    Ok(RapierSnapshot {
        bytes,
        serialize_us: median(s),
        deserialize_us: median(d),
    })
}
