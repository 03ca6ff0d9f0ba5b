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
    // Only active bodies move: static, frozen and sleeping ones stay where they were.
    for k in 0..w.active().len() {
        let i = w.active()[k] as usize;
        let p = &mut w.position[i];
        // Most bodies are inside: four comparisons (a NaN coordinate, never outside, takes
        // the slow path and is left where it is).
        if p.x >= b.min.x && p.x < b.max.x && p.y >= b.min.y && p.y < b.max.y {
            continue;
        }
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
