//! The `bounds` stage: wrap around (Asteroids), or remove bodies that left the world.

use crate::def::WorldDef;
use crate::event::Removal;
use crate::stages::StageCtx;
use crate::stages::remove::remove;
use crate::stages::wrap::wrap_coordinate;

/// Whether the world has bounds.
pub(crate) fn has_work(def: &WorldDef) -> bool {
    def.bounds.is_some()
}

/// Wraps the active bodies that crossed the bounds, or removes them.
pub(crate) fn run(ctx: &mut StageCtx) {
    let Some(b) = ctx.def.bounds else {
        return;
    };
    let size = b.max - b.min;
    let mut gone = Vec::new();
    let w = &mut *ctx.world;
    // Only active bodies move: static, frozen and sleeping ones stay where they were. Most
    // are inside: one tight pass finds the others (and a NaN coordinate, never outside,
    // which the loop below leaves where it is).
    let mut outside = Vec::new();
    w.active_not_inside(b.min, b.max, &mut outside);
    for i in outside {
        let i = i as usize;
        w.disturb(i);
        let p = &mut w.position[i];
        for axis in 0..2 {
            if p[axis] < b.min[axis] || p[axis] >= b.max[axis] {
                if b.wrap {
                    p[axis] = wrap_coordinate(p[axis], b.min[axis], b.max[axis], size[axis]);
                } else if !gone.contains(&w.entity[i]) {
                    gone.push(w.entity[i]);
                }
            }
        }
    }
    for e in gone {
        remove(ctx, e, Removal::LeftWorld, false);
    }
}
