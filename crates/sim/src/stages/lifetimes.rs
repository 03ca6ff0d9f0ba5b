//! The `lifetimes` stage: bodies with a lifetime are removed when it runs out. A frozen
//! body's lifetime is paused with the rest of it.

use crate::event::Removal;
use crate::stages::StageCtx;
use crate::stages::remove::remove;
use crate::world::World;

/// Whether any body has a lifetime.
pub(crate) fn has_work(w: &World) -> bool {
    w.any_lifetime()
}

/// Counts down the lifetimes of the bodies not frozen, and removes those that ran out.
pub(crate) fn run(ctx: &mut StageCtx) {
    let mut expired = Vec::new();
    ctx.world.count_down_lifetimes(&mut expired);
    for e in expired {
        remove(ctx, e, Removal::Expired, false);
    }
}
