//! Removing bodies (destroy responses, scripts, lifetimes, leaving the world), and spawning
//! the children of a split.

use crate::entity::Entity;
use crate::event::{GameEvent, Removal};
use crate::output::RemovedBody;
use crate::stages::StageCtx;

/// Removes `entity` if it is still alive, records it, and, with `split`, spawns its children
/// at its position with its velocity added to theirs.
pub(crate) fn remove(ctx: &mut StageCtx, entity: Entity, cause: Removal, split: bool) {
    let w = &mut *ctx.world;
    let Some(i) = w.index_of(entity) else {
        return;
    };
    let removed = RemovedBody {
        entity,
        name: w.name(i).to_owned(),
        layer: w.layer[i],
        shape: w.shape(i).clone(),
        pose: w.pose(i),
        velocity: w.velocity(i),
        angular_velocity: w.angular_velocity(i),
        kind: w.kind[i],
    };
    ctx.out.events.push(GameEvent::Removed {
        body: entity,
        layer: removed.layer,
        cause,
    });
    let children = if split { w.take_split(i) } else { Vec::new() };
    w.despawn(i);
    for child in children {
        let Some(template) = ctx.templates.get(&child.template) else {
            continue;
        };
        let mut def = template.clone();
        def.position = removed.pose.position + child.offset;
        def.velocity = removed.velocity + child.velocity;
        let e = w.spawn(&def);
        ctx.out.events.push(GameEvent::SplitFrom {
            child: e,
            parent: entity,
        });
    }
    ctx.out.removed.push(removed);
}
