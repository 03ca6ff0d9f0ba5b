//! The world's part of a snapshot: the bodies as they differ from the *baseline* (the world
//! as the simulation was built, before its first step), and the id generations likewise.
//!
//! The bodies are visited in id order beside the baseline's, and each becomes one record:
//! - `KEEP n`: the next `n` bodies of the baseline, alive and unchanged (scenery: 2 bytes
//!   for a whole level);
//! - `DROP n`: the next `n` bodies of the baseline are gone;
//! - `CHANGED` with a mask of the [`group`]s that differ from the baseline's body, each
//!   written whole (a drifting asteroid: position and angle, 25 bytes; its turned bit is a
//!   bit of the mask);
//! - `WHOLE`: a body the baseline does not have (spawned later), or one whose definition
//!   (layer, kind, shape, name, mass, gravity scale, children, having a row) is no longer
//!   the baseline's: every field, as version 1 wrote every body.
//!
//! Written through one [`Sink`], so the snapshot's bytes and [`crate::Simulation::checksum`]
//! cover the same fields; `game_data` false leaves out what no stage reads (`user_data`),
//! from the mask too. The encoding of a state is a function of the state and the baseline
//! alone, never of the history (interned ids, row order): equal states, equal bytes.
//! `Rows` is destructured whole in [`World::write_whole`]: a new column does not compile
//! until it is placed here (or named a cache).

use ricochet_geom::{Shape, Vec2};

use super::local_bounds::LocalBounds;
use super::rows::Rows;
use super::{Inputs, NO_ROW, World};
use crate::def::{BodyDef, BodyKind, Controller, LayerId, Split};
use crate::entity::{Entity, EntityAllocator};
use crate::snapshot::SnapshotError;
use crate::snapshot::codec::Sink;

mod decode;
mod packed;
mod restore;
mod runs_code;

pub(crate) use packed::PackedWorld;

/// The field groups a `CHANGED` record writes when they differ from the baseline's, each a
/// bit of its mask (the tag's low 7 bits), in this order.
pub(crate) mod group {
    /// `position`.
    pub(crate) const POSITION: u8 = 1;
    /// `angle`.
    pub(crate) const ANGLE: u8 = 2;
    /// `velocity`.
    pub(crate) const VELOCITY: u8 = 4;
    /// `angular_velocity`.
    pub(crate) const SPIN: u8 = 8;
    /// `lifetime`.
    pub(crate) const LIFETIME: u8 = 16;
    /// [`super::Motion`]: force, controller, inputs, contact flags, carrier, sleep, and
    /// `user_data` (left out of the checksum's mask and bytes).
    pub(crate) const MOTION: u8 = 32;
    /// The turned bit (the broad phase's bounds: exact, or the any-angle square once the
    /// body turned) is not the baseline's: no bytes, the bit says it all.
    pub(crate) const TURNED: u8 = 64;
    /// The groups only a body with a row has.
    pub(crate) const ROW: u8 = VELOCITY | SPIN | LIFETIME | MOTION | TURNED;
}

const KEEP: u8 = 0;
const DROP: u8 = 1;
const WHOLE: u8 = 2;
const END: u8 = 3;
const CHANGED: u8 = 0x80;

/// The row state the stages change besides motion and lifetime: one group of the mask.
#[derive(Clone, Debug, Default)]
pub(crate) struct Motion {
    force: Vec2,
    controller: Option<Controller>,
    inputs: Inputs,
    grounded: bool,
    on_static: bool,
    carrier: Option<Entity>,
    still: bool,
    frozen: bool,
    asleep: bool,
    rest_frames: u32,
    /// The game's data: in the snapshot, never in the checksum.
    user_data: u128,
}

/// A body written whole (a `WHOLE` record, or a baseline body a restore rebuilds).
#[derive(Clone, Debug)]
pub(crate) struct Whole {
    entity: Entity,
    layer: LayerId,
    kind: BodyKind,
    position: Vec2,
    angle: f64,
    shape: Shape,
    name: String,
    row: Option<WholeRow>,
}

/// The row of a [`Whole`] body.
#[derive(Clone, Debug)]
struct WholeRow {
    mass: f64,
    velocity: Vec2,
    spin: f64,
    gravity_scale: f64,
    lifetime: Option<u32>,
    split: Vec<Split>,
    motion: Motion,
    /// The broad phase's bounds: exact, or the any-angle square once the body turned.
    turned: bool,
}

/// The groups of a `CHANGED` record (the others are the baseline's).
#[derive(Clone, Copy, Debug, Default)]
struct Delta {
    position: Vec2,
    angle: f64,
    velocity: Vec2,
    spin: f64,
    lifetime: Option<u32>,
    /// Index in [`Bodies::motions`] (with [`group::MOTION`]).
    motion: u32,
}

/// One body of a decoded snapshot, in id order.
#[derive(Clone, Copy, Debug)]
struct Entry {
    /// Its index in the baseline, or `u32::MAX` for a whole body.
    base: u32,
    /// The changed groups (0: the baseline's body as it was).
    mask: u8,
    /// Index in [`Bodies::deltas`] (with a mask), or in [`Bodies::wholes`].
    at: u32,
}

/// The bodies of a snapshot, decoded and checked against the baseline, not yet in a world.
#[derive(Debug, Default)]
pub(crate) struct Bodies {
    entries: Vec<Entry>,
    entities: Vec<Entity>,
    deltas: Vec<Delta>,
    motions: Vec<Motion>,
    wholes: Vec<Whole>,
    generations: Vec<u32>,
    /// A whole body has a baseline body's entity: its definition changed.
    redefined: bool,
}

impl Bodies {
    /// The motion group of a `CHANGED` record that has one.
    fn motion(&self, d: &Delta) -> &Motion {
        &self.motions[d.motion as usize]
    }
}

impl World {
    /// Whether body `i`'s broad-phase bounds are the any-angle square (`Motion::turned`).
    fn turned(&self, i: usize) -> bool {
        match self.row[i] {
            NO_ROW => false,
            r => self
                .rows
                .local_bounds
                .get(r as usize)
                .has_turned(self.angle[i]),
        }
    }

    /// Body `i`'s [`Motion`] (scenery: the defaults).
    fn motion(&self, i: usize) -> Motion {
        Motion {
            force: self.force(i),
            controller: self.controller(i).cloned(),
            inputs: self.inputs(i),
            grounded: self.grounded(i),
            on_static: self.on_static(i),
            carrier: self.carrier(i),
            still: self.still(i),
            frozen: self.frozen(i),
            asleep: self.asleep(i),
            rest_frames: self.rest_frames(i),
            user_data: self.user_data(i),
        }
    }

    /// Whether body `i` has the definition of `base`'s body `j` (the same entity): what a
    /// `CHANGED` record takes from the baseline. A shape changes only by `set_shape`, which
    /// sets `reshaped` (as a restore that redefined a body does): compared only then.
    fn same_definition(&self, i: usize, base: &World, j: usize) -> bool {
        let (r, q) = (self.row[i], base.row[j]);
        self.layer[i] == base.layer[j]
            && self.kind[i] == base.kind[j]
            && (r == NO_ROW) == (q == NO_ROW)
            && self.mass(i).to_bits() == base.mass(j).to_bits()
            && self.gravity_scale(i).to_bits() == base.gravity_scale(j).to_bits()
            && same_splits(self.split(i), base.split(j))
            && self.name(i) == base.name(j)
            && (!self.reshaped || same_bits(self.shape(i), base.shape(j), |s, x| s.shape(x)))
    }

    /// The groups in which body `i` differs from `base`'s body `j`, bit for bit.
    fn changes(&self, i: usize, base: &World, j: usize, game_data: bool) -> u8 {
        let mut m = 0;
        if !same_vec(self.position[i], base.position[j]) {
            m |= group::POSITION;
        }
        if self.angle[i].to_bits() != base.angle[j].to_bits() {
            m |= group::ANGLE;
        }
        if self.row[i] == NO_ROW {
            return m;
        }
        if !same_vec(self.velocity(i), base.velocity(j)) {
            m |= group::VELOCITY;
        }
        if self.angular_velocity(i).to_bits() != base.angular_velocity(j).to_bits() {
            m |= group::SPIN;
        }
        if self.lifetime(i) != base.lifetime(j) {
            m |= group::LIFETIME;
        }
        if !self.same_motion(i, base, j) || (game_data && self.user_data(i) != base.user_data(j)) {
            m |= group::MOTION;
        }
        if self.turned(i) != base.turned(j) {
            m |= group::TURNED;
        }
        m
    }

    fn same_motion(&self, i: usize, base: &World, j: usize) -> bool {
        let (a, b) = (self.inputs(i), base.inputs(j));
        same_vec(self.force(i), base.force(j))
            && a.thrust == b.thrust
            && a.drop == b.drop
            && a.turn.to_bits() == b.turn.to_bits()
            && a.run.to_bits() == b.run.to_bits()
            && self.grounded(i) == base.grounded(j)
            && self.on_static(i) == base.on_static(j)
            && self.carrier(i) == base.carrier(j)
            && self.still(i) == base.still(j)
            && self.frozen(i) == base.frozen(j)
            && self.asleep(i) == base.asleep(j)
            && self.rest_frames(i) == base.rest_frames(j)
            && match (self.controller(i), base.controller(j)) {
                (None, None) => true,
                (a, b) => same_bits(&a, &b, |s, x| s.controller(*x)),
            }
    }

    /// Writes every body as it differs from `base` (module docs), then each slot's
    /// generation as it differs from `base`'s.
    pub(crate) fn encode(&self, base: &World, s: &mut impl Sink, game_data: bool) {
        let (mut i, mut j) = (0, 0);
        // The pending run: (KEEP or DROP, length).
        let mut run = (KEEP, 0u64);
        loop {
            let (a, b) = (self.entity.get(i), base.entity.get(j));
            let step = match (a, b) {
                (None, None) => break,
                (Some(a), Some(b)) if a == b => {
                    if self.same_definition(i, base, j) {
                        match self.changes(i, base, j, game_data) {
                            0 => Step::Run(KEEP),
                            m => Step::Changed(m),
                        }
                    } else {
                        Step::Whole
                    }
                }
                (Some(a), b) if b.is_none_or(|b| a.index < b.index) => Step::New,
                _ => Step::Run(DROP),
            };
            if let Step::Run(tag) = step {
                if run.0 != tag && run.1 > 0 {
                    write_run(s, run);
                    run.1 = 0;
                }
                run = (tag, run.1 + 1);
                j += 1;
                i += usize::from(tag == KEEP);
                continue;
            }
            if run.1 > 0 {
                write_run(s, run);
                run.1 = 0;
            }
            match step {
                Step::Changed(m) => {
                    s.u8(CHANGED | m);
                    self.write_groups(i, m, s, game_data);
                    (i, j) = (i + 1, j + 1);
                }
                Step::Whole => {
                    s.u8(WHOLE);
                    self.write_whole(i, s, game_data);
                    (i, j) = (i + 1, j + 1);
                }
                Step::New => {
                    s.u8(WHOLE);
                    self.write_whole(i, s, game_data);
                    i += 1;
                }
                Step::Run(_) => unreachable!("handled above"),
            }
        }
        if run.1 > 0 {
            write_run(s, run);
        }
        s.u8(END);
        let (g, bg) = (self.ids.generations(), base.ids.generations());
        s.len(g.len());
        let differs = |k: &usize| bg.get(*k) != Some(&g[*k]);
        s.len((0..g.len()).filter(differs).count());
        let mut last = 0;
        for k in (0..g.len()).filter(differs) {
            s.var((k - last) as u64);
            s.u32(g[k]);
            last = k;
        }
    }

    /// The groups of `mask` of body `i`, in [`group`] order.
    fn write_groups(&self, i: usize, mask: u8, s: &mut impl Sink, game_data: bool) {
        if mask & group::POSITION != 0 {
            s.vec2(self.position[i]);
        }
        if mask & group::ANGLE != 0 {
            s.f64(self.angle[i]);
        }
        if mask & group::VELOCITY != 0 {
            s.vec2(self.velocity(i));
        }
        if mask & group::SPIN != 0 {
            s.f64(self.angular_velocity(i));
        }
        if mask & group::LIFETIME != 0 {
            write_lifetime(s, self.lifetime(i));
        }
        if mask & group::MOTION != 0 {
            write_motion(s, &self.motion(i), game_data);
        }
    }

    /// Body `i`, every field.
    fn write_whole(&self, i: usize, s: &mut impl Sink, game_data: bool) {
        let Rows {
            entity: _, // the body's, written first
            mass,
            start_position: _, // a cache: `start_frame` copies `position` there each step
            velocity,
            angular_velocity,
            force: _,
            gravity_scale,
            lifetime,
            controller: _,
            inputs: _,
            grounded: _,
            on_static: _,
            carrier: _,
            still: _,
            split,
            frozen: _,
            asleep: _,
            rest_frames: _,
            local_bounds: _, // `turned`, below
            user_data: _,
            no_lifetime_below: _, // a cache: counted again by a restore
            scaled: _,            // a count of `gravity_scale`, kept by every row's push
        } = &self.rows;
        // The `_` columns above are the motion group's ([`World::motion`] reads them all).
        s.entity(self.entity[i]);
        s.u8(self.layer[i]);
        s.u8(kind_tag(self.kind[i]));
        s.vec2(self.position[i]);
        s.f64(self.angle[i]);
        s.shape(self.shape(i));
        s.str(self.name(i));
        let r = self.row[i];
        s.bool(r != NO_ROW);
        if r == NO_ROW {
            return;
        }
        let r = r as usize;
        s.f64(mass[r]);
        s.vec2(velocity[r]);
        s.f64(angular_velocity[r]);
        s.f64(gravity_scale[r]);
        write_lifetime(s, lifetime[r]);
        s.splits(&split[r]);
        write_motion(s, &self.motion(i), game_data);
        s.bool(self.turned(i));
    }
}

enum Step {
    Run(u8),
    Changed(u8),
    Whole,
    New,
}

fn write_run(s: &mut impl Sink, (tag, n): (u8, u64)) {
    s.u8(tag);
    s.var(n);
}

fn same_vec(a: Vec2, b: Vec2) -> bool {
    a.x.to_bits() == b.x.to_bits() && a.y.to_bits() == b.y.to_bits()
}

/// Whether `a` and `b` encode to the same bytes (floats by their bits, unlike `==`).
fn same_bits<T: ?Sized>(a: &T, b: &T, write: impl Fn(&mut Vec<u8>, &T)) -> bool {
    let (mut x, mut y) = (Vec::new(), Vec::new());
    write(&mut x, a);
    write(&mut y, b);
    x == y
}

/// Whether two bodies' children are the same, bit for bit (no allocation for the usual
/// none: this runs for every body of every snapshot and checksum).
fn same_splits(a: &[Split], b: &[Split]) -> bool {
    (a.is_empty() && b.is_empty()) || same_bits(a, b, |s, x| s.splits(x))
}

fn write_lifetime(s: &mut impl Sink, l: Option<u32>) {
    s.bool(l.is_some());
    if let Some(l) = l {
        s.u32(l);
    }
}

fn write_motion(s: &mut impl Sink, m: &Motion, game_data: bool) {
    s.vec2(m.force);
    s.controller(m.controller.as_ref());
    s.inputs(&m.inputs);
    s.bool(m.grounded);
    s.bool(m.on_static);
    s.opt_entity(m.carrier);
    s.bool(m.still);
    s.bool(m.frozen);
    s.bool(m.asleep);
    s.u32(m.rest_frames);
    if game_data {
        s.u128(m.user_data);
    }
}

fn kind_tag(k: BodyKind) -> u8 {
    match k {
        BodyKind::Dynamic => 0,
        BodyKind::Static => 1,
        BodyKind::Kinematic => 2,
    }
}
