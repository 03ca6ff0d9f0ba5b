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

    /// Whether every body is awake and none is frozen (outside the active region): then a
    /// pair's bodies need not be read to know that neither is. One pass over a byte a row,
    /// without a branch a row; `sleeping` is the count of the asleep ones.
    pub(crate) fn all_awake_and_free(&self) -> bool {
        self.sleeping == 0 && !self.rows.frozen.iter().fold(false, |any, &f| any | f)
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
