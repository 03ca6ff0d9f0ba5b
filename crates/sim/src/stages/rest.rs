//! Skipping bodies nothing is happening to: the `cull` stage (the active region) and the
//! `sleep` stage.
//!
//! **Culling.** With `[world.active_region]`, at the start of every frame (after the script)
//! each moving body whose bounds lie entirely outside the box centred on the focus body is
//! frozen: not moved, not tested, its lifetime paused. A frozen body keeps its exact state,
//! so it resumes exactly where it was on the first frame the region overlaps it again.
//! Static bodies are never frozen (and cost nothing while no active body is near them). With
//! the focus body gone, nothing is frozen.
//!
//! **Sleeping.** With `sleep_after = N`, a dynamic body that ends `N` frames in a row
//! held up by a static body (pushed up by one that frame), with zero velocity and angular velocity and exactly (bit for bit) where it
//! started the frame, falls asleep. A body at rest like that is at a fixed point of the
//! step, so skipping it changes none of its state: it keeps its position, zero velocity and
//! `grounded`. It is not integrated and not tested against static bodies or other sleepers;
//! it wakes when an awake body touches it (a `detect` contact, or a per-axis push against it
//! by a body that was not itself still the frame before: a box resting on a sleeper leaves
//! it asleep), when a script event names it, when a static body is added, or when any body is
//! removed (what it rested on may be gone).

use ricochet_geom::{Bounds, Vec2};

use crate::def::BodyKind;
use crate::output::FrameOutput;
use crate::pipeline::Simulation;

pub(crate) fn has_region(sim: &Simulation) -> bool {
    sim.scenario.world.active_region.is_some()
}

pub(crate) fn cull(sim: &mut Simulation, out: &mut FrameOutput) {
    let Some(region) = &sim.scenario.world.active_region else {
        return;
    };
    let w = &mut sim.world;
    // The focus body, remembered by id (a name lookup is a scan of every body).
    let focus = match sim.focus.and_then(|e| w.index_of(e)) {
        Some(i) => Some(i),
        None => w.find(&region.focus),
    };
    sim.focus = focus.map(|i| w.entity[i]);
    let area = focus.map(|f| Bounds::around(w.position[f], region.half_extents));
    let mut frozen = 0;
    for k in 0..w.movers().len() {
        let i = w.movers()[k] as usize;
        let outside = area.is_some_and(|a| Some(i) != focus && !w.bounds(i).overlaps(&a));
        w.frozen[i] = outside;
        frozen += usize::from(outside);
    }
    w.refresh_active();
    out.stats.frozen = frozen;
}

pub(crate) fn has_sleep(sim: &Simulation) -> bool {
    sim.scenario.world.sleep_after.is_some()
}

pub(crate) fn sleep(sim: &mut Simulation, out: &mut FrameOutput) {
    let Some(after) = sim.scenario.world.sleep_after else {
        return;
    };
    let w = &mut sim.world;
    for k in 0..w.active().len() {
        let i = w.active()[k] as usize;
        let still = w.velocity[i] == Vec2::ZERO
            && w.angular_velocity[i] == 0.0
            && w.position[i].x.to_bits() == w.start_position[i].x.to_bits()
            && w.position[i].y.to_bits() == w.start_position[i].y.to_bits();
        w.still[i] = still;
        let resting = still && w.kind[i] == BodyKind::Dynamic && w.on_static[i];
        w.rest_frames[i] = if resting {
            w.rest_frames[i].saturating_add(1)
        } else {
            0
        };
        if w.rest_frames[i] >= after {
            w.put_to_sleep(i);
        }
    }
    // Bodies put to sleep above, and bodies woken this frame (by a contact or a push),
    // leave or rejoin the active list for the next frame.
    w.refresh_active();
    out.stats.asleep = w.sleeping();
}
