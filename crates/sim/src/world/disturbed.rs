//! Which bodies something other than the usual integration touched: what a recorder of
//! `/bodies` must look at, so it need not compare every body every frame (issue #37).
//!
//! The integrator's usual pass ([`World::integrate`] with all three parts run) moves every
//! active body exactly as a reader of `/bodies` predicts: `position + velocity * dt`,
//! `angle + angular_velocity * dt`, the velocities unchanged. Every other write of a body's
//! position, angle, velocity or spin, of whether it is active (asleep, frozen), and every
//! spawn and removal, names the body here ([`World::disturb`]). Every body is named at
//! once ([`World::disturb_all`]) by a restore or a copy, by a frame without the usual pass
//! (frame 0, a scene with per-axis pairs, a motion stage skipped) or with gravity (nearly
//! every velocity changes: named before the stages run, so their names cost a branch), and
//! past a quarter of the bodies' names.
//!
//! The list holds what was named since the end of the step before the last one: a reader
//! that looks after every step (and only then) sees every body named since it last looked,
//! and some twice. [`Disturbed::steps`] and [`Disturbed::serial`] tell it whether it did
//! look after the step before: a copy of the world, or a restored one, is another world.

use crate::entity::Entity;
use crate::interned::next_serial;

use super::World;

/// Names every body: what a list entry holding it means.
const ALL: Entity = Entity {
    index: u32::MAX,
    generation: u32::MAX,
};

/// The bodies named since the step before last ended (see the module).
#[derive(Debug)]
pub struct Disturbed {
    serial: u64,
    steps: u64,
    bodies: Vec<Entity>,
    /// Where the last step's end is in `bodies`: the names before it are dropped when the
    /// next step begins.
    last_end: usize,
    /// `bodies` holds [`ALL`]: a name adds nothing.
    full: bool,
    /// How many names so far, those that added nothing included: it tells "touched since"
    /// even once every body is named ([`Disturbed::mark`]).
    touches: u64,
}

impl Default for Disturbed {
    fn default() -> Disturbed {
        Disturbed {
            serial: next_serial(),
            steps: 0,
            bodies: Vec::new(),
            last_end: 0,
            full: false,
            touches: 0,
        }
    }
}

impl Clone for Disturbed {
    /// A copy is another world: its own serial, every body named.
    fn clone(&self) -> Disturbed {
        let mut copy = Disturbed::default();
        copy.name_all();
        copy
    }
}

impl Disturbed {
    /// This world's number: never another world's, nor a copy's.
    #[must_use]
    pub fn serial(&self) -> u64 {
        self.serial
    }

    /// How many steps have ended.
    #[must_use]
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// Whether every body may have been touched (the list then says nothing).
    #[must_use]
    pub fn all(&self) -> bool {
        self.full
    }

    /// A mark that changes with every name, every step and every copy, every body named or
    /// not: while it is the same, no body was touched but by the integrator, which runs
    /// once a step.
    pub(super) fn mark(&self) -> (u64, u64, u64) {
        (self.serial, self.steps, self.touches)
    }

    /// The bodies named since the step before last ended, repeats and gone bodies included
    /// (meaningful only when not [`Disturbed::all`]).
    #[must_use]
    pub fn bodies(&self) -> &[Entity] {
        &self.bodies
    }

    /// Names `e`, in a world of `len` bodies: more names than a quarter of them (and 64)
    /// become "all" (a reader would compare every body anyway).
    #[inline]
    pub(super) fn name(&mut self, e: Entity, len: usize) {
        self.touches += 1;
        if self.full {
            return;
        }
        if self.bodies.len() < len / 4 + 64 {
            self.bodies.push(e);
        } else {
            self.name_all();
        }
    }

    /// Names every body.
    fn name_all(&mut self) {
        self.touches += 1;
        if !self.full {
            self.bodies.push(ALL);
            self.full = true;
        }
    }

    /// A step begins: the names from before the last step's end are dropped.
    fn begin_step(&mut self) {
        self.bodies.drain(..self.last_end);
        self.last_end = 0;
        self.full = self.bodies.contains(&ALL);
    }

    /// A step ended.
    fn end_step(&mut self) {
        self.last_end = self.bodies.len();
        self.steps += 1;
    }
}

impl World {
    /// What was touched besides the usual integration (see [`Disturbed`]).
    #[must_use]
    pub fn disturbed(&self) -> &Disturbed {
        &self.disturbed
    }

    /// Names body `i` as touched by something other than the usual integration.
    #[inline]
    pub(crate) fn disturb(&mut self, i: usize) {
        if self.disturbed.full {
            self.disturbed.touches += 1;
        } else {
            let e = self.entity[i];
            self.disturbed.name(e, self.entity.len());
        }
    }

    /// Names every body: what was touched cannot be said body by body.
    pub(crate) fn disturb_all(&mut self) {
        self.disturbed.name_all();
    }

    /// A step begins ([`Disturbed::begin_step`]).
    pub(crate) fn begin_step(&mut self) {
        self.disturbed.begin_step();
    }

    /// A step ended ([`Disturbed::end_step`]).
    pub(crate) fn end_step(&mut self) {
        self.disturbed.end_step();
    }
}
