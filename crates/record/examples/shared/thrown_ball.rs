//! The level of `record_game.rs`, built in code: a ball thrown under gravity past a rock.
//! Shared with `tests/golden.rs`, which checks it against its golden log.

use ricochet_sim::{Action, BodyDef, Event, Scenario, ScriptAction, Shape, Vec2, WorldDef};

/// Gravity, units/s² (down).
pub const GRAVITY: f64 = -10.0;
/// The throw: from the origin, units/s.
pub const THROW: Vec2 = Vec2::new(3.0, 12.0);
/// At the start of this frame the game kicks the ball: its velocity becomes [`KICK`].
pub const KICK_FRAME: u64 = 60;
/// The kick's velocity, units/s.
pub const KICK: Vec2 = Vec2::new(3.0, 8.0);
/// Frames after frame 0.
pub const FRAMES: u64 = 120;

/// The game's level, built in code: a thrown ball, kicked at [`KICK_FRAME`], and a rock it
/// flies past.
pub fn level() -> Result<Scenario, Box<dyn std::error::Error>> {
    Ok(Scenario {
        name: "thrown ball".into(),
        world: WorldDef {
            gravity: Vec2::new(0.0, GRAVITY),
            ..WorldDef::default()
        },
        frames: FRAMES,
        bodies: vec![
            BodyDef {
                name: "ball".into(),
                shape: Shape::circle(0.5)?,
                velocity: THROW,
                ..BodyDef::default()
            },
            BodyDef {
                name: "rock".into(),
                shape: Shape::circle(1.0)?,
                position: Vec2::new(40.0, 0.0),
                gravity_scale: 0.0,
                ..BodyDef::default()
            },
        ],
        script: vec![kick(KICK)],
        ..Scenario::default()
    })
}

/// The kick at [`KICK_FRAME`]: the ball's velocity set to `velocity`.
pub fn kick(velocity: Vec2) -> Event {
    Event {
        frame: KICK_FRAME,
        action: ScriptAction::Body {
            name: "ball".into(),
            action: Action::SetVelocity(velocity),
        },
    }
}
