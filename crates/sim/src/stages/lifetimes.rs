//! The `lifetimes` stage: bodies with a lifetime are removed when it runs out. A frozen
//! body's lifetime is paused with the rest of it.

use crate::event::Removal;
use crate::output::FrameOutput;
use crate::pipeline::Simulation;
use crate::stages::remove::remove;

pub(crate) fn has_work(sim: &Simulation) -> bool {
    sim.world.any_lifetime()
}

pub(crate) fn run(sim: &mut Simulation, out: &mut FrameOutput) {
    let mut expired = Vec::new();
    let w = &mut sim.world;
    for (i, life) in w.lifetime.iter_mut().enumerate() {
        if w.frozen[i] {
            continue;
        }
        if let Some(l) = life {
            *l = l.saturating_sub(1);
            if *l == 0 {
                expired.push(w.entity[i]);
            }
        }
    }
    for e in expired {
        remove(sim, out, e, Removal::Expired, false);
    }
}
