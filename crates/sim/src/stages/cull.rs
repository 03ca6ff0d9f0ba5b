//! The `cull` stage: skipping the bodies outside the active region.
//!
//! With `[world.active_region]`, at the start of every frame (after the script) each moving
//! body whose bounds lie entirely outside the box centred on the focus body is frozen: not
//! moved, not tested, its lifetime paused. A frozen body keeps its exact state, so it
//! resumes exactly where it was on the first frame the region overlaps it again. Static
//! bodies are never frozen (and cost nothing while no active body is near them). With the
//! focus body gone, nothing is frozen.

use ricochet_geom::Bounds;

use crate::def::WorldDef;
use crate::entity::Entity;
use crate::stages::StageCtx;

/// Whether the scenario has an active region.
pub(crate) fn has_work(def: &WorldDef) -> bool {
    def.active_region.is_some()
}

/// Freezes the moving bodies outside the region and thaws those inside it. `focus` is the
/// body the region follows, remembered by id from frame to frame (a name lookup is a scan
/// of every body).
pub(crate) fn run(ctx: &mut StageCtx, focus: &mut Option<Entity>) {
    let Some(region) = &ctx.def.active_region else {
        return;
    };
    let w = &mut *ctx.world;
    let found = match focus.and_then(|e| w.index_of(e)) {
        Some(i) => Some(i),
        None => w.find(&region.focus),
    };
    *focus = found.map(|i| w.entity[i]);
    let area = found.map(|f| Bounds::around(w.position[f], region.half_extents));
    let mut frozen = 0;
    for k in 0..w.movers().len() {
        let i = w.movers()[k] as usize;
        let outside = area.is_some_and(|a| Some(i) != found && !w.bounds(i).overlaps(&a));
        if w.frozen(i) != outside {
            w.disturb(i);
        }
        w.set_frozen(i, outside);
        if outside {
            // Thawed, it finds what it stands on again: the lift it rode has moved on.
            *w.carrier_mut(i) = None;
        }
        frozen += usize::from(outside);
    }
    w.refresh_active();
    ctx.out.stats.frozen = frozen;
}
