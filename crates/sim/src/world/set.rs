//! Changing a body now, between frames or inside one: its pose, shape, user data or
//! velocity, each keeping the caches (bounds, static generation, sleep, the active list)
//! right and naming the body as disturbed ([`World::disturbed`]).

use super::local_bounds::LocalBounds;
use super::*;

impl World {
    /// Moves body `i` to `position` at `angle` now, keeping the caches right: a static body
    /// bumps [`World::static_generation`] (the broad phase and the per-axis stages re-index
    /// the static bodies) and wakes every sleeper (what it rested on may have moved); a
    /// moving body wakes and no longer rides what it stood on. The frame's swept tests start
    /// from the new position.
    pub fn teleport(&mut self, i: usize, position: Vec2, angle: f64) {
        *self.position_mut(i) = position;
        *self.angle_mut(i) = angle;
        let r = self.row[i];
        if r != NO_ROW {
            let r = r as usize;
            self.rows.start_position[r] = position;
            self.rows.carrier[r] = None;
            if self.kind[i] == BodyKind::Static {
                self.rows
                    .local_bounds
                    .set(r, LocalBounds::new(self.shape(i), angle));
            }
        }
        // A turned body's bounds follow from the cache (it widens to the any-angle disc).
        self.changed_in_place(i);
    }

    /// Gives body `i` another shape now, keeping the caches right as [`World::teleport`]
    /// does: the body's bounds are recomputed, a static body bumps
    /// [`World::static_generation`] (re-indexed by the broad phase and the per-axis stages)
    /// and wakes every sleeper, a moving body wakes.
    pub fn set_shape(&mut self, i: usize, shape: &Shape) {
        self.layout = crate::interned::next_serial();
        self.reshaped = true;
        let old = self.shape_id[i];
        let layer = usize::from(self.layer[i]);
        if !self.shapes.get(old).0.is_single_aabb() {
            self.non_boxes[layer] -= 1;
        }
        shape_key(shape, &mut self.key);
        let name = self.shapes.name(old);
        let new = self.shapes.acquire(self.key.as_slice(), name, || {
            let zero = shape.bounds(&Pose::new(Vec2::ZERO, 0.0));
            (shape.clone(), zero)
        });
        // Acquired before the old one is released: a look used by this body alone keeps
        // its id when it is given again.
        self.shapes.release(old);
        self.shape_id[i] = new;
        if !shape.is_single_aabb() {
            if self.non_boxes.len() <= layer {
                self.non_boxes.resize(layer + 1, 0);
            }
            self.non_boxes[layer] += 1;
        }
        let r = self.row[i];
        if r != NO_ROW {
            (self.rows.local_bounds).set(r as usize, LocalBounds::new(shape, self.angle[i]));
        }
        self.changed_in_place(i);
    }

    /// Body `i` was moved or reshaped where it stands: a static body bumps
    /// [`World::static_generation`] (the broad phase and the per-axis stages index it
    /// again) and wakes every sleeper, which new static geometry may now touch; a moving
    /// body wakes.
    fn changed_in_place(&mut self, i: usize) {
        if self.kind[i] == BodyKind::Static {
            self.static_generation += 1;
            self.wake_all();
        } else {
            self.wake(i);
            self.refresh_active();
        }
    }

    /// Renames body `i` (tests: no stage renames a body).
    #[cfg(test)]
    pub(crate) fn set_name(&mut self, i: usize, name: &str) {
        self.layout = crate::interned::next_serial();
        let old = self.shape_id[i];
        let id = self.names.acquire(name, || ());
        shape_key(&self.shapes.get(old).0, &mut self.key);
        let shape = self.shapes.get(old).clone();
        self.shape_id[i] = self.shapes.acquire(self.key.as_slice(), id, || shape);
        self.names.release(self.shapes.name(old));
        self.shapes.release(old);
    }

    /// Sets body `i`'s [`World::user_data`] (a body of scenery is given a row first).
    pub fn set_user_data(&mut self, i: usize, data: u128) {
        if data != self.user_data(i) {
            *self.user_data_mut(i) = data;
        }
    }

    /// Sets body `i`'s velocity and wakes it; a static body's velocity stays zero.
    pub fn set_velocity(&mut self, i: usize, velocity: Vec2) {
        if self.kind[i] != BodyKind::Static {
            *self.velocity_mut(i) = velocity;
            self.wake(i);
            self.refresh_active();
        }
    }
}
