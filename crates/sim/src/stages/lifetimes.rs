//! The `lifetimes` stage: bodies with a lifetime are removed when it runs out.

use crate::output::FrameOutput;
use crate::pipeline::Simulation;
use crate::stages::remove::remove;

pub(crate) fn has_work(sim: &Simulation) -> bool {
    sim.world.lifetime.iter().any(Option::is_some)
}

pub(crate) fn run(sim: &mut Simulation, out: &mut FrameOutput) {
    let mut expired = Vec::new();
    for (i, life) in sim.world.lifetime.iter_mut().enumerate() {
        if let Some(l) = life {
            *l = l.saturating_sub(1);
            if *l == 0 {
                expired.push(sim.world.entity[i]);
            }
        }
    }
    for e in expired {
        remove(sim, out, e, "expire", "expired", false);
    }
}
