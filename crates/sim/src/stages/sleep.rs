//! The `sleep` stage: skipping the bodies at rest.
//!
//! With `sleep_after = N`, a dynamic body that ends `N` frames in a row held up by a static
//! body (pushed up by one that frame), with zero velocity and angular velocity and exactly
//! (bit for bit) where it started the frame, falls asleep. A body at rest like that is at a
//! fixed point of the step, so skipping it changes none of its state: it keeps its
//! position, zero velocity and `grounded`. It is not integrated and not tested against
//! static bodies or other sleepers; it wakes when an awake body touches it (a `detect`
//! contact, or a per-axis push against it by a body that was not itself still the frame
//! before: a box resting on a sleeper leaves it asleep), when a script event names it, when
//! a static body is added, or when any body is removed (what it rested on may be gone).

use ricochet_geom::Vec2;

use crate::def::{BodyKind, WorldDef};
use crate::stages::StageCtx;

/// Whether the scenario has `sleep_after`.
pub(crate) fn has_work(def: &WorldDef) -> bool {
    def.sleep_after.is_some()
}

/// Counts the frames each active dynamic body rested, and puts to sleep those that rested
/// `sleep_after` frames.
pub(crate) fn run(ctx: &mut StageCtx) {
    let Some(after) = ctx.def.sleep_after else {
        return;
    };
    let w = &mut *ctx.world;
    for k in 0..w.active().len() {
        let i = w.active()[k] as usize;
        let still = w.velocity(i) == Vec2::ZERO
            && w.angular_velocity(i) == 0.0
            && w.position[i].x.to_bits() == w.start_position(i).x.to_bits()
            && w.position[i].y.to_bits() == w.start_position(i).y.to_bits();
        *w.still_mut(i) = still;
        let resting = still && w.kind[i] == BodyKind::Dynamic && w.on_static(i);
        *w.rest_frames_mut(i) = if resting {
            w.rest_frames(i).saturating_add(1)
        } else {
            0
        };
        if w.rest_frames(i) >= after {
            w.put_to_sleep(i);
        }
    }
    // Bodies put to sleep above, and bodies woken this frame (by a contact or a push),
    // leave or rejoin the active list for the next frame.
    w.refresh_active();
    ctx.out.stats.asleep = w.sleeping();
}
