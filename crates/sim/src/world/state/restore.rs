//! Restoring a snapshot's bodies: onto the same bodies, patched in place column by column
//! (a rollback); onto any other world, built anew from the baseline and the records.

use super::*;

impl World {
    /// Puts the decoded bodies in this world. A world with the same bodies, each with the
    /// baseline's definition (a rollback a few frames back, the common case), is patched in
    /// place, column by column; any other is built anew. Either way every cache (rows,
    /// counters, active list, bounds) is right for the state.
    pub(crate) fn restore_bodies(&mut self, base: &World, b: &Bodies) {
        if !self.patch(base, b) {
            *self = World::rebuilt(base, b);
        }
        self.layout = crate::interned::next_serial();
        self.disturb_all();
        self.kept_energy = None;
    }

    /// Patches the columns in place; false (nothing changed) when this world's bodies are
    /// not `b`'s with the baseline's definitions.
    fn patch(&mut self, base: &World, b: &Bodies) -> bool {
        if !b.wholes.is_empty() || self.reshaped || self.entity != b.entities {
            return false;
        }
        let rows_match = b.entries.iter().enumerate().all(|(i, e)| {
            let j = e.base as usize;
            (self.row[i] == NO_ROW) == (base.row[j] == NO_ROW)
                && self.layer[i] == base.layer[j]
                && self.kind[i] == base.kind[j]
        });
        if !rows_match {
            return false;
        }
        let empty = Delta::default();
        for (i, e) in b.entries.iter().enumerate() {
            let (j, m) = (e.base as usize, e.mask);
            let d = if m == 0 {
                &empty
            } else {
                &b.deltas[e.at as usize]
            };
            let pick = |g: u8| m & g != 0;
            self.position[i] = if pick(group::POSITION) {
                d.position
            } else {
                base.position[j]
            };
            self.angle[i] = if pick(group::ANGLE) {
                d.angle
            } else {
                base.angle[j]
            };
            let r = self.row[i];
            if r == NO_ROW {
                continue;
            }
            let r = r as usize;
            let rows = &mut self.rows;
            rows.start_position[r] = self.position[i];
            rows.velocity[r] = if pick(group::VELOCITY) {
                d.velocity
            } else {
                base.velocity(j)
            };
            rows.angular_velocity[r] = if pick(group::SPIN) {
                d.spin
            } else {
                base.angular_velocity(j)
            };
            rows.lifetime[r] = if pick(group::LIFETIME) {
                d.lifetime
            } else {
                base.lifetime(j)
            };
            if pick(group::MOTION) {
                self.set_motion(r, b.motion(d));
            } else {
                self.set_motion(r, &base.motion(j));
            }
            let turned = base.turned(j) != pick(group::TURNED);
            let (shape, angle) = (&self.shapes.get(self.shape_id[i]).0, self.angle[i]);
            let column = &mut self.rows.local_bounds;
            // Bounds that tell `turned` as they should are what a restore would build: an
            // exact box at another angle becomes the square at its next use.
            if column.get(r).has_turned(angle) != turned {
                column.set(r, LocalBounds::restored(shape, angle, turned));
            }
        }
        self.recount();
        self.ids =
            EntityAllocator::from_parts(b.generations.clone(), self.entity.iter().map(|e| e.index));
        self.refresh_active();
        true
    }

    /// Row `r`'s motion group set to `m` (its `turned` is the caller's).
    fn set_motion(&mut self, r: usize, m: &Motion) {
        let rows = &mut self.rows;
        self.with_force -= usize::from(rows.force[r] != Vec2::ZERO);
        self.with_force += usize::from(m.force != Vec2::ZERO);
        rows.force[r] = m.force;
        if rows.controller[r].is_some() || m.controller.is_some() {
            rows.controller[r].clone_from(&m.controller);
        }
        self.thrusting -= usize::from(rows.inputs[r].thrust);
        self.thrusting += usize::from(m.inputs.thrust);
        rows.inputs[r] = m.inputs;
        rows.grounded[r] = m.grounded;
        rows.on_static[r] = m.on_static;
        rows.carrier[r] = m.carrier;
        rows.still[r] = m.still;
        rows.frozen[r] = m.frozen;
        rows.asleep[r] = m.asleep;
        rows.rest_frames[r] = m.rest_frames;
        rows.user_data[r] = m.user_data;
    }

    /// The counters of the rows, counted again.
    fn recount(&mut self) {
        let rows = &self.rows;
        self.sleeping = rows.asleep.iter().filter(|&&a| a).count();
        self.with_lifetime = rows.lifetime.iter().filter(|l| l.is_some()).count();
        self.controlled = (rows.controller.iter().zip(&rows.entity))
            .filter(|(c, _)| c.is_some())
            .map(|(_, &e)| e)
            .collect();
        self.controlled.sort_unstable();
        self.rows.no_lifetime_below = (self.rows.lifetime.iter())
            .take_while(|l| l.is_none())
            .count();
    }

    /// A world of `b`'s bodies, built body by body (the baseline's definitions cloned).
    fn rebuilt(base: &World, b: &Bodies) -> World {
        let mut w = World::new();
        w.reserve(b.entries.len());
        // Sleep is set once every body is in: a static body's insertion wakes every sleeper.
        let mut sleep = Vec::new();
        for e in &b.entries {
            let whole = match e.base {
                u32::MAX => b.wholes[e.at as usize].clone(),
                j => {
                    let mut x = base.whole(j as usize);
                    if e.mask != 0 {
                        x.apply(e.mask, &b.deltas[e.at as usize], b);
                    }
                    x
                }
            };
            w.insert_whole(whole, &mut sleep);
        }
        for (k, asleep, rest_frames) in sleep {
            w.rows.asleep[k] = asleep;
            w.rows.rest_frames[k] = rest_frames;
            w.sleeping += usize::from(asleep);
        }
        w.ids =
            EntityAllocator::from_parts(b.generations.clone(), w.entity.iter().map(|e| e.index));
        w.reshaped = b.redefined;
        w.refresh_active();
        w
    }

    /// Body `i` as a [`Whole`].
    fn whole(&self, i: usize) -> Whole {
        let row = (self.row[i] != NO_ROW).then(|| WholeRow {
            mass: self.mass(i),
            velocity: self.velocity(i),
            spin: self.angular_velocity(i),
            gravity_scale: self.gravity_scale(i),
            lifetime: self.lifetime(i),
            split: self.split(i).to_vec(),
            motion: self.motion(i),
            turned: self.turned(i),
        });
        Whole {
            entity: self.entity[i],
            layer: self.layer[i],
            kind: self.kind[i],
            position: self.position[i],
            angle: self.angle[i],
            shape: self.shape(i).clone(),
            name: self.name(i).to_owned(),
            row,
        }
    }

    /// Inserts a whole body; its sleep state goes to `sleep`, set once every body is in.
    fn insert_whole(&mut self, x: Whole, sleep: &mut Vec<(usize, bool, u32)>) {
        let mut def = BodyDef {
            kind: x.kind,
            layer: x.layer,
            position: x.position,
            angle: x.angle,
            shape: x.shape,
            name: x.name,
            controller: None,
            ..BodyDef::default()
        };
        let Some(row) = x.row else {
            self.insert(x.entity, &def);
            return;
        };
        def.mass = row.mass;
        def.velocity = row.velocity;
        def.angular_velocity = row.spin;
        def.force = row.motion.force;
        def.gravity_scale = row.gravity_scale;
        def.lifetime = row.lifetime;
        def.controller = row.motion.controller.clone();
        def.split = row.split;
        def.user_data = row.motion.user_data;
        self.insert(x.entity, &def);
        let i = self.len() - 1;
        let k = self.row_of(i);
        let rows = &mut self.rows;
        // A static body's velocity stays zero in its row as `spawn` makes it.
        rows.velocity[k] = def.velocity;
        rows.angular_velocity[k] = def.angular_velocity;
        (rows.local_bounds).set(k, LocalBounds::restored(&def.shape, def.angle, row.turned));
        // Awake until every body is in: a static body inserted later wakes every sleeper.
        let m = row.motion;
        sleep.push((k, m.asleep, m.rest_frames));
        let awake = Motion {
            asleep: false,
            rest_frames: 0,
            ..m
        };
        self.set_motion(k, &awake);
    }
}

impl Whole {
    /// The groups of `mask` from `d`.
    fn apply(&mut self, mask: u8, d: &Delta, b: &Bodies) {
        if mask & group::POSITION != 0 {
            self.position = d.position;
        }
        if mask & group::ANGLE != 0 {
            self.angle = d.angle;
        }
        let Some(row) = &mut self.row else {
            return;
        };
        if mask & group::VELOCITY != 0 {
            row.velocity = d.velocity;
        }
        if mask & group::SPIN != 0 {
            row.spin = d.spin;
        }
        if mask & group::LIFETIME != 0 {
            row.lifetime = d.lifetime;
        }
        if mask & group::MOTION != 0 {
            row.motion = b.motion(d).clone();
        }
        if mask & group::TURNED != 0 {
            row.turned = !row.turned;
        }
    }
}
