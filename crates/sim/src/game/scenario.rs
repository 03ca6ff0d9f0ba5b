//! The scenario's game: what `ricochet run` and `ricochet serve` run. Its rules are the
//! scenario's script, which runs inside the step; its inputs are the script's actions in
//! JSON, addressed by body name (`{"action": "thrust", "body": "ship", "on": true}`), and
//! it has no players.
//!
//! Inputs are checked as strictly as a scenario file's values: every vector (a velocity, an
//! impulse, a force, a spawn's position and velocity) finite and within ±1e15
//! ([`MAX_INPUT_VALUE`]), and an impulse or a force refused when the velocity it makes (in
//! one frame, for a force) would be beyond that.

use ricochet_geom::Vec2;

use super::{Game, Player};
use crate::action::Action;
use crate::def::BodyKind;
use crate::entity::Entity;
use crate::load::file::ActionFile;
use crate::pipeline::Simulation;

/// The largest velocity an input may set or make, units/s, and the largest vector it may
/// carry: the coordinates Ricochet accepts (a scenario file's ±1e15).
pub const MAX_INPUT_VALUE: f64 = ricochet_geom::MAX_COORDINATE;

/// The game every scenario file is: its script, and its actions as inputs.
#[derive(Debug, Clone, Copy, Default)]
pub struct ScenarioGame;

impl ScenarioGame {
    /// Its name in a recording.
    pub const NAME: &'static str = "scenario";
}

impl Game for ScenarioGame {
    type Input = ActionFile;
    type State = ();

    fn name(&self) -> &str {
        Self::NAME
    }

    fn has_players(&self) -> bool {
        false
    }

    fn input(&mut self, sim: &mut Simulation, _: Player, input: ActionFile) -> Result<(), String> {
        if let ActionFile::Spawn {
            template,
            name,
            position,
            velocity,
            angle,
        } = &input
        {
            return spawn(sim, template, name.as_deref(), *position, *velocity, *angle);
        }
        let Some((body, action)) = input.body_action() else {
            return Err("an action that names no body".to_owned());
        };
        if let Some(field) = action.out_of_range() {
            return Err(format!("{}: {field} out of range", action.name()));
        }
        if let Action::SetVelocity(v) | Action::ApplyImpulse(v) | Action::SetForce(v) = action
            && !within(v)
        {
            return Err(format!(
                "{}: {} beyond ±{MAX_INPUT_VALUE:e}",
                action.name(),
                vector(v)
            ));
        }
        let e = sim
            .entity_named(body)
            .ok_or_else(|| format!("no body named {body:?}"))?;
        check_velocity(sim, e, &action)?;
        sim.apply(e, action).map_err(|e| e.to_string())
    }
}

/// Refuses an impulse, or a force, that would make a dynamic body's velocity (after one
/// frame, for a force) non-finite or beyond ±[`MAX_INPUT_VALUE`]: a tiny mass turns a
/// bounded impulse into any speed.
fn check_velocity(sim: &Simulation, e: Entity, action: &Action) -> Result<(), String> {
    let w = sim.world();
    let Some(i) = w.index_of(e) else {
        return Ok(());
    };
    if w.kind[i] != BodyKind::Dynamic {
        return Ok(());
    }
    let v = w.velocity(i);
    let made = match action {
        Action::ApplyImpulse(j) => v + *j / w.mass(i),
        Action::SetForce(f) => v + *f / w.mass(i) * sim.dt(),
        _ => return Ok(()),
    };
    if within(made) {
        Ok(())
    } else {
        Err(format!(
            "{}: it would make {:?}'s velocity {}, beyond ±{MAX_INPUT_VALUE:e}",
            action.name(),
            w.name(i),
            vector(made)
        ))
    }
}

/// A body from the scenario's template `template`, as the script's `spawn` makes one; it
/// is in the world for the next step.
fn spawn(
    sim: &mut Simulation,
    template: &str,
    name: Option<&str>,
    position: [f64; 2],
    velocity: Option<[f64; 2]>,
    angle: Option<f64>,
) -> Result<(), String> {
    let Some(base) = sim.scenario().templates.get(template) else {
        let known: Vec<&String> = sim.scenario().templates.keys().collect();
        return Err(format!(
            "no template {template:?} (the scenario has {known:?})"
        ));
    };
    let mut def = base.clone();
    if let Some(n) = name {
        def.name = n.to_owned();
    }
    let ok = |v: [f64; 2]| within(Vec2::new(v[0], v[1]));
    if !ok(position) || !velocity.is_none_or(ok) || !angle.is_none_or(f64::is_finite) {
        return Err(format!(
            "spawn: position and velocity must be finite and within ±{MAX_INPUT_VALUE:e}, \
             the angle finite"
        ));
    }
    def.position = Vec2::new(position[0], position[1]);
    if let Some(v) = velocity {
        if def.kind == BodyKind::Static {
            return Err(format!(
                "spawn: template {template:?} is static: it can't move"
            ));
        }
        def.velocity = Vec2::new(v[0], v[1]);
    }
    if let Some(a) = angle {
        def.angle = a;
    }
    sim.spawn(&def);
    Ok(())
}

/// Whether `v` is finite and within ±[`MAX_INPUT_VALUE`] on both axes.
fn within(v: Vec2) -> bool {
    v.is_finite() && v.abs().max_element() <= MAX_INPUT_VALUE
}

/// `[x, y]` in a short form that reads back the same (`1.7e308`, not 309 digits).
fn vector(v: Vec2) -> String {
    let number = |x: f64| {
        if x != 0.0 && x.is_finite() && !(1e-4..1e6).contains(&x.abs()) {
            format!("{x:e}")
        } else {
            format!("{x:?}")
        }
    };
    format!("[{}, {}]", number(v.x), number(v.y))
}
