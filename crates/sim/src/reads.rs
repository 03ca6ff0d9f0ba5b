//! Reading a body by [`Entity`]: every per-body value the world keeps by dense index
//! ([`World::velocity`], [`World::carrier`], ...) has a reader here that takes the body's id
//! and answers `None` when the body is gone, never another body's value (Box2D's
//! `b2Body_GetPosition`, rapier's `RigidBodySet::get`). A game never needs a dense index:
//! indices shift as bodies are removed; ids do not.
//!
//! [`World`]: crate::World
//! [`World::velocity`]: crate::World::velocity
//! [`World::carrier`]: crate::World::carrier

use ricochet_geom::{Pose, Shape, Vec2};

use crate::def::{BodyKind, Controller, LayerId, Split};
use crate::entity::Entity;
use crate::pipeline::Simulation;
use crate::world::Inputs;

/// Readers by entity of the world's per-body values: `name(e) -> Option<ty>` reads
/// `expr` for the body's dense index `i` in world `w`.
macro_rules! by_entity {
    ($($(#[$doc:meta])* $name:ident -> $ty:ty = |$w:ident, $i:ident| $expr:expr;)*) => {
        impl Simulation {
            $(
                $(#[$doc])*
                #[must_use]
                pub fn $name(&self, e: Entity) -> Option<$ty> {
                    let $w = &self.world;
                    $w.index_of(e).map(|$i| $expr)
                }
            )*
        }
    };
}

by_entity! {
    /// A body's position.
    position -> Vec2 = |w, i| w.position[i];
    /// A body's angle in radians (counter-clockwise).
    angle -> f64 = |w, i| w.angle[i];
    /// A body's pose (position and angle).
    pose -> Pose = |w, i| w.pose(i);
    /// A body's velocity.
    velocity -> Vec2 = |w, i| w.velocity(i);
    /// A body's angular velocity in radians/s.
    angular_velocity -> f64 = |w, i| w.angular_velocity(i);
    /// Whether a body was held up by something it stands on in the last step.
    grounded -> bool = |w, i| w.grounded(i);
    /// A body's layer.
    layer -> LayerId = |w, i| w.layer[i];
    /// Whether a body is dynamic, static or kinematic.
    kind -> BodyKind = |w, i| w.kind[i];
    /// A body's shape.
    shape -> &Shape = |w, i| w.shape(i);
    /// A body's name (shared with every body of that name).
    name -> &str = |w, i| w.name(i);
    /// A dynamic body's mass.
    mass -> f64 = |w, i| w.mass(i);
    /// The constant force on a body.
    force -> Vec2 = |w, i| w.force(i);
    /// A body's multiplier of the world gravity.
    gravity_scale -> f64 = |w, i| w.gravity_scale(i);
    /// The frames a body has left to live (`Some(None)`: it lives until removed).
    lifetime -> Option<u32> = |w, i| w.lifetime(i);
    /// A body's controller (ship, runner, walker), if it has one.
    controller -> Option<&Controller> = |w, i| w.controller(i);
    /// A controlled body's current inputs (thrust, turn, run).
    inputs -> Inputs = |w, i| w.inputs(i);
    /// What a box rides (`Some(None)`: nothing, or a static body): the kinematic or
    /// dynamic box that held it up in the last step; it is carried by that body's motion.
    carrier -> Option<Entity> = |w, i| w.carrier(i);
    /// Whether a body stands on a static body (held up by one in the last step).
    on_static -> bool = |w, i| w.on_static(i);
    /// Whether a body is frozen outside the active region (not moved, not tested).
    frozen -> bool = |w, i| w.frozen(i);
    /// Whether a body is asleep (at rest on static geometry, not integrated).
    asleep -> bool = |w, i| w.asleep(i);
    /// The children a body splits into when destroyed.
    split -> &[Split] = |w, i| w.split(i);
    /// The game's own data for a body ([`crate::BodyDef::user_data`]; 0 unless set).
    user_data -> u128 = |w, i| w.user_data(i);
}
