//! What happened in a frame, as data: the game events the stages raise. The simulation never
//! formats them; the recorder turns each into a line of text for the log.
//!
//! Every body is named by its [`Entity`] (index and generation). A body alive at the end of
//! the frame is found with [`crate::World::index_of`]; one removed during the frame is in
//! [`crate::FrameOutput::removed`].

use ricochet_geom::Vec2;

use crate::def::LayerId;
use crate::entity::Entity;

/// One game event, in the order it happened within its frame.
#[derive(Clone, Debug, PartialEq)]
pub enum GameEvent {
    /// A script event set an input or edited a body's motion.
    Input {
        /// The body the script named.
        body: Entity,
        /// What the script did to it.
        input: ScriptInput,
    },
    /// A script event named a body that is not alive; nothing happened.
    Missed {
        /// The action's name in the scenario file (`destroy`, `fire`, ...).
        action: &'static str,
        /// The body name the event gave.
        name: String,
    },
    /// An action sent with [`crate::Simulation::apply`] found its body gone by the step;
    /// nothing happened.
    Gone {
        /// The action's name (`fire`, `thrust`, ...).
        action: &'static str,
        /// The body it was sent to.
        body: Entity,
    },
    /// A script event spawned a body from a template.
    Spawned {
        /// The new body.
        body: Entity,
        /// The template's name.
        template: String,
    },
    /// A ship fired: its bullet template spawned ahead of it.
    Fired {
        /// The new bullet.
        bullet: Entity,
        /// The ship that fired it.
        ship: Entity,
    },
    /// A destroyed body's split child spawned where the body was.
    SplitFrom {
        /// The new body.
        child: Entity,
        /// The body it split from (removed this frame).
        parent: Entity,
    },
    /// A body was removed.
    Removed {
        /// The body (in [`crate::FrameOutput::removed`], with its last state).
        body: Entity,
        /// Its layer: what tells a rock from a bullet without a look in `removed`.
        layer: LayerId,
        /// Why.
        cause: Removal,
    },
    /// A box that a kinematic body pushed or carried this frame still overlaps a static or
    /// kinematic box after its per-axis pass: it was pushed into a wall (or ceiling, or
    /// floor) with no room to go. The engine leaves it where the pushes put it, overlapping;
    /// the game decides (remove it, take a life, stop the lift).
    Crushed {
        /// The box.
        body: Entity,
        /// The kinematic body that pushed it, or the one it rode (at the bottom of its chain
        /// of carriers).
        by: Entity,
        /// The pass that found it: `0` for `resolve_x`, `1` for `resolve_y`.
        axis: u8,
    },
    /// Two bodies began to touch: the pair has a contact record this frame and did not touch
    /// at the end of the last one (the `touch` stage, `docs/touches.md`). Raised after every
    /// other event of the frame, begins in pair order before ends.
    TouchBegin {
        /// The body with the lower id.
        a: Entity,
        /// The body with the higher id.
        b: Entity,
        /// The normal of the pair's first contact record of the frame (detection order),
        /// from `a` to `b`.
        normal: Vec2,
        /// Its penetration depth.
        depth: f64,
        /// Its contact point.
        point: Vec2,
    },
    /// Two bodies that touched at the end of the last frame no longer do: no contact record
    /// this frame and apart by more than [`crate::SLOP`] (unless both are at rest), or a
    /// body removed this frame. After every begin of the frame, in pair order.
    TouchEnd {
        /// The body with the lower id.
        a: Entity,
        /// The body with the higher id.
        b: Entity,
    },
}

/// What a script event did to a body it found.
#[derive(Clone, Debug, PartialEq)]
pub enum ScriptInput {
    /// `set_velocity` (ignored by static bodies).
    Velocity(Vec2),
    /// `apply_impulse` (only dynamic bodies respond).
    Impulse(Vec2),
    /// `set_force`.
    Force(Vec2),
    /// `thrust`: the engine on or off.
    Thrust(bool),
    /// `turn`, the input from -1 to 1.
    Turn(f64),
    /// `move`, the input from -1 to 1.
    Move(f64),
    /// `jump`, and whether it happened.
    Jump(JumpOutcome),
    /// `fire`, and whether it happened.
    Fire(FireOutcome),
    /// `drop`: whether the body was grounded (and now drops through the one-way platforms
    /// it stands on) or ignored it.
    Drop(bool),
}

/// The outcome of a `jump` input.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JumpOutcome {
    /// The runner jumped.
    Jumped,
    /// Ignored: the runner was in the air.
    NotGrounded,
    /// Ignored: the body has no runner controller.
    NotARunner,
}

/// The outcome of a `fire` input.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum FireOutcome {
    /// A bullet was spawned (the [`GameEvent::Fired`] just before this input says which).
    Fired,
    /// Ignored: the body has no ship controller.
    NotAShip,
    /// Ignored: the ship's bullet template does not exist; its name.
    NoTemplate(String),
}

/// Why a body was removed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Removal {
    /// A `destroy` script event.
    Script,
    /// A `destroy` response: hit by this body.
    HitBy(Entity),
    /// It left the world bounds.
    LeftWorld,
    /// Its lifetime ran out.
    Expired,
}
