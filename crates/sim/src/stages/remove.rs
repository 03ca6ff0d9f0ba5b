//! Removing bodies (destroy responses, scripts, lifetimes, leaving the world), and spawning
//! the children of a split.

use crate::entity::Entity;
use crate::event::{GameEvent, Removal};
use crate::output::{FrameOutput, RemovedBody};
use crate::pipeline::Simulation;

/// Removes `entity` if it is still alive, records it, and, with `split`, spawns its children
/// at its position with its velocity added to theirs.
pub(crate) fn remove(
    sim: &mut Simulation,
    out: &mut FrameOutput,
    entity: Entity,
    cause: Removal,
    split: bool,
) {
    let Some(i) = sim.world.index_of(entity) else {
        return;
    };
    let w = &sim.world;
    let removed = RemovedBody {
        entity,
        name: w.name[i].clone(),
        layer: w.layer[i],
        shape: w.shape[i].clone(),
        pose: w.pose(i),
        velocity: w.velocity[i],
        kind: w.kind[i],
    };
    out.events.push(GameEvent::Removed {
        body: entity,
        cause,
    });
    let children = if split {
        std::mem::take(&mut sim.world.split[i])
    } else {
        Vec::new()
    };
    sim.world.despawn(i);
    for child in children {
        let Some(template) = sim.templates.get(&child.template) else {
            continue;
        };
        let mut def = template.clone();
        def.position = removed.pose.position + child.offset;
        def.velocity = removed.velocity + child.velocity;
        let e = sim.world.spawn(&def);
        out.events.push(GameEvent::SplitFrom {
            child: e,
            parent: entity,
        });
    }
    out.removed.push(removed);
}
