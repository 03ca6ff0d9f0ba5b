//! The rows: the columns of the bodies that are not scenery (see the module docs of
//! `world`), their readers and writers by dense index, and how a row is added, removed and
//! counted.

use ricochet_geom::Vec2;

use super::local_bounds::{LocalBounds, LocalBoundsColumn};
use super::{Inputs, NO_ROW, World};
use crate::def::{BodyDef, BodyKind, Controller, Split};
use crate::entity::Entity;

/// The columns of the bodies that have a row, indexed by row.
#[derive(Clone, Debug, Default)]
pub(super) struct Rows {
    /// The body of each row.
    pub(super) entity: Vec<Entity>,
    pub(super) mass: Vec<f64>,
    pub(super) start_position: Vec<Vec2>,
    pub(super) velocity: Vec<Vec2>,
    pub(super) angular_velocity: Vec<f64>,
    pub(super) force: Vec<Vec2>,
    pub(super) gravity_scale: Vec<f64>,
    pub(super) lifetime: Vec<Option<u32>>,
    pub(super) controller: Vec<Option<Controller>>,
    pub(super) inputs: Vec<Inputs>,
    pub(super) grounded: Vec<bool>,
    pub(super) on_static: Vec<bool>,
    pub(super) carrier: Vec<Option<Entity>>,
    pub(super) still: Vec<bool>,
    pub(super) split: Vec<Vec<Split>>,
    pub(super) frozen: Vec<bool>,
    pub(super) asleep: Vec<bool>,
    pub(super) rest_frames: Vec<u32>,
    pub(super) local_bounds: LocalBoundsColumn,
    pub(super) user_data: Vec<u128>,
    /// No row below this one has a lifetime (0 claims nothing): an asteroid field spawned
    /// before its bullets counts down only the bullets' rows.
    pub(super) no_lifetime_below: usize,
    /// How many rows have a gravity scale other than 1 (by its bits): with none, and no
    /// force, the `forces` stage reads neither column (`World::accelerate`).
    pub(super) scaled: usize,
}

/// The row columns every body reads (a copy), with what scenery reads: each gets a reader
/// `name(i)` by dense index.
macro_rules! row_readers {
    ($($(#[$doc:meta])* $get:ident: $ty:ty = $scenery:expr;)*) => {
        impl World {
            $(
                $(#[$doc])*
                #[must_use]
                #[inline]
                pub fn $get(&self, i: usize) -> $ty {
                    match self.row[i] {
                        NO_ROW => $scenery,
                        r => self.rows.$get[r as usize],
                    }
                }
            )*
        }
    };
}

/// The row columns the stages write: each gets, inside the crate, a writer `name_mut(i)`
/// by dense index (scenery written to, a script's force or input sent to a tile, gets a row
/// first).
macro_rules! row_writers {
    ($($get:ident, $get_mut:ident: $ty:ty;)*) => {
        impl World {
            $(
                #[doc = concat!("[`World::", stringify!($get), "`] of body `i`, to change.")]
                #[inline]
                pub(crate) fn $get_mut(&mut self, i: usize) -> &mut $ty {
                    let r = self.row_of(i);
                    &mut self.rows.$get[r]
                }
            )*
        }
    };
}

row_readers! {
    /// Mass (dynamic bodies).
    mass: f64 = 1.0;
    /// Velocity.
    velocity: Vec2 = Vec2::ZERO;
    /// Angular velocity.
    angular_velocity: f64 = 0.0;
    /// Constant force.
    force: Vec2 = Vec2::ZERO;
    /// Gravity multiplier.
    gravity_scale: f64 = 1.0;
    /// Frames left to live.
    lifetime: Option<u32> = None;
    /// Current inputs.
    inputs: Inputs = Inputs::default();
    /// Standing on something: pushed up by a `separate` response this frame.
    grounded: bool = false;
    /// Standing on a static body: pushed up by one this frame (what sleeping needs).
    on_static: bool = false;
    /// What a box stands on and rides (`stages/carry.rs`): the kinematic or dynamic box that
    /// last pushed it up in the last `resolve_y` (or that it still rests on, flush), `None`
    /// on a static body or in the air. `move_x` and `move_y` move it by that carrier's
    /// displacement before its own motion.
    carrier: Option<Entity> = None;
    /// Ended the last frame where it started it, with zero velocity (a box resting on a
    /// sleeper does not wake it).
    still: bool = false;
    /// Frozen outside the active region: not moved, not tested, lifetime paused.
    frozen: bool = false;
    /// Asleep: at rest on static geometry, not integrated until something touches it.
    asleep: bool = false;
    /// Consecutive frames a dynamic body has ended exactly where it started, grounded.
    rest_frames: u32 = 0;
    /// The game's own data ([`crate::BodyDef::user_data`]).
    user_data: u128 = 0;
}

row_writers! {
    inputs, inputs_mut: Inputs;
    grounded, grounded_mut: bool;
    on_static, on_static_mut: bool;
    carrier, carrier_mut: Option<Entity>;
    still, still_mut: bool;
    rest_frames, rest_frames_mut: u32;
    user_data, user_data_mut: u128;
}

impl World {
    /// Sets whether body `i` is frozen; a change is counted ([`World::count_movers`] keeps
    /// its count until one).
    #[inline]
    pub(crate) fn set_frozen(&mut self, i: usize, frozen: bool) {
        let r = self.row_of(i);
        if self.rows.frozen[r] != frozen {
            self.rows.frozen[r] = frozen;
            self.frozen_changes += 1;
        }
    }

    /// [`World::velocity`] of body `i`, to change: the body is named as disturbed
    /// ([`World::disturbed`]), and the kept kinetic energy dropped.
    #[inline]
    pub(crate) fn velocity_mut(&mut self, i: usize) -> &mut Vec2 {
        self.disturb(i);
        self.kept_energy = None;
        let r = self.row_of(i);
        &mut self.rows.velocity[r]
    }

    /// [`World::angular_velocity`] of body `i`, to change: the body is named as disturbed.
    #[inline]
    pub(crate) fn angular_velocity_mut(&mut self, i: usize) -> &mut f64 {
        self.disturb(i);
        let r = self.row_of(i);
        &mut self.rows.angular_velocity[r]
    }

    /// Body `i`'s position, to change: the body is named as disturbed.
    #[inline]
    pub(crate) fn position_mut(&mut self, i: usize) -> &mut Vec2 {
        self.disturb(i);
        &mut self.position[i]
    }

    /// Body `i`'s angle, to change: the body is named as disturbed.
    #[inline]
    pub(crate) fn angle_mut(&mut self, i: usize) -> &mut f64 {
        self.disturb(i);
        &mut self.angle[i]
    }
}

/// One body's motion, as [`World::motions`] reads it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion {
    /// The body.
    pub entity: Entity,
    /// Position.
    pub position: Vec2,
    /// Angle, radians.
    pub angle: f64,
    /// Velocity ([`Vec2::ZERO`] for scenery).
    pub velocity: Vec2,
    /// Angular velocity (0 for scenery).
    pub angular_velocity: f64,
}

impl World {
    /// Every body's motion, by dense index: what [`World::velocity`] and the columns give
    /// one by one, read in one pass over borrowed columns (a recorder comparing 10,000
    /// bodies a frame spent a third of its time in the per-body bounds checks).
    pub fn motions(&self) -> impl ExactSizeIterator<Item = Motion> + '_ {
        let n = self.entity.len();
        let m = self.rows.velocity.len();
        let (velocity, spin) = (&self.rows.velocity[..m], &self.rows.angular_velocity[..m]);
        self.entity[..n]
            .iter()
            .zip(&self.position[..n])
            .zip(&self.angle[..n])
            .zip(&self.row[..n])
            .map(move |(((&entity, &position), &angle), &r)| {
                let (velocity, angular_velocity) = match r {
                    NO_ROW => (Vec2::ZERO, 0.0),
                    r => (velocity[r as usize], spin[r as usize]),
                };
                Motion {
                    entity,
                    position,
                    angle,
                    velocity,
                    angular_velocity,
                }
            })
    }
}

/// Whether a gravity scale counts in [`Rows::scaled`]: any but 1, by its bits.
pub(super) fn is_scaled(scale: f64) -> bool {
    scale.to_bits() != 1f64.to_bits()
}

impl Rows {
    /// Appends a row for `def`'s body `e`.
    pub(super) fn push(&mut self, e: Entity, def: &BodyDef) {
        let moves = def.kind != BodyKind::Static;
        self.entity.push(e);
        self.mass.push(def.mass);
        self.start_position.push(def.position);
        self.velocity
            .push(if moves { def.velocity } else { Vec2::ZERO });
        self.angular_velocity
            .push(if moves { def.angular_velocity } else { 0.0 });
        self.force.push(def.force);
        self.gravity_scale.push(def.gravity_scale);
        self.scaled += usize::from(is_scaled(def.gravity_scale));
        if def.lifetime.is_none() && self.no_lifetime_below == self.lifetime.len() {
            self.no_lifetime_below += 1;
        }
        self.lifetime.push(def.lifetime);
        self.controller.push(def.controller.clone());
        self.inputs.push(Inputs::default());
        self.grounded.push(false);
        self.on_static.push(false);
        self.carrier.push(None);
        self.still.push(false);
        self.split.push(def.split.clone());
        self.frozen.push(false);
        self.asleep.push(false);
        self.rest_frames.push(0);
        self.local_bounds
            .push(LocalBounds::new(&def.shape, def.angle));
        self.user_data.push(def.user_data);
    }

    /// Removes row `r`, moving the last row into its place.
    pub(super) fn swap_remove(&mut self, r: usize) {
        self.entity.swap_remove(r);
        self.mass.swap_remove(r);
        self.start_position.swap_remove(r);
        self.velocity.swap_remove(r);
        self.angular_velocity.swap_remove(r);
        self.force.swap_remove(r);
        self.scaled -= usize::from(is_scaled(self.gravity_scale.swap_remove(r)));
        self.lifetime.swap_remove(r);
        // The last row moved into `r` (if `r` was not the last).
        let below = self.no_lifetime_below.min(self.lifetime.len());
        self.no_lifetime_below = match self.lifetime.get(r) {
            Some(Some(_)) => below.min(r),
            _ => below,
        };
        self.controller.swap_remove(r);
        self.inputs.swap_remove(r);
        self.grounded.swap_remove(r);
        self.on_static.swap_remove(r);
        self.carrier.swap_remove(r);
        self.still.swap_remove(r);
        self.split.swap_remove(r);
        self.frozen.swap_remove(r);
        self.asleep.swap_remove(r);
        self.rest_frames.swap_remove(r);
        self.local_bounds.swap_remove(r);
        self.user_data.swap_remove(r);
    }

    /// Heap bytes of the columns (capacities).
    pub(super) fn heap_bytes(&self) -> usize {
        fn cap<T>(v: &Vec<T>) -> usize {
            v.capacity() * size_of::<T>()
        }
        let children: usize = self.split.iter().map(cap).sum();
        cap(&self.entity)
            + cap(&self.mass)
            + cap(&self.start_position)
            + cap(&self.velocity)
            + cap(&self.angular_velocity)
            + cap(&self.force)
            + cap(&self.gravity_scale)
            + cap(&self.lifetime)
            + cap(&self.controller)
            + cap(&self.inputs)
            + cap(&self.grounded)
            + cap(&self.on_static)
            + cap(&self.carrier)
            + cap(&self.still)
            + cap(&self.split)
            + children
            + cap(&self.frozen)
            + cap(&self.asleep)
            + cap(&self.rest_frames)
            + self.local_bounds.heap_bytes()
            + cap(&self.user_data)
    }
}

impl World {
    /// Body `i`'s row, made for scenery first (with what scenery reads: nothing changes
    /// but where the body's state is kept).
    #[inline]
    pub(super) fn row_of(&mut self, i: usize) -> usize {
        match self.row[i] {
            NO_ROW => self.give_row(i),
            r => r as usize,
        }
    }

    #[cold]
    fn give_row(&mut self, i: usize) -> usize {
        let def = BodyDef {
            layer: self.layer[i],
            shape: self.shape(i).clone(),
            kind: self.kind[i],
            position: self.position[i],
            angle: self.angle[i],
            ..BodyDef::default()
        };
        let r = self.rows.entity.len();
        self.rows.push(self.entity[i], &def);
        self.row[i] = r as u32;
        r
    }
}
