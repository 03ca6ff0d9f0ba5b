//! The world's part of a snapshot: every body's state in id order, and the id allocator.
//!
//! Written through one [`Sink`], so the snapshot's bytes and [`crate::Simulation::checksum`]
//! cover the same fields; `game_data` false leaves out what no stage reads (`user_data`).
//! Rows are destructured whole: a new row column does not compile until it is written here
//! (or named as a cache).

use super::bounds::LocalBounds;
use super::rows::Rows;
use super::{NO_ROW, World};
use crate::def::{BodyDef, BodyKind};
use crate::entity::{Entity, EntityAllocator};
use crate::snapshot::SnapshotError;
use crate::snapshot::codec::{Reader, Sink};

fn bad(what: &str) -> SnapshotError {
    SnapshotError::malformed(what)
}

impl World {
    /// Writes every body's state, in id order, then each slot's generation.
    pub(crate) fn encode(&self, s: &mut impl Sink, game_data: bool) {
        let Rows {
            entity: _, // the body's, written below
            mass,
            start_position: _, // a cache: `start_frame` copies `position` there each step
            velocity,
            angular_velocity,
            force,
            gravity_scale,
            lifetime,
            controller,
            inputs,
            grounded,
            on_static,
            carrier,
            still,
            split,
            frozen,
            asleep,
            rest_frames,
            local_bounds,
            user_data,
        } = &self.rows;
        s.len(self.len());
        for i in 0..self.len() {
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
                continue;
            }
            let r = r as usize;
            s.f64(mass[r]);
            s.vec2(velocity[r]);
            s.f64(angular_velocity[r]);
            s.vec2(force[r]);
            s.f64(gravity_scale[r]);
            s.bool(lifetime[r].is_some());
            s.u32(lifetime[r].unwrap_or(0));
            s.controller(controller[r].as_ref());
            s.inputs(&inputs[r]);
            s.bool(grounded[r]);
            s.bool(on_static[r]);
            s.opt_entity(carrier[r]);
            s.bool(still[r]);
            s.splits(&split[r]);
            s.bool(frozen[r]);
            s.bool(asleep[r]);
            s.u32(rest_frames[r]);
            // The broad phase's bounds: exact, or the any-angle square once the body turned.
            s.bool(local_bounds[r].has_turned(self.shape(i), self.angle[i]));
            if game_data {
                s.u128(user_data[r]);
            }
        }
        let g = self.ids.generations();
        s.len(g.len());
        for &x in g {
            s.u32(x);
        }
    }

    /// The world [`World::encode`] wrote (with `game_data`), its caches rebuilt.
    pub(crate) fn decode(r: &mut Reader, layers: usize) -> Result<World, SnapshotError> {
        let mut w = World::new();
        let n = r.len(40)?;
        w.reserve(n);
        let mut last: Option<Entity> = None;
        // Sleep is set once every body is in: a static body's insertion wakes every sleeper.
        let mut sleep = Vec::new();
        for _ in 0..n {
            let e = r.entity()?;
            if last.is_some_and(|l| l.index >= e.index) {
                return Err(bad("bodies out of id order"));
            }
            last = Some(e);
            let layer = r.u8()?;
            if usize::from(layer) >= layers {
                return Err(bad("a body's layer"));
            }
            let kind = match r.u8()? {
                0 => BodyKind::Dynamic,
                1 => BodyKind::Static,
                2 => BodyKind::Kinematic,
                _ => return Err(bad("a body's kind")),
            };
            let mut def = BodyDef {
                kind,
                layer,
                position: r.vec2()?,
                angle: r.f64()?,
                shape: r.shape()?,
                name: r.str()?,
                ..BodyDef::default()
            };
            if !r.bool()? {
                def.controller = None;
                if !World::makes_scenery(&def) {
                    return Err(bad("scenery that is not static"));
                }
                w.insert(e, &def);
                continue;
            }
            def.mass = r.f64()?;
            def.velocity = r.vec2()?;
            def.angular_velocity = r.f64()?;
            def.force = r.vec2()?;
            def.gravity_scale = r.f64()?;
            let has_lifetime = r.bool()?;
            let l = r.u32()?;
            def.lifetime = has_lifetime.then_some(l);
            def.controller = r.controller()?;
            let inputs = r.inputs()?;
            let grounded = r.bool()?;
            let on_static = r.bool()?;
            let carrier = r.opt_entity()?;
            let still = r.bool()?;
            def.split = r.splits()?;
            let frozen = r.bool()?;
            let asleep = r.bool()?;
            let rest_frames = r.u32()?;
            let turned = r.bool()?;
            def.user_data = r.u128()?;
            w.insert(e, &def);
            let i = w.len() - 1;
            let k = w.row_of(i);
            let rows = &mut w.rows;
            // A static body's velocity stays zero in its row as `spawn` makes it.
            rows.velocity[k] = def.velocity;
            rows.angular_velocity[k] = def.angular_velocity;
            rows.inputs[k] = inputs;
            rows.grounded[k] = grounded;
            rows.on_static[k] = on_static;
            rows.carrier[k] = carrier;
            rows.still[k] = still;
            rows.frozen[k] = frozen;
            rows.local_bounds[k] = LocalBounds::restored(&def.shape, def.angle, turned);
            sleep.push((k, asleep, rest_frames));
        }
        for (k, asleep, rest_frames) in sleep {
            w.rows.asleep[k] = asleep;
            w.rows.rest_frames[k] = rest_frames;
            w.sleeping += usize::from(asleep);
        }
        let g = r.len(4)?;
        let generations = (0..g).map(|_| r.u32()).collect::<Result<Vec<_>, _>>()?;
        for e in &w.entity {
            if generations.get(e.index as usize) != Some(&e.generation) {
                return Err(bad("a body's generation is not its slot's"));
            }
        }
        w.ids = EntityAllocator::from_parts(generations, w.entity.iter().map(|e| e.index));
        for i in 0..w.len() {
            let c = w.carrier(i);
            if c.is_some_and(|c| w.index_of(c).is_none()) {
                return Err(bad("a carrier that is not a live body"));
            }
        }
        w.refresh_active();
        Ok(w)
    }
}

fn kind_tag(k: BodyKind) -> u8 {
    match k {
        BodyKind::Dynamic => 0,
        BodyKind::Static => 1,
        BodyKind::Kinematic => 2,
    }
}
