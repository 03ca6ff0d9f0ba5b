//! The script: timed events, checked against the bodies and templates they name.

use std::collections::BTreeMap;

use crate::action::{Action, Event, ScriptAction};
use crate::check::problems::{names_sorted, shared_name};
use crate::def::{BodyDef, BodyKind};
use crate::load::context::{Ctx, ScenarioError, finite, unknown, vec2, within_world};
use crate::load::file::{ActionFile, EventFile, ScenarioFile};
use ricochet_geom::Number;

pub(crate) fn script(
    ctx: &Ctx<'_>,
    raw: &ScenarioFile,
    world: &crate::WorldDef,
    templates: &BTreeMap<String, BodyDef>,
    bodies: &[BodyDef],
    frames: u64,
) -> Result<Vec<Event>, ScenarioError> {
    // Names a script may refer to: bodies, templates' names, and names given by spawns.
    let mut names: Vec<&str> = bodies.iter().map(|b| b.name.as_str()).collect();
    names.extend(templates.values().map(|t| t.name.as_str()));
    for e in &raw.script {
        if let ActionFile::Spawn { name: Some(n), .. } = &e.get_ref().action {
            names.push(n);
        }
    }
    names.sort_unstable();
    names.dedup();
    let by_name = names_sorted(bodies);
    let mut events = Vec::with_capacity(raw.script.len());
    for (i, e) in raw.script.iter().enumerate() {
        let field = format!("script[{i}]");
        let EventFile { frame, action } = e.get_ref();
        let fail = |f: &str, problem: String| ctx.err(e.span(), format!("{field}.{f}"), problem);
        if *frame < 0 {
            return Err(fail(
                "frame",
                format!("{frame} is in the past: frames start at 0"),
            ));
        }
        if frame.unsigned_abs() > frames {
            return Err(fail(
                "frame",
                format!(
                    "{frame} is after the last frame ({frames}): the event would never \
                     happen; raise `frames` or move the event"
                ),
            ));
        }
        let body = |name: &String| -> Result<String, ScenarioError> {
            if let Some(problem) = shared_name(&by_name, name, "the one this event is for") {
                return Err(fail("body", problem));
            }
            if names.binary_search(&name.as_str()).is_ok() {
                Ok(name.clone())
            } else {
                Err(fail(
                    "body",
                    crate::check::problems::no_such_name(name, &names),
                ))
            }
        };
        let named = |b: &String, action: Action| -> Result<ScriptAction, ScenarioError> {
            Ok(ScriptAction::Body {
                name: body(b)?,
                action,
            })
        };
        // As strict as a body's values and a live input's (crates/record/src/session.rs): finite, and
        // within the coordinates the geometry accepts.
        let v = |f: &str, v: [f64; 2]| {
            if !v.iter().all(|x| finite(*x)) {
                Err(fail(f, "must be finite numbers".to_owned()))
            } else if v.iter().any(|x| x.abs() > ricochet_geom::MAX_COORDINATE) {
                Err(fail(
                    f,
                    format!(
                        "{} is beyond ±{:e}, the largest {} Ricochet accepts",
                        ricochet_geom::Numbers(v),
                        ricochet_geom::MAX_COORDINATE,
                        if f == "position" {
                            "coordinate"
                        } else {
                            "value"
                        }
                    ),
                ))
            } else {
                Ok(vec2(v))
            }
        };
        let input = |x: f64| {
            if finite(x) && (-1.0..=1.0).contains(&x) {
                Ok(x)
            } else {
                Err(fail(
                    "input",
                    format!("must be between -1 and 1, got {}", Number(x)),
                ))
            }
        };
        let action = match action {
            ActionFile::Spawn {
                template,
                name,
                position,
                velocity,
                angle,
            } => {
                let Some(base) = templates.get(template) else {
                    return Err(unknown(
                        ctx,
                        e.span(),
                        format!("{field}.template"),
                        "template",
                        template,
                        templates.keys(),
                    ));
                };
                let mut def = base.clone();
                if let Some(n) = name {
                    def.name = n.clone();
                }
                def.position = within_world(fail, v("position", *position)?)?;
                if let Some(problem) = crate::check::problems::static_outside(world, &def) {
                    return Err(fail("position", problem));
                }
                if let Some(vel) = velocity {
                    if def.kind == BodyKind::Static {
                        return Err(fail(
                            "velocity",
                            format!(
                                "template \"{template}\" is static: a static body never \
                                 moves, so this velocity would be dropped: for a body that \
                                 moves at its velocity, give the template \
                                 `kind = \"kinematic\"`"
                            ),
                        ));
                    }
                    def.velocity = v("velocity", *vel)?;
                }
                if let Some(a) = angle {
                    if !finite(*a) {
                        return Err(fail("angle", "must be a finite number".to_owned()));
                    }
                    def.angle = *a;
                }
                ScriptAction::Spawn {
                    body: Box::new(def),
                    template: template.clone(),
                }
            }
            ActionFile::Destroy { body: b } => named(b, Action::Destroy)?,
            ActionFile::SetVelocity { body: b, velocity } => {
                named(b, Action::SetVelocity(v("velocity", *velocity)?))?
            }
            ActionFile::ApplyImpulse { body: b, impulse } => {
                named(b, Action::ApplyImpulse(v("impulse", *impulse)?))?
            }
            ActionFile::SetForce { body: b, force } => {
                named(b, Action::SetForce(v("force", *force)?))?
            }
            ActionFile::Thrust { body: b, on } => named(b, Action::Thrust(*on))?,
            ActionFile::Turn { body: b, input: x } => named(b, Action::Turn(input(*x)?))?,
            ActionFile::Fire { body: b } => named(b, Action::Fire)?,
            ActionFile::Move { body: b, input: x } => named(b, Action::Move(input(*x)?))?,
            ActionFile::Jump { body: b } => named(b, Action::Jump)?,
            ActionFile::Drop { body: b } => named(b, Action::Drop)?,
        };
        events.push(Event {
            frame: frame.unsigned_abs(),
            action,
        });
    }
    // Stable: events of one frame keep their file order.
    events.sort_by_key(|e| e.frame);
    Ok(events)
}
