//! The `/events` channel's text: every [`GameEvent`] as a `foxglove.Log` kind, level and
//! sentence. The simulation reports events as data; this is the only place they are worded.
//!
//! Contacts themselves are not events: every contact of every frame, its response and its
//! push, is on `/contacts`. `/events` says when a pair starts and stops touching
//! (`touch_begin`, `touch_end`; `docs/touches.md`), so a box resting on a floor writes one
//! line when it lands and one when it leaves, none in between.
//!
//! A body is written `name #index:generation` (`rock #5:1`), the same id as `/bodies`,
//! `/contacts` and `/scene` give it. Names are looked up at the end of the frame: in the world
//! for a body still alive, in the frame's removed bodies for one removed during it.

use crate::recorder::Level as LogLevel;
use ricochet_geom::{Number, ShapeDef, Vec2};
use ricochet_sim::{
    BodyKind, Controller, Entity, FireOutcome, FrameOutput, GameEvent, JumpOutcome, Removal,
    ScriptInput, Simulation, World,
};

/// One event as a log line.
pub struct EventLine {
    /// `input`, `spawn`, `destroy`, `expire`, `missed`, `crush`, `touch_begin`,
    /// `touch_end`, or `click` (a live answer of `ricochet serve`, never recorded).
    pub kind: &'static str,
    /// Warnings for bodies lost or crushed and events that missed, info for the rest
    /// (inputs, spawns, touches).
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
        GameEvent::Crushed { .. } => "crush",
        GameEvent::TouchBegin { .. } => "touch_begin",
        GameEvent::TouchEnd { .. } => "touch_end",
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
        ScriptInput::Drop(true) => "drop".to_owned(),
        ScriptInput::Drop(false) => "drop ignored: not grounded".to_owned(),
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
        GameEvent::Removed { body: e, cause, .. } => {
            let why = match cause {
                Removal::Script => "destroyed by the script".to_owned(),
                Removal::HitBy(by) => format!("hit by {}", body(*by)),
                Removal::LeftWorld => "left the world".to_owned(),
                Removal::Expired => "expired".to_owned(),
            };
            format!("{} {why}", body(*e))
        }
        GameEvent::Crushed { body: e, by, axis } => format!(
            "{} crushed by {}: no room to be pushed out along {}",
            body(*e),
            body(*by),
            if *axis == 0 { "x" } else { "y" },
        ),
        GameEvent::TouchBegin { a, b, depth, .. } => {
            // Shortest round-trip digits, scientific below 1e-5: a landing's depth of
            // 1.6e-14 is not written as fifteen zeros.
            format!(
                "{} touches {}, depth {}",
                body(*a),
                body(*b),
                Number(*depth)
            )
        }
        GameEvent::TouchEnd { a, b } => {
            format!("{} no longer touches {}", body(*a), body(*b))
        }
    }
}

/// One event as a log line, names looked up in `world` (the end of the frame) and `out`.
pub fn line(event: &GameEvent, world: &World, out: &FrameOutput) -> EventLine {
    let kind = kind(event);
    let level = match kind {
        "destroy" | "expire" | "missed" | "crush" => LogLevel::Warning,
        _ => LogLevel::Info,
    };
    EventLine {
        kind,
        level,
        message: message(event, world, out),
    }
}

/// Bodies a click's line lists at most (about 400 bytes each); the rest are counted.
pub const MAX_CLICK_BODIES: usize = 16;

/// `[x, y]` with [`Number`]'s digits.
fn pair(v: Vec2) -> String {
    format!("[{}, {}]", Number(v.x), Number(v.y))
}

/// A body's whole state, after its `name #id`: what a step reads of it, as `/bodies` and
/// the reads by entity give it (its `user_data` is the game's and never written).
fn state(sim: &Simulation, e: Entity) -> Option<String> {
    let layer = sim.scenario().world.layers.name(sim.layer(e)?);
    let shape = serde_json::to_string(&ShapeDef::from_shape(sim.shape(e)?)).ok()?;
    let yes = |b: bool| if b { "yes" } else { "no" };
    let mut s = format!(
        "layer {layer}, {}, shape {shape}, position {}, angle {}, velocity {}, angular velocity {}",
        sim.kind(e)?.name(),
        pair(sim.position(e)?),
        Number(sim.angle(e)?),
        pair(sim.velocity(e)?),
        Number(sim.angular_velocity(e)?),
    );
    if sim.kind(e)? == BodyKind::Dynamic {
        s += &format!(", mass {}", Number(sim.mass(e)?));
    }
    s += &format!(
        ", force {}, gravity scale {}, lifetime {}",
        pair(sim.force(e)?),
        Number(sim.gravity_scale(e)?),
        sim.lifetime(e)?
            .map_or("unlimited".to_owned(), |f| format!("{f} frames")),
    );
    if let Some(c) = sim.controller(e)? {
        let i = sim.inputs(e)?;
        s += &match c {
            Controller::Ship { .. } => format!(
                ", ship: thrust {}, turn {}",
                if i.thrust { "on" } else { "off" },
                Number(i.turn)
            ),
            Controller::Runner { .. } => format!(", runner: move {}", Number(i.run)),
            Controller::Walker { .. } => ", walker".to_owned(),
        };
    }
    let carrier = sim.carrier(e)?.map_or("nothing".to_owned(), |c| {
        format!("{} #{c}", sim.name(c).unwrap_or("?"))
    });
    s += &format!(
        ", grounded {}, on static {}, carried by {carrier}, asleep {}, frozen {}",
        yes(sim.grounded(e)?),
        yes(sim.on_static(e)?),
        yes(sim.asleep(e)?),
        yes(sim.frozen(e)?),
    );
    Some(s)
}

/// The line answering a click at `point` (world coordinates; `ricochet serve`, live only)
/// that found `bodies` there: each with its whole state, at most [`MAX_CLICK_BODIES`].
pub fn click(sim: &Simulation, point: Vec2, bodies: &[Entity]) -> EventLine {
    let mut message = format!("click at {}: ", pair(point));
    if bodies.is_empty() {
        message += "no body there";
    } else {
        let listed: Vec<String> = bodies
            .iter()
            .take(MAX_CLICK_BODIES)
            .map(|&e| {
                let name = sim.name(e).unwrap_or("?");
                let state = state(sim, e).unwrap_or_default();
                format!("{name} #{e} ({state})")
            })
            .collect();
        message += &listed.join("; ");
        if bodies.len() > MAX_CLICK_BODIES {
            message += &format!("; and {} more", bodies.len() - MAX_CLICK_BODIES);
        }
    }
    EventLine {
        kind: "click",
        level: LogLevel::Info,
        message,
    }
}

#[cfg(test)]
mod tests {
    use ricochet_sim::{Simulation, load_scenario};

    use super::*;

    /// Frame 1 destroys `old` (slot 0) and spawns `new`, which takes slot 0 again: the text
    /// names the removed body from the frame's removed list, the new one from the world,
    /// each with its generation. `old` overlapped `wall` from frame 0 on (the circles'
    /// centres 0.75 apart, radii 0.5: depth 0.25), so their touch begins at frame 0 and ends
    /// with the destroy, after it.
    #[test]
    fn a_reused_slot_is_worded_with_each_bodys_generation() {
        let text = r#"
layers = ["thing"]
collide = [{ a = "thing", b = "thing", response = "report" }]
bodies = [
    { name = "old", template = "thing", position = [0, 0] },
    { name = "wall", template = "thing", kind = "static", position = [0.75, 0] },
]
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
        let lines = |sim: &Simulation, out: &FrameOutput| -> Vec<(&str, LogLevel, String)> {
            out.events
                .iter()
                .map(|e| {
                    let l = line(e, sim.world(), out);
                    (l.kind, l.level, l.message)
                })
                .collect()
        };
        let out = sim.step();
        assert_eq!(
            lines(&sim, &out),
            [(
                "touch_begin",
                LogLevel::Info,
                "old #0:0 touches wall #1:0, depth 0.25".to_owned()
            )]
        );
        let out = sim.step();
        assert_eq!(
            lines(&sim, &out),
            [
                (
                    "destroy",
                    LogLevel::Warning,
                    "old #0:0 destroyed by the script".to_owned()
                ),
                (
                    "spawn",
                    LogLevel::Info,
                    "new #0:1 spawned from template thing".to_owned()
                ),
                (
                    "missed",
                    LogLevel::Warning,
                    "set_velocity: no body named old is alive".to_owned()
                ),
                (
                    "touch_end",
                    LogLevel::Info,
                    "old #0:0 no longer touches wall #1:0".to_owned()
                ),
            ]
        );
    }

    /// A lift climbing into a ceiling with a box on it: the crush is a warning naming the box
    /// and the lift, and the pass it was found in. The box stands flush on the lift at frame
    /// 0 (no record: no touch yet); at frame 1 gravity and the lift press them together, the
    /// pass pushes the box up, and their touch begins, at level info like every touch.
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
        assert!(sim.step().events.is_empty(), "frame 0: flush, no record");
        let out = sim.step();
        let begin = line(&out.events[0], sim.world(), &out);
        assert_eq!((begin.kind, begin.level), ("touch_begin", LogLevel::Info));
        assert!(
            begin
                .message
                .starts_with("lift #0:0 touches box #2:0, depth "),
            "{}",
            begin.message
        );
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
