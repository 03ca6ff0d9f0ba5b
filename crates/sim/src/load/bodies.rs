//! Templates and bodies: a body's fields over its template's, the references between
//! templates (bullets, splits), and the checked [`BodyDef`].

use std::collections::BTreeMap;
use std::ops::Range;

use crate::check::problems::{controller_problem, mass_problem};
use crate::def::{BodyDef, BodyKind, Controller, Layers, Split};
use crate::load::context::{Ctx, ScenarioError, finite, unknown, vec2, within_world};
use crate::load::file::{BodyFile, ControllerFile, SplitFile};
use ricochet_geom::{Number, Numbers};

/// A body's fields over its template's.
pub(crate) fn merge(body: &BodyFile, base: &BodyFile) -> BodyFile {
    BodyFile {
        template: body.template.clone(),
        name: body.name.clone().or_else(|| base.name.clone()),
        layer: body.layer.clone().or_else(|| base.layer.clone()),
        shape: body.shape.clone().or_else(|| base.shape.clone()),
        kind: body.kind.clone().or_else(|| base.kind.clone()),
        mass: body.mass.or(base.mass),
        position: body.position.or(base.position),
        angle: body.angle.or(base.angle),
        velocity: body.velocity.or(base.velocity),
        angular_velocity: body.angular_velocity.or(base.angular_velocity),
        force: body.force.or(base.force),
        gravity_scale: body.gravity_scale.or(base.gravity_scale),
        lifetime: body.lifetime.or(base.lifetime),
        controller: body.controller.clone().or_else(|| base.controller.clone()),
        split: body.split.clone().or_else(|| base.split.clone()),
    }
}

pub(crate) fn references(
    ctx: &Ctx<'_>,
    templates: &BTreeMap<String, BodyDef>,
    b: &BodyFile,
    span: Range<usize>,
    field: &str,
) -> Result<(), ScenarioError> {
    if let Some(ControllerFile::Ship { bullet, .. }) = &b.controller {
        let Some(t) = templates.get(bullet) else {
            return Err(unknown(
                ctx,
                span,
                format!("{field}.controller.bullet"),
                "template",
                bullet,
                templates.keys(),
            ));
        };
        // A bullet leaves at the ship's velocity plus `bullet_speed`; a static one never
        // moves, so that velocity would be dropped without a word.
        if t.kind == BodyKind::Static {
            return Err(ctx.err(
                span,
                format!("{field}.controller.bullet"),
                format!(
                    "template \"{bullet}\" is static: a static bullet never moves, so its \
                     velocity (the ship's plus bullet_speed) would be dropped: give the \
                     template `kind = \"dynamic\"` (or \"kinematic\")"
                ),
            ));
        }
    }
    for (i, s) in b.split.iter().flatten().enumerate() {
        let Some(t) = templates.get(&s.template) else {
            return Err(unknown(
                ctx,
                span,
                format!("{field}.split[{i}].template"),
                "template",
                &s.template,
                templates.keys(),
            ));
        };
        // A child leaves at the parent's velocity plus the split's; a static child never
        // moves, so that velocity would be dropped without a word, unless there is none (a
        // static parent, no split velocity).
        let static_parent = b.kind.as_deref() == Some("static");
        if t.kind == BodyKind::Static && (!static_parent || s.velocity != [0.0, 0.0]) {
            return Err(ctx.err(
                span,
                format!("{field}.split[{i}].template"),
                format!(
                    "template \"{}\" is static: a static child never moves, so its velocity \
                     (the parent's plus the split's) would be dropped: give the template \
                     `kind = \"dynamic\"` (or \"kinematic\")",
                    s.template
                ),
            ));
        }
    }
    Ok(())
}

pub(crate) fn body_def(
    ctx: &Ctx<'_>,
    layers: &Layers,
    b: &BodyFile,
    span: Range<usize>,
    field: &str,
    default_name: &str,
) -> Result<BodyDef, ScenarioError> {
    let fail = |f: &str, problem: String| ctx.err(span.clone(), format!("{field}.{f}"), problem);
    let num = |f: &str, v: f64| {
        if finite(v) {
            Ok(v)
        } else {
            Err(fail(
                f,
                format!("must be a finite number, got {}", Number(v)),
            ))
        }
    };
    let pair = |f: &str, v: [f64; 2]| {
        if v.iter().all(|x| finite(*x)) {
            Ok(vec2(v))
        } else {
            Err(fail(
                f,
                format!("must be finite numbers, got {}", Numbers(v)),
            ))
        }
    };
    let Some(layer_name) = &b.layer else {
        return Err(fail(
            "layer",
            "every body needs a layer (here or in its template)".to_owned(),
        ));
    };
    let layer = layers.id(layer_name).ok_or_else(|| {
        unknown(
            ctx,
            span.clone(),
            format!("{field}.layer"),
            "layer",
            layer_name,
            layers.names().iter(),
        )
    })?;
    let Some(shape) = &b.shape else {
        return Err(fail(
            "shape",
            "every body needs a shape (here or in its template)".to_owned(),
        ));
    };
    let shape = shape
        .to_shape()
        .map_err(|e| fail(&format!("shape.{}", e.field), e.problem))?;
    let kind = match b.kind.as_deref() {
        None | Some("dynamic") => BodyKind::Dynamic,
        Some("static") => BodyKind::Static,
        Some("kinematic") => BodyKind::Kinematic,
        Some(other) => {
            return Err(fail(
                "kind",
                format!("expected dynamic, static or kinematic, got \"{other}\""),
            ));
        }
    };
    if shape.is_chain() && kind != BodyKind::Static {
        return Err(fail(
            "kind",
            "a chain is static terrain: give this body kind = \"static\" (a moving line \
             is a capsule or a polygon)"
                .to_owned(),
        ));
    }
    let mass = num("mass", b.mass.unwrap_or(1.0))?;
    if let Some(problem) = mass_problem(mass) {
        return Err(fail("mass", problem));
    }
    let lifetime = match b.lifetime {
        None => None,
        Some(l) if l >= 1 && l <= i64::from(u32::MAX) => u32::try_from(l).ok(),
        Some(l) => {
            return Err(fail(
                "lifetime",
                format!(
                    "must be a whole number of frames from 1 to {}, got {l}",
                    u32::MAX
                ),
            ));
        }
    };
    let controller = match &b.controller {
        None => None,
        Some(ControllerFile::Ship {
            thrust,
            turn_rate,
            bullet,
            bullet_speed,
            muzzle,
        }) => Some(Controller::Ship {
            thrust: num("controller.thrust", *thrust)?,
            turn_rate: num("controller.turn_rate", *turn_rate)?,
            bullet: bullet.clone(),
            bullet_speed: num("controller.bullet_speed", *bullet_speed)?,
            muzzle: {
                let m = num("controller.muzzle", *muzzle)?;
                if m.abs() > ricochet_geom::MAX_COORDINATE {
                    return Err(fail(
                        "controller.muzzle",
                        format!(
                            "{} is beyond ±{:e}, the largest coordinate Ricochet accepts",
                            Number(m),
                            ricochet_geom::MAX_COORDINATE
                        ),
                    ));
                }
                m
            },
        }),
        Some(ControllerFile::Runner {
            run_speed,
            jump_speed,
        }) => Some(Controller::Runner {
            run_speed: num("controller.run_speed", *run_speed)?,
            jump_speed: num("controller.jump_speed", *jump_speed)?,
        }),
        Some(ControllerFile::Walker { speed }) => Some(Controller::Walker {
            speed: num("controller.speed", *speed)?,
        }),
    };
    if let Some((f, problem)) = controller.as_ref().and_then(controller_problem) {
        return Err(fail(&f, problem));
    }
    let mut split = Vec::new();
    for (
        i,
        SplitFile {
            template,
            offset,
            velocity,
        },
    ) in b.split.iter().flatten().enumerate()
    {
        split.push(Split {
            template: template.clone(),
            offset: pair(&format!("split[{i}].offset"), *offset)?,
            velocity: pair(&format!("split[{i}].velocity"), *velocity)?,
        });
    }
    Ok(BodyDef {
        name: b.name.clone().unwrap_or_else(|| default_name.to_owned()),
        layer,
        shape,
        kind,
        mass,
        position: within_world(fail, pair("position", b.position.unwrap_or_default())?)?,
        angle: num("angle", b.angle.unwrap_or(0.0))?,
        velocity: pair("velocity", b.velocity.unwrap_or_default())?,
        angular_velocity: num("angular_velocity", b.angular_velocity.unwrap_or(0.0))?,
        force: pair("force", b.force.unwrap_or_default())?,
        gravity_scale: num("gravity_scale", b.gravity_scale.unwrap_or(1.0))?,
        lifetime,
        controller,
        split,
        // A game's own; scenario files have none.
        user_data: 0,
    })
}

/// The fields a body file may set that some kind of body ignores, and whether `b` sets each.
fn kind_sensitive(b: &BodyFile) -> [(&'static str, bool); 6] {
    [
        ("velocity", b.velocity.is_some()),
        ("angular_velocity", b.angular_velocity.is_some()),
        ("force", b.force.is_some()),
        ("gravity_scale", b.gravity_scale.is_some()),
        ("mass", b.mass.is_some()),
        (
            "controller",
            matches!(
                b.controller,
                Some(ControllerFile::Runner { .. } | ControllerFile::Walker { .. })
            ),
        ),
    ]
}

/// Why a body of `kind` ignores `field` (one of [`kind_sensitive`]'s), if it does. What the
/// stages really do: a static body's velocity and angular velocity are set to zero when it
/// is created, and it is never integrated, so no controller that sets a velocity (runner,
/// walker) moves it (a static ship still fires; its turn and thrust do nothing); `forces`
/// and impulses act on dynamic bodies only, so static and kinematic bodies ignore `force`,
/// `gravity_scale` and `mass` (a kinematic body keeps its velocity, angular velocity and
/// controller: it moves, turns, runs or walks, whatever touches it).
fn ignored_because(kind: BodyKind, field: &str) -> Option<&'static str> {
    match (kind, field) {
        (BodyKind::Static, "velocity") => Some(
            "a static body never moves, so this velocity would be dropped: for a body that \
             moves at its velocity whatever it touches, write `kind = \"kinematic\"`",
        ),
        (BodyKind::Static, "angular_velocity") => Some(
            "a static body never turns, so this angular velocity would be dropped: for a body \
             that turns whatever it touches, write `kind = \"kinematic\"`",
        ),
        (BodyKind::Static, "controller") => Some(
            "a static body never moves, so a runner or walker controller would do nothing: \
             make it dynamic (or kinematic), or remove the controller",
        ),
        (BodyKind::Static, _) => Some(
            "a static body is moved by nothing, so this would be ignored: make it dynamic, \
             or remove the field",
        ),
        (BodyKind::Kinematic, "force" | "gravity_scale" | "mass") => Some(
            "a kinematic body moves at its velocity whatever acts on it, so this would be \
             ignored: make it dynamic, or remove the field",
        ),
        _ => None,
    }
}

/// The first field `merged` (a body over its template, or a template) sets that a body of
/// `kind` ignores, with the problem: whoever wrote it expected it to do something. `own`
/// is what the body itself wrote: a field set only by its template says so.
pub(crate) fn ignored_field(
    kind: BodyKind,
    merged: &BodyFile,
    own: &BodyFile,
) -> Option<(&'static str, String)> {
    kind_sensitive(merged)
        .iter()
        .zip(kind_sensitive(own))
        .find_map(|(&(field, set), (_, set_here))| {
            let why = ignored_because(kind, field).filter(|_| set)?;
            let problem = match (&own.template, set_here) {
                (Some(t), false) => format!("{why} (set by template \"{t}\")"),
                _ => why.to_owned(),
            };
            Some((field, problem))
        })
}
