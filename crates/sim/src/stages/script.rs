//! The `script` stage: this frame's scripted events, in file order, then the actions the
//! game sent with [`crate::Simulation::apply`], in the order sent.

use ricochet_geom::Vec2;

use crate::action::{Action, Event, ScriptAction};
use crate::def::{BodyKind, Controller};
use crate::entity::Entity;
use crate::event::{FireOutcome, GameEvent, JumpOutcome, Removal, ScriptInput};
use crate::stages::StageCtx;
use crate::stages::remove::remove;

/// Applies `due`, the script events of this frame, then `sent`, the actions the game sent
/// since the last step, in the order sent.
pub(crate) fn run(ctx: &mut StageCtx, due: &[Event], sent: &[(Entity, Action)]) {
    for event in due {
        match &event.action {
            ScriptAction::Spawn { body, template } => {
                let e = ctx.world.spawn(body);
                ctx.out.events.push(GameEvent::Spawned {
                    body: e,
                    template: template.clone(),
                });
            }
            ScriptAction::Body { name, action } => match ctx.world.find(name) {
                Some(i) => apply(ctx, i, action),
                None => ctx.out.events.push(GameEvent::Missed {
                    action: action.name(),
                    name: name.clone(),
                }),
            },
        }
    }
    for (entity, action) in sent {
        match ctx.world.index_of(*entity) {
            Some(i) => apply(ctx, i, action),
            None => ctx.out.events.push(GameEvent::Gone {
                action: action.name(),
                body: *entity,
            }),
        }
    }
    // A body an event named was woken: it moves this frame.
    ctx.world.refresh_active();
}

/// Applies one action to body `i` and records what it did.
fn apply(ctx: &mut StageCtx, i: usize, action: &Action) {
    let entity = ctx.world.entity[i];
    ctx.world.wake(i);
    let w = &mut *ctx.world;
    let input = match action {
        Action::Destroy => {
            remove(ctx, entity, Removal::Script, false);
            return;
        }
        Action::SetVelocity(velocity) => {
            if w.kind[i] != BodyKind::Static {
                *w.velocity_mut(i) = *velocity;
            }
            ScriptInput::Velocity(*velocity)
        }
        Action::ApplyImpulse(impulse) => {
            if w.kind[i] == BodyKind::Dynamic {
                let m = w.mass(i);
                *w.velocity_mut(i) += *impulse / m;
            }
            ScriptInput::Impulse(*impulse)
        }
        Action::SetForce(force) => {
            w.set_force(i, *force);
            ScriptInput::Force(*force)
        }
        Action::Thrust(on) => {
            w.set_thrust(i, *on);
            ScriptInput::Thrust(*on)
        }
        Action::Turn(input) => {
            w.inputs_mut(i).turn = *input;
            ScriptInput::Turn(*input)
        }
        Action::Move(input) => {
            w.inputs_mut(i).run = *input;
            ScriptInput::Move(*input)
        }
        Action::Jump => ScriptInput::Jump(match w.controller(i).cloned() {
            Some(Controller::Runner { jump_speed, .. }) if w.grounded(i) => {
                w.velocity_mut(i).y = jump_speed;
                *w.grounded_mut(i) = false;
                JumpOutcome::Jumped
            }
            Some(Controller::Runner { .. }) => JumpOutcome::NotGrounded,
            _ => JumpOutcome::NotARunner,
        }),
        Action::Fire => ScriptInput::Fire(fire(ctx, i)),
        Action::Drop => {
            let grounded = w.kind[i] == BodyKind::Dynamic && w.grounded(i);
            if grounded {
                w.inputs_mut(i).drop = true;
            }
            ScriptInput::Drop(grounded)
        }
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
    }) = w.controller(i)
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
    def.velocity = w.velocity(i) + heading * *bullet_speed;
    def.angle = w.angle[i];
    let ship = w.entity[i];
    let bullet = w.spawn(&def);
    ctx.out.events.push(GameEvent::Fired { bullet, ship });
    FireOutcome::Fired
}

/// Sets the velocities that move each kinematic body of `targets` to its target pose over
/// this step (`(target - now) / dt`), and stops those of `targeted` (moved to a target last
/// step) that have none this time; `targeted` becomes this step's bodies. A body gone since
/// is skipped. See [`crate::Simulation::set_target_pose`].
pub(crate) fn move_to_targets(
    world: &mut crate::World,
    dt: f64,
    targets: &mut Vec<(Entity, ricochet_geom::Pose)>,
    targeted: &mut Vec<Entity>,
) {
    for e in targeted.iter() {
        let again = targets.binary_search_by_key(e, |t| t.0).is_ok();
        if let (false, Some(i)) = (again, world.index_of(*e)) {
            *world.velocity_mut(i) = Vec2::ZERO;
            *world.angular_velocity_mut(i) = 0.0;
        }
    }
    targeted.clear();
    for (e, pose) in targets.drain(..) {
        if let Some(i) = world.index_of(e) {
            *world.velocity_mut(i) = (pose.position - world.position[i]) / dt;
            *world.angular_velocity_mut(i) = (pose.angle - world.angle[i]) / dt;
            targeted.push(e);
        }
    }
}
