//! The scenario file as written (TOML, `deny_unknown_fields`): plain serde structs, checked
//! later by [`crate::scenario`]. Every field, unit and default is documented in
//! `scenarios/README.md`; keep the two in step.

use std::collections::BTreeMap;

use ricochet_geom::ShapeDef;

use crate::Action;
use serde::Deserialize;
use toml::Spanned;

/// The whole file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScenarioFile {
    /// A name for logs and summaries (default: the file name).
    pub name: Option<String>,
    /// Steps per second. Give `hz` or `dt`, not both (default: 60 Hz).
    pub hz: Option<Spanned<f64>>,
    /// Seconds per step.
    pub dt: Option<Spanned<f64>>,
    /// How many steps `ricochet run` takes by default (default 600).
    pub frames: Option<Spanned<i64>>,
    /// World settings.
    #[serde(default)]
    pub world: WorldFile,
    /// Layer names, in order; a body's `layer` must be one of them.
    pub layers: Spanned<Vec<Spanned<String>>>,
    /// Layers whose bodies move further than their own size in a frame (bullets): their
    /// pairs are swept (time of impact) unless a `[[collide]]` entry says `sweep = false`.
    #[serde(default)]
    pub fast_layers: Vec<Spanned<String>>,
    /// Which layer pairs interact and how. Unlisted pairs are ignored.
    #[serde(default)]
    pub collide: Vec<Spanned<CollideFile>>,
    /// Named body prototypes, used by bodies, `spawn` events, `fire` and `split`.
    #[serde(default)]
    pub templates: BTreeMap<String, Spanned<BodyFile>>,
    /// The bodies present at frame 0.
    #[serde(default)]
    pub bodies: Vec<Spanned<BodyFile>>,
    /// Timed inputs and events.
    #[serde(default)]
    pub script: Vec<Spanned<EventFile>>,
    /// A level from a Tiled map (read by `ricochet-tiled`, not here: this crate does no I/O).
    pub tiled: Option<Spanned<TiledFile>>,
}

/// `[tiled]`: which map, and which of its layers become what.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TiledFile {
    /// The map file (`.tmx`, `.tmj` or Tiled `.json`), relative to the scenario file.
    pub map: Spanned<String>,
    /// World units per tile width, > 0 (default 1).
    pub units_per_tile: Option<Spanned<f64>>,
    /// Map layers (`LAYER`, `LAYER?PROP`, `LAYER?PROP=VALUE`) whose shapes are static solids.
    #[serde(default)]
    pub solid: Vec<Spanned<String>>,
    /// Map layers whose shapes are one-way platforms.
    #[serde(default)]
    pub one_way: Vec<Spanned<String>>,
    /// The scenario layer the one-way pieces go to: the platform layer of a `one_way`
    /// `[[collide]]` pair (needed when `one_way` lists something).
    pub one_way_layer: Option<Spanned<String>>,
    /// The scenario layer the map's static bodies go to.
    pub layer: Spanned<String>,
    /// Object class, type or name → the template spawned at the object's centre.
    #[serde(default)]
    pub spawn: BTreeMap<String, Spanned<String>>,
}

/// One `[[bodies]]` table parsed on its own (see `chunks.rs`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyTable {
    /// The one body of the table.
    pub bodies: Vec<Spanned<BodyFile>>,
}

/// `[world]`.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WorldFile {
    /// Acceleration applied to every dynamic body times its `gravity_scale`, units/s².
    pub gravity: Option<Spanned<[f64; 2]>>,
    /// World bounds.
    pub bounds: Option<Spanned<BoundsFile>>,
    /// `auto` (default), `brute-force`, `sort-and-sweep` or `grid`.
    pub broad_phase: Option<Spanned<String>>,
    /// Frames at rest on static geometry before a dynamic body sleeps, >= 1 (default:
    /// nothing sleeps).
    pub sleep_after: Option<Spanned<i64>>,
    /// The steepest slope a runner or walker climbs, degrees, 0 to < 90 (default 45).
    pub max_climb_angle: Option<Spanned<f64>>,
    /// Moving bodies outside a box around a focus body are frozen (default: none).
    pub active_region: Option<ActiveRegionFile>,
}

/// `[world.active_region]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ActiveRegionFile {
    /// Name of a body in `[[bodies]]`; the region follows the lowest id with that name.
    pub focus: Spanned<String>,
    /// Half the region's width and height, units, > 0.
    pub half_extents: Spanned<[f64; 2]>,
}

/// `[world.bounds]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoundsFile {
    /// Lower-left corner.
    pub min: [f64; 2],
    /// Upper-right corner.
    pub max: [f64; 2],
    /// Whether a body leaving one side comes back on the other (Asteroids).
    #[serde(default)]
    pub wrap: bool,
}

/// One `[[collide]]` entry of the layer-pair matrix.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CollideFile {
    /// First layer.
    pub a: String,
    /// Second layer (may equal `a`).
    pub b: String,
    /// `ignore`, `report`, `destroy` or `separate`.
    pub response: String,
    /// For `destroy`: which body goes, `a`, `b` or `both` (default `both`).
    pub destroy: Option<String>,
    /// Test along the whole frame's motion (time of impact) rather than at its end only
    /// (default: true when either layer is in `fast_layers`).
    pub sweep: Option<bool>,
    /// Track the pair's touches and report their begin and end (`touch_begin`,
    /// `touch_end`; default true). Not on an `ignore` pair, which never touches.
    pub touches: Option<bool>,
}

/// A body or a template. Every field is optional in a template; a body takes its template's
/// values and overrides them.
#[derive(Debug, Default, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyFile {
    /// The template to start from.
    pub template: Option<String>,
    /// Body name (default: the template name, or `body`).
    pub name: Option<String>,
    /// Layer name.
    pub layer: Option<String>,
    /// Collision shape.
    pub shape: Option<ShapeDef>,
    /// `dynamic` (default), `static` or `kinematic`.
    pub kind: Option<String>,
    /// Mass of a dynamic body, > 0 (default 1).
    pub mass: Option<f64>,
    /// Position, units.
    pub position: Option<[f64; 2]>,
    /// Angle, radians counter-clockwise.
    pub angle: Option<f64>,
    /// Velocity, units/s.
    pub velocity: Option<[f64; 2]>,
    /// Angular velocity, radians/s.
    pub angular_velocity: Option<f64>,
    /// Constant force, newtons (mass units · units/s²).
    pub force: Option<[f64; 2]>,
    /// Multiplier of the world gravity (default 1).
    pub gravity_scale: Option<f64>,
    /// Frames until the body is removed (default: never).
    pub lifetime: Option<i64>,
    /// What inputs drive the body.
    pub controller: Option<ControllerFile>,
    /// Bodies spawned where this one is destroyed (asteroid splitting).
    pub split: Option<Vec<SplitFile>>,
}

/// A body's controller.
#[derive(Debug, Clone, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum ControllerFile {
    /// Asteroids ship: `thrust`, `turn` and `fire` inputs.
    Ship {
        /// Thrust force along the heading, newtons.
        thrust: f64,
        /// Turn rate at full input, radians/s.
        turn_rate: f64,
        /// Template fired by `fire`.
        bullet: String,
        /// Bullet speed relative to the ship, units/s.
        bullet_speed: f64,
        /// Distance ahead of the ship centre where bullets appear (default 0).
        #[serde(default)]
        muzzle: f64,
    },
    /// Platformer character: `move` and `jump` inputs.
    Runner {
        /// Horizontal speed at full input, units/s.
        run_speed: f64,
        /// Upward speed given by a jump, units/s.
        jump_speed: f64,
    },
    /// Walks at `speed` and turns around when it bumps into something along x.
    Walker {
        /// Horizontal speed, units/s; the sign is the starting direction.
        speed: f64,
    },
}

/// One child of a split.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SplitFile {
    /// Template of the child.
    pub template: String,
    /// Offset from the parent's position (not rotated), units.
    #[serde(default)]
    pub offset: [f64; 2],
    /// Velocity added to the parent's, units/s.
    #[serde(default)]
    pub velocity: [f64; 2],
}

/// One `[[script]]` entry: something that happens at the start of a frame.
#[derive(Debug)]
pub struct EventFile {
    /// The frame it happens at, ≥ 0.
    pub frame: i64,
    /// What happens.
    pub action: ActionFile,
}

// serde's `flatten` can't be combined with `deny_unknown_fields`, so `frame` is taken out by
// hand and the rest must be exactly one action.
impl<'de> Deserialize<'de> for EventFile {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        let mut table = toml::Table::deserialize(deserializer)?;
        let frame = match table.remove("frame") {
            Some(toml::Value::Integer(f)) => f,
            Some(other) => {
                return Err(D::Error::custom(format!(
                    "`frame` must be a whole number, got {other}"
                )));
            }
            None => return Err(D::Error::missing_field("frame")),
        };
        let action = ActionFile::deserialize(toml::Value::Table(table))
            .map_err(|e| D::Error::custom(e.message().to_owned()))?;
        Ok(EventFile { frame, action })
    }
}

/// What a script event does.
#[derive(Debug, Clone, Deserialize, serde::Serialize)]
#[serde(tag = "action", rename_all = "snake_case", deny_unknown_fields)]
pub enum ActionFile {
    /// Create a body from a template.
    Spawn {
        /// The template.
        template: String,
        /// Name of the new body (default: the template's).
        name: Option<String>,
        /// Position.
        position: [f64; 2],
        /// Velocity (default: the template's).
        velocity: Option<[f64; 2]>,
        /// Angle (default: the template's).
        angle: Option<f64>,
    },
    /// Remove a body by name.
    Destroy {
        /// Body name.
        body: String,
    },
    /// Set a body's velocity.
    SetVelocity {
        /// Body name.
        body: String,
        /// New velocity.
        velocity: [f64; 2],
    },
    /// Add `impulse / mass` to a body's velocity.
    ApplyImpulse {
        /// Body name.
        body: String,
        /// Impulse, mass units · units/s.
        impulse: [f64; 2],
    },
    /// Set a body's constant force.
    SetForce {
        /// Body name.
        body: String,
        /// Force.
        force: [f64; 2],
    },
    /// Ship: engine on or off.
    Thrust {
        /// Body name.
        body: String,
        /// On (default true).
        #[serde(default = "yes")]
        on: bool,
    },
    /// Ship: turn input, -1 (clockwise) to 1 (counter-clockwise).
    Turn {
        /// Body name.
        body: String,
        /// Input.
        input: f64,
    },
    /// Ship: fire one bullet.
    Fire {
        /// Body name.
        body: String,
    },
    /// Runner: horizontal input, -1 to 1.
    Move {
        /// Body name.
        body: String,
        /// Input.
        input: f64,
    },
    /// Runner: jump if grounded.
    Jump {
        /// Body name.
        body: String,
    },
    /// A grounded body drops through the one-way platforms it stands on.
    Drop {
        /// Body name.
        body: String,
    },
}

fn yes() -> bool {
    true
}

impl ActionFile {
    /// The body an action other than `spawn` names, and what it does to it; `None` for
    /// `spawn`. Values are not checked here: see [`Action::out_of_range`].
    #[must_use]
    pub fn body_action(&self) -> Option<(&str, Action)> {
        let v = |a: &[f64; 2]| ricochet_geom::Vec2::new(a[0], a[1]);
        Some(match self {
            ActionFile::Spawn { .. } => return None,
            ActionFile::Destroy { body } => (body, Action::Destroy),
            ActionFile::SetVelocity { body, velocity } => (body, Action::SetVelocity(v(velocity))),
            ActionFile::ApplyImpulse { body, impulse } => (body, Action::ApplyImpulse(v(impulse))),
            ActionFile::SetForce { body, force } => (body, Action::SetForce(v(force))),
            ActionFile::Thrust { body, on } => (body, Action::Thrust(*on)),
            ActionFile::Turn { body, input } => (body, Action::Turn(*input)),
            ActionFile::Fire { body } => (body, Action::Fire),
            ActionFile::Move { body, input } => (body, Action::Move(*input)),
            ActionFile::Jump { body } => (body, Action::Jump),
            ActionFile::Drop { body } => (body, Action::Drop),
        })
    }
}
