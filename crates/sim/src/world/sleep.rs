//! Sleep: waking a body, putting one to sleep, and waking every sleeper.

use super::{NO_ROW, World};

impl World {
    /// Wakes body `i` if it sleeps: it is integrated again from the next frame (or the
    /// next [`World::refresh_active`]). Scenery never sleeps.
    pub fn wake(&mut self, i: usize) {
        let r = self.row[i];
        if r == NO_ROW {
            return;
        }
        let r = r as usize;
        if self.rows.asleep[r] {
            self.sleeping -= 1;
            self.disturb(i);
        }
        self.rows.asleep[r] = false;
        self.rows.rest_frames[r] = 0;
    }

    /// Puts body `i` to sleep (from the next [`World::refresh_active`] on). A sleeper rides
    /// nothing: when it wakes, the next `resolve_y` finds what it stands on.
    pub fn put_to_sleep(&mut self, i: usize) {
        let r = self.row_of(i);
        if !self.rows.asleep[r] {
            self.sleeping += 1;
            self.disturb(i);
        }
        self.rows.asleep[r] = true;
        self.rows.carrier[r] = None;
    }

    /// How many bodies are asleep.
    #[must_use]
    pub fn sleeping(&self) -> usize {
        self.sleeping
    }

    /// Wakes every sleeping body, now: the active list is recomputed.
    pub fn wake_all(&mut self) {
        if self.sleeping > 0 {
            self.disturb_all();
            self.sleeping = 0;
            self.rows.asleep.fill(false);
            self.rows.rest_frames.fill(0);
            self.refresh_active();
        }
    }
}
