//! The world: hand-written struct-of-arrays body columns, like Box2D's and rapier's body sets.
//!
//! Every column is indexed by the same dense index, and the columns are kept sorted by
//! [`Entity`], so iterating `0..len()` visits bodies in id order. Removing a body shifts the
//! rest down (`Vec::remove`): slower than a swap-remove, but the order, and so every log,
//! never depends on what was removed before.

use ricochet_geom::{Shape, Vec2};

use crate::def::{BodyDef, BodyKind, Controller, LayerId, Split};
use crate::entity::{Entity, EntityAllocator};

/// What a controller's inputs currently are.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Inputs {
    /// Ship engine on.
    pub thrust: bool,
    /// Ship turn input, -1 to 1.
    pub turn: f64,
    /// Runner horizontal input, -1 to 1.
    pub run: f64,
}

/// The body columns. Fields are public for reading; change bodies through the methods so the
/// columns stay in step.
#[derive(Clone, Debug, Default)]
pub struct World {
    ids: EntityAllocator,
    /// Entity of each body, ascending.
    pub entity: Vec<Entity>,
    /// Name.
    pub name: Vec<String>,
    /// Layer.
    pub layer: Vec<LayerId>,
    /// Collision shape, local coordinates.
    pub shape: Vec<Shape>,
    /// Dynamic, static or kinematic.
    pub kind: Vec<BodyKind>,
    /// Mass (dynamic bodies).
    pub mass: Vec<f64>,
    /// Position.
    pub position: Vec<Vec2>,
    /// Position at the start of the current frame (where a swept test starts).
    pub start_position: Vec<Vec2>,
    /// Angle, radians.
    pub angle: Vec<f64>,
    /// Velocity.
    pub velocity: Vec<Vec2>,
    /// Angular velocity.
    pub angular_velocity: Vec<f64>,
    /// Constant force.
    pub force: Vec<Vec2>,
    /// Gravity multiplier.
    pub gravity_scale: Vec<f64>,
    /// Frames left to live.
    pub lifetime: Vec<Option<u32>>,
    /// Input handling.
    pub controller: Vec<Option<Controller>>,
    /// Current inputs.
    pub inputs: Vec<Inputs>,
    /// Standing on something: pushed up by a `separate` response this frame.
    pub grounded: Vec<bool>,
    /// Children spawned on destruction.
    pub split: Vec<Vec<Split>>,
}

impl World {
    /// An empty world.
    #[must_use]
    pub fn new() -> World {
        World::default()
    }

    /// How many bodies.
    #[must_use]
    pub fn len(&self) -> usize {
        self.entity.len()
    }

    /// Whether there are no bodies.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.entity.is_empty()
    }

    /// The dense index of a live entity.
    #[must_use]
    pub fn index_of(&self, e: Entity) -> Option<usize> {
        self.entity.binary_search(&e).ok()
    }

    /// The dense index of the live body with this name and the lowest id.
    #[must_use]
    pub fn find(&self, name: &str) -> Option<usize> {
        self.name.iter().position(|n| n == name)
    }

    /// Creates a body; it takes the lowest free id, and its column position follows from it.
    pub fn spawn(&mut self, def: &BodyDef) -> Entity {
        let e = self.ids.allocate();
        let i = self.entity.partition_point(|x| *x < e);
        self.entity.insert(i, e);
        self.name.insert(i, def.name.clone());
        self.layer.insert(i, def.layer);
        self.shape.insert(i, def.shape.clone());
        self.kind.insert(i, def.kind);
        self.mass.insert(i, def.mass);
        self.position.insert(i, def.position);
        self.start_position.insert(i, def.position);
        self.angle.insert(i, def.angle);
        let moves = def.kind != BodyKind::Static;
        self.velocity
            .insert(i, if moves { def.velocity } else { Vec2::ZERO });
        self.angular_velocity
            .insert(i, if moves { def.angular_velocity } else { 0.0 });
        self.force.insert(i, def.force);
        self.gravity_scale.insert(i, def.gravity_scale);
        self.lifetime.insert(i, def.lifetime);
        self.controller.insert(i, def.controller.clone());
        self.inputs.insert(i, Inputs::default());
        self.grounded.insert(i, false);
        self.split.insert(i, def.split.clone());
        e
    }

    /// Removes the body at dense index `i`, keeping the order of the rest.
    pub fn despawn(&mut self, i: usize) {
        let e = self.entity.remove(i);
        self.ids.free(e);
        self.name.remove(i);
        self.layer.remove(i);
        self.shape.remove(i);
        self.kind.remove(i);
        self.mass.remove(i);
        self.position.remove(i);
        self.start_position.remove(i);
        self.angle.remove(i);
        self.velocity.remove(i);
        self.angular_velocity.remove(i);
        self.force.remove(i);
        self.gravity_scale.remove(i);
        self.lifetime.remove(i);
        self.controller.remove(i);
        self.inputs.remove(i);
        self.grounded.remove(i);
        self.split.remove(i);
    }

    /// The pose of body `i`.
    #[must_use]
    pub fn pose(&self, i: usize) -> ricochet_geom::Pose {
        ricochet_geom::Pose::new(self.position[i], self.angle[i])
    }

    /// A 64-bit FNV-1a hash of every body's raw state bits in id order (entity, position,
    /// angle, velocity, angular velocity), like Box2D's determinism test: any change of any
    /// bit anywhere changes it.
    #[must_use]
    pub fn digest(&self) -> u64 {
        const PRIME: u64 = 0x0000_0100_0000_01b3;
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        let mut eat = |bits: u64| {
            for byte in bits.to_le_bytes() {
                h ^= u64::from(byte);
                h = h.wrapping_mul(PRIME);
            }
        };
        for i in 0..self.len() {
            eat(u64::from(self.entity[i].index) << 32 | u64::from(self.entity[i].generation));
            for v in [
                self.position[i].x,
                self.position[i].y,
                self.angle[i],
                self.velocity[i].x,
                self.velocity[i].y,
                self.angular_velocity[i],
            ] {
                eat(v.to_bits());
            }
        }
        h
    }

    /// Kinetic energy of the dynamic bodies, `sum(m v² / 2)` (translation only).
    #[must_use]
    pub fn kinetic_energy(&self) -> f64 {
        (0..self.len())
            .filter(|&i| self.kind[i] == BodyKind::Dynamic)
            .map(|i| 0.5 * self.mass[i] * self.velocity[i].length_squared())
            .sum()
    }
}
