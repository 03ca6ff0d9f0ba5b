//! The `script` stage: this frame's scripted events, in file order.

use ricochet_geom::Vec2;

use crate::def::{Action, BodyKind, Controller, Event};
use crate::event::{FireOutcome, GameEvent, JumpOutcome, Removal, ScriptInput};
use crate::stages::StageCtx;
use crate::stages::remove::remove;

/// Applies `due`, the script events of this frame.
pub(crate) fn run(ctx: &mut StageCtx, due: &[Event]) {
    for event in due {
        apply(ctx, &event.action);
    }
    // A body an event named was woken: it moves this frame.
    ctx.world.refresh_active();
}

/// Applies one script action and records what it did.
fn apply(ctx: &mut StageCtx, action: &Action) {
    if let Action::Spawn { body, template } = action {
        let e = ctx.world.spawn(body);
        ctx.out.events.push(GameEvent::Spawned {
            body: e,
            template: template.clone(),
        });
        return;
    }
    let name = match action {
        Action::Spawn { .. } => unreachable!("handled above"),
        Action::Destroy { body }
        | Action::SetVelocity { body, .. }
        | Action::ApplyImpulse { body, .. }
        | Action::SetForce { body, .. }
        | Action::Thrust { body, .. }
        | Action::Turn { body, .. }
        | Action::Fire { body }
        | Action::Move { body, .. }
        | Action::Jump { body } => body,
    };
    let Some(i) = ctx.world.find(name) else {
        ctx.out.events.push(GameEvent::Missed {
            action: action.name(),
            name: name.clone(),
        });
        return;
    };
    let entity = ctx.world.entity[i];
    ctx.world.wake(i);
    let w = &mut *ctx.world;
    let input = match action {
        Action::Destroy { .. } => {
            remove(ctx, entity, Removal::Script, false);
            return;
        }
        Action::SetVelocity { velocity, .. } => {
            if w.kind[i] != BodyKind::Static {
                w.velocity[i] = *velocity;
            }
            ScriptInput::Velocity(*velocity)
        }
        Action::ApplyImpulse { impulse, .. } => {
            if w.kind[i] == BodyKind::Dynamic {
                w.velocity[i] += *impulse / w.mass[i];
            }
            ScriptInput::Impulse(*impulse)
        }
        Action::SetForce { force, .. } => {
            w.force[i] = *force;
            ScriptInput::Force(*force)
        }
        Action::Thrust { on, .. } => {
            w.inputs[i].thrust = *on;
            ScriptInput::Thrust(*on)
        }
        Action::Turn { input, .. } => {
            w.inputs[i].turn = *input;
            ScriptInput::Turn(*input)
        }
        Action::Move { input, .. } => {
            w.inputs[i].run = *input;
            ScriptInput::Move(*input)
        }
        Action::Jump { .. } => ScriptInput::Jump(match &w.controller[i] {
            Some(Controller::Runner { jump_speed, .. }) if w.grounded[i] => {
                w.velocity[i].y = *jump_speed;
                w.grounded[i] = false;
                JumpOutcome::Jumped
            }
            Some(Controller::Runner { .. }) => JumpOutcome::NotGrounded,
            _ => JumpOutcome::NotARunner,
        }),
        Action::Fire { .. } => ScriptInput::Fire(fire(ctx, i)),
        Action::Spawn { .. } => unreachable!("handled above"),
    };
    ctx.out.events.push(GameEvent::Input {
        body: entity,
        input,
    });
}

/// A ship fires: its bullet template appears `muzzle` ahead, moving at the ship's velocity
/// plus `bullet_speed` along the heading.
fn fire(ctx: &mut StageCtx, i: usize) -> FireOutcome {
    let w = &mut *ctx.world;
    let Some(Controller::Ship {
        bullet,
        bullet_speed,
        muzzle,
        ..
    }) = &w.controller[i]
    else {
        return FireOutcome::NotAShip;
    };
    let Some(template) = ctx.templates.get(bullet) else {
        return FireOutcome::NoTemplate(bullet.clone());
    };
    let (s, c) = libm::sincos(w.angle[i]);
    let heading = Vec2::new(c, s);
    let mut def = template.clone();
    def.position = w.position[i] + heading * *muzzle;
    def.velocity = w.velocity[i] + heading * *bullet_speed;
    def.angle = w.angle[i];
    let ship = w.entity[i];
    let bullet = w.spawn(&def);
    ctx.out.events.push(GameEvent::Fired { bullet, ship });
    FireOutcome::Fired
}
