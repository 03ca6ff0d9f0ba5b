//! The `script` stage: this frame's scripted events, in file order.

use ricochet_geom::Vec2;

use crate::def::{Action, BodyKind, Controller};
use crate::output::{EventRecord, FrameOutput};
use crate::pipeline::Simulation;
use crate::stages::remove::remove;

pub(crate) fn has_work(sim: &Simulation) -> bool {
    !sim.due_events().is_empty()
}

pub(crate) fn run(sim: &mut Simulation, out: &mut FrameOutput) {
    let events = sim.due_events().to_vec();
    sim.cursor += events.len();
    for event in &events {
        apply(sim, out, &event.action);
    }
    // A body an event named was woken: it moves this frame.
    sim.world.refresh_active();
}

fn apply(sim: &mut Simulation, out: &mut FrameOutput, action: &Action) {
    if let Action::Spawn { body, template } = action {
        let e = sim.world.spawn(body);
        out.events.push(EventRecord {
            kind: "spawn",
            message: format!("{} #{e} spawned from template {template}", body.name),
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
    let Some(i) = sim.world.find(name) else {
        out.events.push(EventRecord {
            kind: "missed",
            message: format!("{}: no body named {name} is alive", action.name()),
        });
        return;
    };
    let entity = sim.world.entity[i];
    sim.world.wake(i);
    let w = &mut sim.world;
    let what = match action {
        Action::Destroy { .. } => {
            remove(
                sim,
                out,
                entity,
                "destroy",
                "destroyed by the script",
                false,
            );
            return;
        }
        Action::SetVelocity { velocity, .. } => {
            if w.kind[i] != BodyKind::Static {
                w.velocity[i] = *velocity;
            }
            format!("velocity set to [{}, {}]", velocity.x, velocity.y)
        }
        Action::ApplyImpulse { impulse, .. } => {
            if w.kind[i] == BodyKind::Dynamic {
                w.velocity[i] += *impulse / w.mass[i];
            }
            format!("impulse [{}, {}]", impulse.x, impulse.y)
        }
        Action::SetForce { force, .. } => {
            w.force[i] = *force;
            format!("force set to [{}, {}]", force.x, force.y)
        }
        Action::Thrust { on, .. } => {
            w.inputs[i].thrust = *on;
            format!("thrust {}", if *on { "on" } else { "off" })
        }
        Action::Turn { input, .. } => {
            w.inputs[i].turn = *input;
            format!("turn {input}")
        }
        Action::Move { input, .. } => {
            w.inputs[i].run = *input;
            format!("move {input}")
        }
        Action::Jump { .. } => match &w.controller[i] {
            Some(Controller::Runner { jump_speed, .. }) if w.grounded[i] => {
                w.velocity[i].y = *jump_speed;
                w.grounded[i] = false;
                "jump".to_owned()
            }
            Some(Controller::Runner { .. }) => "jump ignored: not grounded".to_owned(),
            _ => "jump ignored: not a runner".to_owned(),
        },
        Action::Fire { .. } => fire(sim, out, i),
        Action::Spawn { .. } => unreachable!("handled above"),
    };
    out.events.push(EventRecord {
        kind: "input",
        message: format!("{name} #{entity}: {what}"),
    });
}

/// A ship fires: its bullet template appears `muzzle` ahead, moving at the ship's velocity
/// plus `bullet_speed` along the heading.
fn fire(sim: &mut Simulation, out: &mut FrameOutput, i: usize) -> String {
    let w = &sim.world;
    let Some(Controller::Ship {
        bullet,
        bullet_speed,
        muzzle,
        ..
    }) = &w.controller[i]
    else {
        return "fire ignored: not a ship".to_owned();
    };
    let Some(template) = sim.templates.get(bullet) else {
        return format!("fire ignored: no template {bullet}");
    };
    let (s, c) = libm::sincos(w.angle[i]);
    let heading = Vec2::new(c, s);
    let mut def = template.clone();
    def.position = w.position[i] + heading * *muzzle;
    def.velocity = w.velocity[i] + heading * *bullet_speed;
    def.angle = w.angle[i];
    let e = sim.world.spawn(&def);
    out.events.push(EventRecord {
        kind: "spawn",
        message: format!("{} #{e} fired", def.name),
    });
    "fire".to_owned()
}
