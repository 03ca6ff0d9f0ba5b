//! Loading a scenario: TOML text → [`ScenarioFile`] (syntax) → [`Scenario`] (meaning). Every
//! error carries `file:line:column`, the field, and what was expected.

use std::collections::BTreeMap;
use std::ops::Range;

use crate::broad_phase::BroadPhaseKind;
use crate::def::{
    Action, ActiveRegion, BodyDef, BodyKind, Controller, Doomed, Event, LayerId, Layers, Response,
    Split, WorldBounds, WorldDef,
};
use crate::scenario_file::{
    ActionFile, BodyFile, ControllerFile, EventFile, ScenarioFile, SplitFile,
};
use ricochet_geom::Vec2;

/// A checked scenario, ready to simulate.
#[derive(Clone, Debug, PartialEq)]
pub struct Scenario {
    /// Name for logs.
    pub name: String,
    /// World settings.
    pub world: WorldDef,
    /// Default number of steps.
    pub frames: u64,
    /// Body prototypes by name.
    pub templates: BTreeMap<String, BodyDef>,
    /// Bodies at frame 0, in file order (which is their id order).
    pub bodies: Vec<BodyDef>,
    /// Script events sorted by frame (file order within a frame).
    pub script: Vec<Event>,
}

/// Why a scenario was rejected. Displays as `file:line:column: field: problem`.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{file}:{line}:{column}: {field}{sep}{problem}", sep = if self.field.is_empty() { "" } else { ": " })]
pub struct ScenarioError {
    /// The file name as given.
    pub file: String,
    /// 1-based line.
    pub line: usize,
    /// 1-based column.
    pub column: usize,
    /// The field path (`bodies[2].layer`), empty for a syntax error.
    pub field: String,
    /// What is wrong and what was expected.
    pub problem: String,
}

/// The most frames a scenario may ask for by default; longer runs are a `--frames` choice.
const MAX_FRAMES: i64 = 100_000_000;

struct Ctx<'a> {
    file: &'a str,
    text: &'a str,
}

impl Ctx<'_> {
    /// An error at `span`, narrowed to the line of `field`'s own key when that key is
    /// written inside the span (so `bodies[2].mass` points at `mass = -1`, not at
    /// `[[bodies]]`).
    fn err(
        &self,
        span: Range<usize>,
        field: impl Into<String>,
        problem: impl Into<String>,
    ) -> ScenarioError {
        let field = field.into();
        let start = self
            .key_in(&span, &field)
            .unwrap_or(span.start)
            .min(self.text.len());
        let before = &self.text[..start];
        let line = before.matches('\n').count() + 1;
        let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        ScenarioError {
            file: self.file.to_owned(),
            line,
            column,
            field,
            problem: problem.into(),
        }
    }

    /// Where the last key of `field` (`mass` in `bodies[2].mass`, `half_extents` in
    /// `bodies[0].shape.half_extents[1]`) is written as `key =` in the table at `span`.
    fn key_in(&self, span: &Range<usize>, field: &str) -> Option<usize> {
        let last = field.rsplit('.').next()?;
        let key = last.split('[').next()?;
        if key.is_empty() {
            return None;
        }
        // A table's span covers only its `[[header]]`: search on to the next header.
        let end = self.text[span.end.min(self.text.len())..]
            .find("\n[")
            .map_or(self.text.len(), |at| span.end + at);
        let text = self.text.get(span.start..end)?;
        let mut from = 0;
        while let Some(at) = text[from..].find(key) {
            let pos = from + at;
            let before = text[..pos].chars().next_back();
            let after = text[pos + key.len()..].trim_start();
            let starts_word = before.is_none_or(|c| !(c.is_alphanumeric() || c == '_'));
            if starts_word && after.starts_with('=') {
                return Some(span.start + pos);
            }
            from = pos + key.len();
        }
        None
    }
}

fn finite(v: f64) -> bool {
    v.is_finite()
}

/// A position within the coordinates the geometry accepts (`ricochet_geom::MAX_COORDINATE`).
fn within_world(
    fail: impl Fn(&str, String) -> ScenarioError,
    p: Vec2,
) -> Result<Vec2, ScenarioError> {
    if p.abs().max_element() > ricochet_geom::MAX_COORDINATE {
        return Err(fail(
            "position",
            format!(
                "[{:?}, {:?}] is beyond ±{:e}, the largest coordinate Ricochet accepts",
                p.x,
                p.y,
                ricochet_geom::MAX_COORDINATE
            ),
        ));
    }
    Ok(p)
}

fn vec2(v: [f64; 2]) -> Vec2 {
    Vec2::new(v[0], v[1])
}

/// Parses and checks a scenario. `file` is only used in error messages.
pub fn load_scenario(text: &str, file: &str) -> Result<Scenario, ScenarioError> {
    let ctx = Ctx { file, text };
    let raw: ScenarioFile = toml::from_str(text).map_err(|e| {
        let span = e.span().unwrap_or(0..0);
        ctx.err(span, "", e.message().trim_end().to_owned())
    })?;
    let dt = timestep(&ctx, &raw)?;
    let frames = match &raw.frames {
        None => 600,
        Some(f) => {
            let v = *f.get_ref();
            if !(0..=MAX_FRAMES).contains(&v) {
                return Err(ctx.err(
                    f.span(),
                    "frames",
                    format!("must be 0 to {MAX_FRAMES}, got {v}"),
                ));
            }
            v.unsigned_abs()
        }
    };
    let layers = layers(&ctx, &raw)?;
    let mut world = WorldDef {
        dt,
        layers,
        ..WorldDef::default()
    };
    if let Some(g) = &raw.world.gravity {
        let v = *g.get_ref();
        if !v.iter().all(|x| finite(*x)) {
            return Err(ctx.err(g.span(), "world.gravity", "must be finite numbers"));
        }
        world.gravity = vec2(v);
    }
    if let Some(b) = &raw.world.bounds {
        let r = b.get_ref();
        let ok = r.min.iter().chain(&r.max).all(|x| finite(*x))
            && r.min[0] < r.max[0]
            && r.min[1] < r.max[1];
        if !ok {
            return Err(ctx.err(
                b.span(),
                "world.bounds",
                "min and max must be finite with min < max on both axes",
            ));
        }
        world.bounds = Some(WorldBounds {
            min: vec2(r.min),
            max: vec2(r.max),
            wrap: r.wrap,
        });
    }
    if let Some(k) = &raw.world.broad_phase {
        world.broad_phase = match k.get_ref().as_str() {
            "auto" => BroadPhaseKind::Auto,
            "brute-force" => BroadPhaseKind::BruteForce,
            "sort-and-sweep" => BroadPhaseKind::SortAndSweep,
            "grid" => BroadPhaseKind::Grid,
            other => {
                return Err(ctx.err(
                    k.span(),
                    "world.broad_phase",
                    format!("expected auto, brute-force, sort-and-sweep or grid, got \"{other}\""),
                ));
            }
        };
    }
    if let Some(n) = &raw.world.sleep_after {
        let v = *n.get_ref();
        let frames = u32::try_from(v).ok().filter(|f| *f >= 1).ok_or_else(|| {
            ctx.err(
                n.span(),
                "world.sleep_after",
                format!(
                    "must be a whole number of frames from 1 to {}, got {v}",
                    u32::MAX
                ),
            )
        })?;
        world.sleep_after = Some(frames);
    }
    if let Some(r) = &raw.world.active_region {
        let h = *r.half_extents.get_ref();
        if !h.iter().all(|x| finite(*x) && *x > 0.0) {
            return Err(ctx.err(
                r.half_extents.span(),
                "world.active_region.half_extents",
                format!(
                    "must be finite numbers > 0 on both axes, got [{}, {}]",
                    h[0], h[1]
                ),
            ));
        }
        // The focus is checked once the bodies are known, below.
        world.active_region = Some(ActiveRegion {
            focus: r.focus.get_ref().clone(),
            half_extents: vec2(h),
        });
    }
    let mut templates = BTreeMap::new();
    for (name, t) in &raw.templates {
        let field = format!("templates.{name}");
        if t.get_ref().template.is_some() {
            return Err(ctx.err(
                t.span(),
                format!("{field}.template"),
                "a template cannot itself use a template",
            ));
        }
        let def = body_def(&ctx, &world.layers, t.get_ref(), t.span(), &field, name)?;
        templates.insert(name.clone(), def);
    }
    // Checks that need every template: bullets and splits must name one.
    for (name, t) in &raw.templates {
        references(
            &ctx,
            &templates,
            t.get_ref(),
            t.span(),
            &format!("templates.{name}"),
        )?;
    }
    // A split chain must end: a template that splits (through others) into itself would
    // multiply bodies every time one is destroyed.
    for (name, t) in &raw.templates {
        if let Some(path) = split_cycle(&templates, name) {
            return Err(ctx.err(
                t.span(),
                format!("templates.{name}.split"),
                format!(
                    "{} splits into itself: a split chain must end",
                    path.join(" -> ")
                ),
            ));
        }
    }
    let mut bodies = Vec::with_capacity(raw.bodies.len());
    for (i, b) in raw.bodies.iter().enumerate() {
        let field = format!("bodies[{i}]");
        let merged = match &b.get_ref().template {
            None => b.get_ref().clone(),
            Some(t) => {
                let Some(base) = raw.templates.get(t) else {
                    return Err(unknown(
                        &ctx,
                        b.span(),
                        format!("{field}.template"),
                        "template",
                        t,
                        raw.templates.keys(),
                    ));
                };
                merge(b.get_ref(), base.get_ref())
            }
        };
        let default_name = b
            .get_ref()
            .template
            .clone()
            .unwrap_or_else(|| "body".to_owned());
        references(&ctx, &templates, &merged, b.span(), &field)?;
        bodies.push(body_def(
            &ctx,
            &world.layers,
            &merged,
            b.span(),
            &field,
            &default_name,
        )?);
    }
    if let Some(r) = &raw.world.active_region {
        let focus = r.focus.get_ref();
        if !bodies.iter().any(|b| &b.name == focus) {
            let mut names: Vec<&str> = bodies.iter().map(|b| b.name.as_str()).collect();
            names.sort_unstable();
            names.dedup();
            return Err(ctx.err(
                r.focus.span(),
                "world.active_region.focus",
                format!(
                    "no body in [[bodies]] is named \"{focus}\"; known: {}",
                    if names.is_empty() {
                        "none".to_owned()
                    } else {
                        names.join(", ")
                    }
                ),
            ));
        }
    }
    let script = script(&ctx, &raw, &templates, &bodies)?;
    Ok(Scenario {
        name: raw.name.clone().unwrap_or_else(|| {
            std::path::Path::new(file).file_stem().map_or_else(
                || "scenario".to_owned(),
                |s| s.to_string_lossy().into_owned(),
            )
        }),
        world,
        frames,
        templates,
        bodies,
        script,
    })
}

/// The chain of templates by which `start` splits back into itself, if it does.
fn split_cycle(templates: &BTreeMap<String, BodyDef>, start: &str) -> Option<Vec<String>> {
    fn walk(
        templates: &BTreeMap<String, BodyDef>,
        start: &str,
        at: &str,
        path: &mut Vec<String>,
    ) -> bool {
        let Some(t) = templates.get(at) else {
            return false;
        };
        for child in &t.split {
            if child.template == start {
                path.push(child.template.clone());
                return true;
            }
            if path.contains(&child.template) {
                continue;
            }
            path.push(child.template.clone());
            if walk(templates, start, &child.template, path) {
                return true;
            }
            path.pop();
        }
        false
    }
    let mut path = vec![start.to_owned()];
    walk(templates, start, start, &mut path).then_some(path)
}

fn unknown<'a>(
    ctx: &Ctx<'_>,
    span: Range<usize>,
    field: String,
    what: &str,
    name: &str,
    known: impl Iterator<Item = &'a String>,
) -> ScenarioError {
    let known: Vec<&str> = known.map(String::as_str).collect();
    ctx.err(
        span,
        field,
        format!(
            "unknown {what} \"{name}\"; known: {}",
            if known.is_empty() {
                "none".to_owned()
            } else {
                known.join(", ")
            }
        ),
    )
}

fn timestep(ctx: &Ctx<'_>, raw: &ScenarioFile) -> Result<f64, ScenarioError> {
    match (&raw.hz, &raw.dt) {
        (Some(h), Some(_)) => Err(ctx.err(h.span(), "hz", "give `hz` or `dt`, not both")),
        (Some(h), None) => {
            let v = *h.get_ref();
            if !(finite(v) && v > 0.0) {
                return Err(ctx.err(
                    h.span(),
                    "hz",
                    format!("must be a finite number > 0, got {v}"),
                ));
            }
            Ok(1.0 / v)
        }
        (None, Some(d)) => {
            let v = *d.get_ref();
            if !(finite(v) && v > 0.0) {
                return Err(ctx.err(
                    d.span(),
                    "dt",
                    format!("must be a finite number of seconds > 0, got {v}"),
                ));
            }
            Ok(v)
        }
        (None, None) => Ok(1.0 / 60.0),
    }
}

fn layers(ctx: &Ctx<'_>, raw: &ScenarioFile) -> Result<Layers, ScenarioError> {
    let list = raw.layers.get_ref();
    if list.is_empty() || list.len() > usize::from(LayerId::MAX) {
        return Err(ctx.err(raw.layers.span(), "layers", "list 1 to 255 layer names"));
    }
    let mut names: Vec<String> = Vec::with_capacity(list.len());
    for (i, n) in list.iter().enumerate() {
        if names.contains(n.get_ref()) {
            return Err(ctx.err(
                n.span(),
                format!("layers[{i}]"),
                format!("layer \"{}\" is listed twice", n.get_ref()),
            ));
        }
        names.push(n.get_ref().clone());
    }
    let mut layers = Layers::new(names);
    for (i, f) in raw.fast_layers.iter().enumerate() {
        let Some(id) = layers.id(f.get_ref()) else {
            return Err(unknown(
                ctx,
                f.span(),
                format!("fast_layers[{i}]"),
                "layer",
                f.get_ref(),
                layers.names().iter(),
            ));
        };
        layers.set_fast(id);
    }
    let mut seen = Vec::new();
    for (i, c) in raw.collide.iter().enumerate() {
        let field = format!("collide[{i}]");
        let r = c.get_ref();
        let id = |name: &str, which: &str| {
            layers.id(name).ok_or_else(|| {
                unknown(
                    ctx,
                    c.span(),
                    format!("{field}.{which}"),
                    "layer",
                    name,
                    layers.names().iter(),
                )
            })
        };
        let (a, b) = (id(&r.a, "a")?, id(&r.b, "b")?);
        let key = (a.min(b), a.max(b));
        if seen.contains(&key) {
            return Err(ctx.err(
                c.span(),
                field,
                format!("the pair {}/{} is listed twice", r.a, r.b),
            ));
        }
        seen.push(key);
        if a == b && matches!(r.destroy.as_deref(), Some("a" | "b")) {
            return Err(ctx.err(
                c.span(),
                format!("{field}.destroy"),
                format!("both sides are layer \"{}\": say \"both\"; \"a\" and \"b\" can't tell them apart", r.a),
            ));
        }
        let response = match (r.response.as_str(), r.destroy.as_deref()) {
            ("ignore", None) => Response::Ignore,
            ("report", None) => Response::Report,
            ("separate", None) => Response::Separate,
            ("destroy", None | Some("both")) => Response::Destroy(Doomed::Both),
            ("destroy", Some("a")) => Response::Destroy(Doomed::First),
            ("destroy", Some("b")) => Response::Destroy(Doomed::Second),
            ("destroy", Some(other)) => {
                return Err(ctx.err(
                    c.span(),
                    format!("{field}.destroy"),
                    format!("expected \"a\", \"b\" or \"both\", got \"{other}\""),
                ));
            }
            ("ignore" | "report" | "separate", Some(_)) => {
                return Err(ctx.err(
                    c.span(),
                    format!("{field}.destroy"),
                    "only a `destroy` response says which body goes",
                ));
            }
            (other, _) => {
                return Err(ctx.err(
                    c.span(),
                    format!("{field}.response"),
                    format!("expected ignore, report, destroy or separate, got \"{other}\""),
                ));
            }
        };
        layers.set(a, b, response);
        if let Some(sweep) = r.sweep {
            layers.set_sweep(a, b, sweep);
        }
    }
    Ok(layers)
}

/// A body's fields over its template's.
fn merge(body: &BodyFile, base: &BodyFile) -> BodyFile {
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

fn references(
    ctx: &Ctx<'_>,
    templates: &BTreeMap<String, BodyDef>,
    b: &BodyFile,
    span: Range<usize>,
    field: &str,
) -> Result<(), ScenarioError> {
    if let Some(ControllerFile::Ship { bullet, .. }) = &b.controller
        && !templates.contains_key(bullet)
    {
        return Err(unknown(
            ctx,
            span,
            format!("{field}.controller.bullet"),
            "template",
            bullet,
            templates.keys(),
        ));
    }
    for (i, s) in b.split.iter().flatten().enumerate() {
        if !templates.contains_key(&s.template) {
            return Err(unknown(
                ctx,
                span,
                format!("{field}.split[{i}].template"),
                "template",
                &s.template,
                templates.keys(),
            ));
        }
    }
    Ok(())
}

fn body_def(
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
            Err(fail(f, format!("must be a finite number, got {v}")))
        }
    };
    let pair = |f: &str, v: [f64; 2]| {
        if v.iter().all(|x| finite(*x)) {
            Ok(vec2(v))
        } else {
            Err(fail(
                f,
                format!("must be finite numbers, got [{}, {}]", v[0], v[1]),
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
    let mass = num("mass", b.mass.unwrap_or(1.0))?;
    if mass <= 0.0 {
        return Err(fail("mass", format!("must be greater than 0, got {mass}")));
    }
    let lifetime = match b.lifetime {
        None => None,
        Some(l) if l >= 1 && l <= i64::from(u32::MAX) => u32::try_from(l).ok(),
        Some(l) => {
            return Err(fail(
                "lifetime",
                format!("must be a whole number of frames >= 1, got {l}"),
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
            muzzle: num("controller.muzzle", *muzzle)?,
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
    })
}

fn script(
    ctx: &Ctx<'_>,
    raw: &ScenarioFile,
    templates: &BTreeMap<String, BodyDef>,
    bodies: &[BodyDef],
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
        let body = |name: &String| -> Result<String, ScenarioError> {
            if names.binary_search(&name.as_str()).is_ok() {
                Ok(name.clone())
            } else {
                Err(fail(
                    "body",
                    format!(
                        "no body, template or spawn is named \"{name}\"; known: {}",
                        names.join(", ")
                    ),
                ))
            }
        };
        let v = |f: &str, v: [f64; 2]| {
            if v.iter().all(|x| finite(*x)) {
                Ok(vec2(v))
            } else {
                Err(fail(f, "must be finite numbers".to_owned()))
            }
        };
        let input = |x: f64| {
            if finite(x) && (-1.0..=1.0).contains(&x) {
                Ok(x)
            } else {
                Err(fail("input", format!("must be between -1 and 1, got {x}")))
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
                def.position = v("position", *position)?;
                if let Some(vel) = velocity {
                    def.velocity = v("velocity", *vel)?;
                }
                if let Some(a) = angle {
                    if !finite(*a) {
                        return Err(fail("angle", "must be a finite number".to_owned()));
                    }
                    def.angle = *a;
                }
                Action::Spawn {
                    body: Box::new(def),
                    template: template.clone(),
                }
            }
            ActionFile::Destroy { body: b } => Action::Destroy { body: body(b)? },
            ActionFile::SetVelocity { body: b, velocity } => Action::SetVelocity {
                body: body(b)?,
                velocity: v("velocity", *velocity)?,
            },
            ActionFile::ApplyImpulse { body: b, impulse } => Action::ApplyImpulse {
                body: body(b)?,
                impulse: v("impulse", *impulse)?,
            },
            ActionFile::SetForce { body: b, force } => Action::SetForce {
                body: body(b)?,
                force: v("force", *force)?,
            },
            ActionFile::Thrust { body: b, on } => Action::Thrust {
                body: body(b)?,
                on: *on,
            },
            ActionFile::Turn { body: b, input: x } => Action::Turn {
                body: body(b)?,
                input: input(*x)?,
            },
            ActionFile::Fire { body: b } => Action::Fire { body: body(b)? },
            ActionFile::Move { body: b, input: x } => Action::Move {
                body: body(b)?,
                input: input(*x)?,
            },
            ActionFile::Jump { body: b } => Action::Jump { body: body(b)? },
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
