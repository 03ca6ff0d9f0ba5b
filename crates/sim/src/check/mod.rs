//! Checking a scene built in code as the loader checks a scenario file
//! ([`Scenario::check`], [`Simulation::try_new`], [`Simulation::try_spawn`]): the same
//! limits, the same words, an error naming the field (`script[3].body`) where a file's
//! names its `file:line:column` too.

pub(crate) mod problems;

use ricochet_geom::{Number, Numbers, Vec2};

use crate::action::{Action, ScriptAction};
use crate::def::{BodyDef, BodyKind, LayerId, MAX_FRAMES, WorldDef};
use crate::entity::Entity;
use crate::pipeline::Simulation;
use crate::scenario::Scenario;
use problems::{
    beyond_world, controller_problem, mass_problem, names_sorted, no_such_name, oversized,
    shared_name, split_problem, static_outside, unknown_problem,
};

/// Why a scenario was rejected: by the loader (`file:line:column: field: problem`) or by
/// [`Scenario::check`] (`name: field: problem`, `line` and `column` 0: a scene built in code
/// has no text to point into, its field path says where).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{}{field}{sep}{problem}", located(self), sep = if self.field.is_empty() { "" } else { ": " })]
pub struct ScenarioError {
    /// The file name as given, or the name of a scenario built in code.
    pub file: String,
    /// 1-based line; 0 for a scenario built in code.
    pub line: usize,
    /// 1-based column; 0 for a scenario built in code.
    pub column: usize,
    /// The field path (`bodies[2].layer`), empty for a syntax error.
    pub field: String,
    /// What is wrong and what was expected.
    pub problem: String,
}

fn located(e: &ScenarioError) -> String {
    if e.line == 0 {
        format!("{}: ", e.file)
    } else {
        format!("{}:{}:{}: ", e.file, e.line, e.column)
    }
}

/// Builds the errors of one scenario built in code.
struct At<'a>(&'a str);

impl At<'_> {
    fn err(&self, field: impl Into<String>, problem: impl Into<String>) -> ScenarioError {
        ScenarioError {
            file: self.0.to_owned(),
            line: 0,
            column: 0,
            field: field.into(),
            problem: problem.into(),
        }
    }
}

fn finite(at: &At<'_>, field: String, v: f64) -> Result<(), ScenarioError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(at.err(field, format!("must be a finite number, got {}", Number(v))))
    }
}

fn finite2(at: &At<'_>, field: String, v: Vec2) -> Result<(), ScenarioError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(at.err(
            field,
            format!("must be finite numbers, got {}", Numbers([v.x, v.y])),
        ))
    }
}

/// What the loader checks of the world settings, and of the run's length.
fn check_world(at: &At<'_>, world: &WorldDef, frames: u64) -> Result<(), ScenarioError> {
    if !(world.dt.is_finite() && world.dt > 0.0) {
        return Err(at.err(
            "dt",
            format!(
                "must be a finite number of seconds > 0, got {}",
                Number(world.dt)
            ),
        ));
    }
    if frames > MAX_FRAMES {
        return Err(at.err("frames", format!("must be 0 to {MAX_FRAMES}, got {frames}")));
    }
    if let Err(e) = world.last_time_ns(frames) {
        let field = match e {
            crate::RunLengthError::TooLong { .. } => "frames",
            _ => "dt",
        };
        return Err(at.err(field, e.to_string()));
    }
    let names = world.layers.names();
    if names.is_empty() || names.len() > usize::from(LayerId::MAX) {
        return Err(at.err("layers", "list 1 to 255 layer names"));
    }
    for (i, n) in names.iter().enumerate() {
        if names[..i].contains(n) {
            return Err(at.err(
                format!("layers[{i}]"),
                format!("layer \"{n}\" is listed twice"),
            ));
        }
    }
    if !world.gravity.is_finite() {
        return Err(at.err("world.gravity", "must be finite numbers"));
    }
    if let Some(b) = &world.bounds
        && !(b.min.is_finite() && b.max.is_finite() && b.min.x < b.max.x && b.min.y < b.max.y)
    {
        return Err(at.err(
            "world.bounds",
            "min and max must be finite with min < max on both axes",
        ));
    }
    if world.sleep_after == Some(0) {
        return Err(at.err(
            "world.sleep_after",
            format!(
                "must be a whole number of frames from 1 to {}, got 0",
                u32::MAX
            ),
        ));
    }
    if !crate::limits::climb_angle_ok(world.max_climb_angle) {
        return Err(at.err(
            "world.max_climb_angle",
            crate::limits::climb_angle_problem(world.max_climb_angle),
        ));
    }
    if let Some(r) = &world.active_region {
        let h = r.half_extents;
        if !(h.is_finite() && h.min_element() > 0.0) {
            return Err(at.err(
                "world.active_region.half_extents",
                format!(
                    "must be finite numbers > 0 on both axes, got {}",
                    Numbers([h.x, h.y])
                ),
            ));
        }
    }
    Ok(())
}

/// What the loader checks of a body's (or a template's) values, at `field`: its layer,
/// every number finite, its position within the coordinates Ricochet accepts, its mass,
/// lifetime and controller within the loader's limits, the templates its bullets and
/// splits name, and its size and place in a wrapping world.
fn check_body(
    at: &At<'_>,
    scenario: &Scenario,
    def: &BodyDef,
    field: &str,
) -> Result<(), ScenarioError> {
    let world = &scenario.world;
    let f = |name: &str| format!("{field}.{name}");
    let names = world.layers.names();
    if usize::from(def.layer) >= names.len() {
        return Err(at.err(
            f("layer"),
            format!(
                "layer id {} is not one of the {} layers ({})",
                def.layer,
                names.len(),
                names.join(", ")
            ),
        ));
    }
    finite2(at, f("position"), def.position)?;
    if let Some(problem) = beyond_world([def.position.x, def.position.y]) {
        return Err(at.err(f("position"), problem));
    }
    finite(at, f("angle"), def.angle)?;
    if def.shape.is_chain() && def.kind != crate::BodyKind::Static {
        return Err(at.err(
            f("kind"),
            "a chain is static terrain: only a static body may have a chain shape",
        ));
    }
    finite2(at, f("velocity"), def.velocity)?;
    finite(at, f("angular_velocity"), def.angular_velocity)?;
    finite2(at, f("force"), def.force)?;
    finite(at, f("gravity_scale"), def.gravity_scale)?;
    if let Some(problem) = mass_problem(def.mass) {
        return Err(at.err(f("mass"), problem));
    }
    if def.lifetime == Some(0) {
        return Err(at.err(
            f("lifetime"),
            format!(
                "must be a whole number of frames from 1 to {}, got 0",
                u32::MAX
            ),
        ));
    }
    if let Some((name, problem)) = def.controller.as_ref().and_then(controller_problem) {
        return Err(at.err(f(&name), problem));
    }
    if let Some(crate::Controller::Ship { bullet, .. }) = &def.controller {
        match scenario.templates.get(bullet) {
            None => {
                return Err(at.err(
                    f("controller.bullet"),
                    unknown_problem("template", bullet, scenario.templates.keys()),
                ));
            }
            Some(t) if t.kind == BodyKind::Static => {
                return Err(at.err(
                    f("controller.bullet"),
                    format!(
                        "template \"{bullet}\" is static: a static bullet never moves, so \
                         its velocity (the ship's plus bullet_speed) would be dropped: give \
                         the template `kind = \"dynamic\"` (or \"kinematic\")"
                    ),
                ));
            }
            Some(_) => {}
        }
    }
    for (i, s) in def.split.iter().enumerate() {
        finite2(at, f(&format!("split[{i}].offset")), s.offset)?;
        finite2(at, f(&format!("split[{i}].velocity")), s.velocity)?;
        let Some(t) = scenario.templates.get(&s.template) else {
            return Err(at.err(
                f(&format!("split[{i}].template")),
                unknown_problem("template", &s.template, scenario.templates.keys()),
            ));
        };
        let static_parent = def.kind == BodyKind::Static;
        if t.kind == BodyKind::Static && (!static_parent || s.velocity != Vec2::ZERO) {
            return Err(at.err(
                f(&format!("split[{i}].template")),
                format!(
                    "template \"{}\" is static: a static child never moves, so its velocity \
                     (the parent's plus the split's) would be dropped: give the template \
                     `kind = \"dynamic\"` (or \"kinematic\")",
                    s.template
                ),
            ));
        }
    }
    if let Some(problem) = oversized(world, def) {
        return Err(at.err(f("shape"), problem));
    }
    if let Some(problem) = static_outside(world, def) {
        return Err(at.err(f("position"), problem));
    }
    Ok(())
}

/// What the loader checks of a script event's values (finite, within the coordinates
/// Ricochet accepts, inputs from -1 to 1).
fn check_action(at: &At<'_>, field: &str, action: &Action) -> Result<(), ScenarioError> {
    let (name, v) = match action {
        Action::SetVelocity(v) => ("velocity", *v),
        Action::ApplyImpulse(v) => ("impulse", *v),
        Action::SetForce(v) => ("force", *v),
        Action::Turn(x) | Action::Move(x) => {
            if x.is_finite() && (-1.0..=1.0).contains(x) {
                return Ok(());
            }
            return Err(at.err(
                format!("{field}.input"),
                format!("must be between -1 and 1, got {}", Number(*x)),
            ));
        }
        _ => return Ok(()),
    };
    if !v.is_finite() {
        return Err(at.err(format!("{field}.{name}"), "must be finite numbers"));
    }
    if v.abs().max_element() > ricochet_geom::MAX_COORDINATE {
        return Err(at.err(
            format!("{field}.{name}"),
            format!(
                "{} is beyond ±{:e}, the largest value Ricochet accepts",
                Numbers([v.x, v.y]),
                ricochet_geom::MAX_COORDINATE
            ),
        ));
    }
    Ok(())
}

impl Scenario {
    /// Checks a scenario built in code as [`crate::load_scenario`] checks a file, with its
    /// limits and its words: the world settings and run length ([`MAX_FRAMES`], a timestep
    /// a log can hold), the layers, every template, tile row and body (layer, finite values,
    /// [`crate::MIN_MASS`] to [`crate::MAX_MASS`], [`crate::MAX_CONTROLLER_VALUE`], the
    /// templates bullets and splits name, split chains that end, sizes in a wrapping
    /// world), the active region's focus, and every script event (its frame within
    /// `frames`, the body, template or spawn it names, its values). What a definition built
    /// in code cannot say (that a field was written for a kind of body that ignores it) is
    /// not checked. The script need not be sorted: a [`Simulation`] sorts it.
    ///
    /// # Errors
    /// The first problem, as `name: field: problem` (the field path as in a file:
    /// `script[3].body`, `bodies[2].mass`, `templates.bullet.controller.thrust`).
    pub fn check(&self) -> Result<(), ScenarioError> {
        let at = At(&self.name);
        check_world(&at, &self.world, self.frames)?;
        for (name, t) in &self.templates {
            check_body(&at, self, t, &format!("templates.{name}"))?;
        }
        if let Some((name, problem)) = split_problem(&self.templates) {
            return Err(at.err(format!("templates.{name}.split"), problem));
        }
        for (i, rows) in self.tiles.iter().enumerate() {
            let field = format!("tiles[{i}]");
            if !rows.step.is_finite() {
                return Err(at.err(format!("{field}.step"), "must be finite numbers"));
            }
            // Only a row's two ends: a row is a straight line, so its other tiles lie
            // between them (and in a wrapping world inside it when both ends are).
            for (r, &(start, count)) in rows.rows.iter().enumerate() {
                let last = start + rows.step * f64::from(count.saturating_sub(1));
                for p in [start, last] {
                    let def = BodyDef {
                        name: rows.name.clone(),
                        layer: rows.layer,
                        kind: BodyKind::Static,
                        shape: rows.shape.clone(),
                        position: p,
                        ..BodyDef::default()
                    };
                    check_body(&at, self, &def, &format!("{field}.rows[{r}]"))?;
                }
            }
        }
        for (i, b) in self.bodies.iter().enumerate() {
            check_body(&at, self, b, &format!("bodies[{i}]"))?;
        }
        if let Some(r) = &self.world.active_region
            && let Some(problem) =
                shared_name(&names_sorted(&self.bodies), &r.focus, "the one to follow")
        {
            return Err(at.err("world.active_region.focus", problem));
        }
        if let Some(r) = &self.world.active_region
            && !self.bodies.iter().any(|b| b.name == r.focus)
        {
            let mut names: Vec<&str> = self.bodies.iter().map(|b| b.name.as_str()).collect();
            names.sort_unstable();
            names.dedup();
            return Err(at.err(
                "world.active_region.focus",
                format!(
                    "no body in [[bodies]] is named \"{}\"; known: {}",
                    r.focus,
                    if names.is_empty() {
                        "none".to_owned()
                    } else {
                        names.join(", ")
                    }
                ),
            ));
        }
        self.check_script(&at)
    }

    fn check_script(&self, at: &At<'_>) -> Result<(), ScenarioError> {
        // Names a script may refer to: tiles, bodies, templates' names, names of spawns.
        let mut names: Vec<&str> = self.bodies.iter().map(|b| b.name.as_str()).collect();
        names.extend(self.tiles.iter().map(|t| t.name.as_str()));
        names.extend(self.templates.values().map(|t| t.name.as_str()));
        for e in &self.script {
            if let ScriptAction::Spawn { body, .. } = &e.action {
                names.push(&body.name);
            }
        }
        names.sort_unstable();
        names.dedup();
        let by_name = names_sorted(&self.bodies);
        for (i, e) in self.script.iter().enumerate() {
            let field = format!("script[{i}]");
            if e.frame > self.frames {
                return Err(at.err(
                    format!("{field}.frame"),
                    format!(
                        "{} is after the last frame ({}): the event would never happen; \
                         raise `frames` or move the event",
                        e.frame, self.frames
                    ),
                ));
            }
            match &e.action {
                ScriptAction::Body { name, action } => {
                    if let Some(problem) = shared_name(&by_name, name, "the one this event is for")
                    {
                        return Err(at.err(format!("{field}.body"), problem));
                    }
                    if names.binary_search(&name.as_str()).is_err() {
                        return Err(at.err(format!("{field}.body"), no_such_name(name, &names)));
                    }
                    check_action(at, &field, action)?;
                }
                ScriptAction::Spawn { body, template } => {
                    if !self.templates.contains_key(template) {
                        return Err(at.err(
                            format!("{field}.template"),
                            unknown_problem("template", template, self.templates.keys()),
                        ));
                    }
                    check_body(at, self, body, &field)?;
                }
            }
        }
        Ok(())
    }
}

impl Simulation {
    /// [`Simulation::new`] of a scenario that passes [`Scenario::check`]: a scene built in
    /// code refused as its scenario file would be, before it runs (a script naming a body
    /// that does not exist is an error here, not a `missed` event at its frame).
    ///
    /// # Errors
    /// The first problem [`Scenario::check`] finds.
    pub fn try_new(scenario: &Scenario) -> Result<Simulation, ScenarioError> {
        scenario.check()?;
        Ok(Simulation::new(scenario))
    }

    /// [`Simulation::spawn`] of a definition that passes the loader's checks of a body
    /// (those of [`Scenario::check`], at field `spawn`): refused rather than brought within
    /// the limits.
    ///
    /// # Errors
    /// The first problem with the definition: a layer the world does not have, a value
    /// that is not finite or past the loader's limits, a template it names that the
    /// simulation does not have, a size or place a wrapping world refuses.
    pub fn try_spawn(&mut self, def: &BodyDef) -> Result<Entity, ScenarioError> {
        check_body(&At(&self.scenario.name), &self.scenario, def, "spawn")?;
        Ok(self.spawn(def))
    }
}
