//! The `/events` channel's text: every [`GameEvent`] as a `foxglove.Log` kind, level and
//! sentence. The simulation reports events as data; this is the only place they are worded.
//!
//! A body is written `name #index:generation` (`rock #5:1`), the same id as `/bodies`,
//! `/contacts` and `/scene` give it. Names are looked up at the end of the frame: in the world
//! for a body still alive, in the frame's removed bodies for one removed during it.

use crate::record::Level as LogLevel;
use ricochet_sim::{
    Entity, FireOutcome, FrameOutput, GameEvent, JumpOutcome, Removal, ScriptInput, World,
};

/// One event as a log line.
pub struct EventLine {
    /// `input`, `spawn`, `destroy`, `expire`, `missed`, `contact`, `hit`, `hit_x`, `hit_y` or
    /// `crush`.
    pub kind: &'static str,
    /// Warnings for bodies lost and events that missed, info for inputs and spawns, debug for
    /// collisions.
    pub level: LogLevel,
    /// A sentence for people.
    pub message: String,
}

/// The `name #id` of a body alive at the end of the frame or removed during it.
fn body(world: &World, out: &FrameOutput, e: Entity) -> String {
    let name = match world.index_of(e) {
        Some(i) => world.name(i),
        None => out
            .removed
            .iter()
            .find(|r| r.entity == e)
            .map_or("?", |r| r.name.as_str()),
    };
    format!("{name} #{e}")
}

/// The event's kind: what Foxglove's Log panel shows as its name.
fn kind(event: &GameEvent) -> &'static str {
    match event {
        GameEvent::Input { .. } => "input",
        GameEvent::Missed { .. } | GameEvent::Gone { .. } => "missed",
        GameEvent::Spawned { .. } | GameEvent::Fired { .. } | GameEvent::SplitFrom { .. } => {
            "spawn"
        }
        GameEvent::Removed {
            cause: Removal::Expired,
            ..
        } => "expire",
        GameEvent::Removed { .. } => "destroy",
        GameEvent::Contact { .. } => "contact",
        GameEvent::PushedApart { .. } => "hit",
        GameEvent::PushedOut { axis: 0, .. } => "hit_x",
        GameEvent::PushedOut { .. } => "hit_y",
        GameEvent::Crushed { .. } => "crush",
    }
}

/// What a script input did, after `name #id: `.
fn input_text(input: &ScriptInput) -> String {
    match input {
        ScriptInput::Velocity(v) => format!("velocity set to [{}, {}]", v.x, v.y),
        ScriptInput::Impulse(v) => format!("impulse [{}, {}]", v.x, v.y),
        ScriptInput::Force(v) => format!("force set to [{}, {}]", v.x, v.y),
        ScriptInput::Thrust(on) => format!("thrust {}", if *on { "on" } else { "off" }),
        ScriptInput::Turn(x) => format!("turn {x}"),
        ScriptInput::Move(x) => format!("move {x}"),
        ScriptInput::Jump(JumpOutcome::Jumped) => "jump".to_owned(),
        ScriptInput::Jump(JumpOutcome::NotGrounded) => "jump ignored: not grounded".to_owned(),
        ScriptInput::Jump(JumpOutcome::NotARunner) => "jump ignored: not a runner".to_owned(),
        ScriptInput::Fire(FireOutcome::Fired) => "fire".to_owned(),
        ScriptInput::Fire(FireOutcome::NotAShip) => "fire ignored: not a ship".to_owned(),
        ScriptInput::Fire(FireOutcome::NoTemplate(t)) => format!("fire ignored: no template {t}"),
    }
}

/// The sentence for one event.
fn message(event: &GameEvent, world: &World, out: &FrameOutput) -> String {
    let body = |e: Entity| body(world, out, e);
    match event {
        GameEvent::Input { body: e, input } => format!("{}: {}", body(*e), input_text(input)),
        GameEvent::Missed { action, name } => format!("{action}: no body named {name} is alive"),
        GameEvent::Gone { action, body: e } => format!("{action}: body #{e} is no longer alive"),
        GameEvent::Spawned { body: e, template } => {
            format!("{} spawned from template {template}", body(*e))
        }
        GameEvent::Fired { bullet, .. } => format!("{} fired", body(*bullet)),
        GameEvent::SplitFrom { child, parent } => {
            format!("{} split from {}", body(*child), body(*parent))
        }
        GameEvent::Removed { body: e, cause } => {
            let why = match cause {
                Removal::Script => "destroyed by the script".to_owned(),
                Removal::HitBy(by) => format!("hit by {}", body(*by)),
                Removal::LeftWorld => "left the world".to_owned(),
                Removal::Expired => "expired".to_owned(),
            };
            format!("{} {why}", body(*e))
        }
        GameEvent::Contact { a, b, depth } => {
            format!("{} touches {}, depth {depth}", body(*a), body(*b))
        }
        GameEvent::PushedApart { a, b, depth } => {
            format!("{} and {} pushed apart by {depth}", body(*a), body(*b))
        }
        GameEvent::PushedOut {
            body: e,
            axis,
            by,
            obstacle,
        } => format!(
            "{} pushed along {} by {by} out of {}",
            body(*e),
            if *axis == 0 { "x" } else { "y" },
            body(*obstacle)
        ),
        GameEvent::Crushed { body: e, by, axis } => format!(
            "{} crushed by {}: no room to be pushed out along {}",
            body(*e),
            body(*by),
            if *axis == 0 { "x" } else { "y" },
        ),
    }
}

/// One event as a log line, names looked up in `world` (the end of the frame) and `out`.
pub fn line(event: &GameEvent, world: &World, out: &FrameOutput) -> EventLine {
    let kind = kind(event);
    let level = match kind {
        "destroy" | "expire" | "missed" | "crush" => LogLevel::Warning,
        "input" | "spawn" => LogLevel::Info,
        _ => LogLevel::Debug,
    };
    EventLine {
        kind,
        level,
        message: message(event, world, out),
    }
}

#[cfg(test)]
mod tests {
    use ricochet_sim::{Simulation, load_scenario};

    use super::*;

    /// Frame 1 destroys `old` (slot 0) and spawns `new`, which takes slot 0 again: the text
    /// names the removed body from the frame's removed list, the new one from the world,
    /// each with its generation.
    #[test]
    fn a_reused_slot_is_worded_with_each_bodys_generation() {
        let text = r#"
layers = ["thing"]
bodies = [{ name = "old", template = "thing", position = [0, 0] }]
script = [
    { frame = 1, action = "destroy", body = "old" },
    { frame = 1, action = "spawn", template = "thing", name = "new", position = [5, 0] },
    { frame = 1, action = "set_velocity", body = "old", velocity = [1, 0] },
]
[templates.thing]
layer = "thing"
shape = { kind = "circle", radius = 0.5 }
"#;
        let scenario = load_scenario(text, "reuse.toml").unwrap();
        let mut sim = Simulation::new(&scenario);
        sim.step();
        let out = sim.step();
        let lines: Vec<(&str, String)> = out
            .events
            .iter()
            .map(|e| {
                let l = line(e, sim.world(), &out);
                (l.kind, l.message)
            })
            .collect();
        assert_eq!(
            lines,
            [
                ("destroy", "old #0:0 destroyed by the script".to_owned()),
                ("spawn", "new #0:1 spawned from template thing".to_owned()),
                (
                    "missed",
                    "set_velocity: no body named old is alive".to_owned()
                ),
            ]
        );
    }

    /// A lift climbing into a ceiling with a box on it: the crush is a warning naming the box
    /// and the lift, and the pass it was found in.
    #[test]
    fn a_crush_is_a_warning_naming_the_box_and_what_crushed_it() {
        let text = r#"
layers = ["solid", "box"]
collide = [{ a = "box", b = "solid", response = "separate" }]
world.gravity = [0, -20]
[[bodies]]
name = "lift"
layer = "solid"
kind = "kinematic"
shape = { kind = "aabb", half_extents = [1.5, 0.25] }
velocity = [0, 3]
[[bodies]]
name = "ceiling"
layer = "solid"
kind = "static"
shape = { kind = "aabb", half_extents = [4, 0.5] }
position = [0, 2.025]
[[bodies]]
name = "box"
layer = "box"
shape = { kind = "aabb", half_extents = [0.4, 0.4] }
position = [0.3, 0.65]
"#;
        let scenario = load_scenario(text, "crush.toml").unwrap();
        let mut sim = Simulation::new(&scenario);
        let crush = (0..30).find_map(|_| {
            let out = sim.step();
            out.events
                .iter()
                .find(|e| matches!(e, GameEvent::Crushed { .. }))
                .map(|e| line(e, sim.world(), &out))
        });
        let crush = crush.expect("the box is crushed");
        assert_eq!(crush.kind, "crush");
        assert_eq!(crush.level, LogLevel::Warning);
        assert_eq!(
            crush.message,
            "box #2:0 crushed by lift #0:0: no room to be pushed out along y"
        );
    }
}
