//! Inputs: what a game, or a scenario's script, does to a body between two steps.
//!
//! A game sends an [`Action`] to a body by [`crate::Entity`] with
//! [`crate::Simulation::apply`]; a scenario's script names the body instead
//! ([`ScriptAction::Body`]). Either way it takes effect in the `script` stage at the start
//! of the next step: the script's events of that frame first, in file order, then the
//! applied actions in the order they were sent.

use ricochet_geom::Vec2;

use crate::def::BodyDef;

/// An input to one body.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    /// Remove the body (no split).
    Destroy,
    /// Set a moving body's velocity, units/s (a static body ignores it).
    SetVelocity(Vec2),
    /// Add `impulse / mass` to a dynamic body's velocity.
    ApplyImpulse(Vec2),
    /// Set the constant force, newtons.
    SetForce(Vec2),
    /// Ship engine on or off.
    Thrust(bool),
    /// Ship turn input, -1 (clockwise) to 1 (counter-clockwise).
    Turn(f64),
    /// A ship fires its bullet template.
    Fire,
    /// Runner horizontal input, -1 to 1.
    Move(f64),
    /// A runner jumps if it is grounded.
    Jump,
    /// A grounded dynamic body drops through the one-way platforms it stands on
    /// (`stages/one_way.rs`).
    Drop,
}

impl Action {
    /// The action's name as written in scenario files.
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            Action::Destroy => "destroy",
            Action::SetVelocity(_) => "set_velocity",
            Action::ApplyImpulse(_) => "apply_impulse",
            Action::SetForce(_) => "set_force",
            Action::Thrust(_) => "thrust",
            Action::Turn(_) => "turn",
            Action::Fire => "fire",
            Action::Move(_) => "move",
            Action::Jump => "jump",
            Action::Drop => "drop",
        }
    }

    /// The field a value out of range would be reported under, if any: vectors must be
    /// finite, and turn and move inputs within -1 to 1.
    #[must_use]
    pub fn out_of_range(&self) -> Option<&'static str> {
        match self {
            Action::SetVelocity(v) if !v.is_finite() => Some("velocity"),
            Action::ApplyImpulse(v) if !v.is_finite() => Some("impulse"),
            Action::SetForce(v) if !v.is_finite() => Some("force"),
            Action::Turn(x) | Action::Move(x) if !(x.is_finite() && (-1.0..=1.0).contains(x)) => {
                Some("input")
            }
            _ => None,
        }
    }
}

/// What a script event does.
#[derive(Clone, Debug, PartialEq)]
pub enum ScriptAction {
    /// Create a body from a template.
    Spawn {
        /// The body to create (template values with the event's overrides).
        body: Box<BodyDef>,
        /// Template name, for the event log.
        template: String,
    },
    /// An input to the live body with this name and the lowest id.
    Body {
        /// Body name.
        name: String,
        /// What it gets.
        action: Action,
    },
}

impl ScriptAction {
    /// The action's name as written in scenario files.
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            ScriptAction::Spawn { .. } => "spawn",
            ScriptAction::Body { action, .. } => action.name(),
        }
    }
}

/// A script event.
#[derive(Clone, Debug, PartialEq)]
pub struct Event {
    /// The frame at whose start it happens.
    pub frame: u64,
    /// What happens.
    pub action: ScriptAction,
}
