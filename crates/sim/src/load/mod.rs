//! Loading a scenario file: TOML text → [`file::ScenarioFile`] (syntax, serde with
//! `deny_unknown_fields`) → [`Scenario`] (meaning, defaults). Every error carries
//! `file:line:column`, the field, and what was expected.

mod bodies;
mod chunks;
mod context;
pub mod file;
mod script;
mod tiled;
mod world;

use std::collections::BTreeMap;

use crate::check::problems::{names_sorted, shared_name};
use crate::check::problems::{oversized, split_problem, static_outside};
use crate::scenario::{Scenario, TiledDef};
use bodies::{body_def, ignored_field, merge, references};
use chunks::split_bodies;
pub use context::ScenarioError;
use context::{Ctx, unknown};
use file::{BodyFile, BodyTable, ScenarioFile};
use script::script;
use std::ops::Range;
use toml::Spanned;
use world::world_settings;

/// Parses and checks a scenario. `file` is only used in error messages.
///
/// # Errors
/// The first problem, located. A scenario with a `[tiled]` table is refused here (its
/// level would be missing): load it with [`load_scenario_and_map`] and give the table to
/// `ricochet-tiled`, as the `ricochet` binary does.
pub fn load_scenario(text: &str, file: &str) -> Result<Scenario, ScenarioError> {
    match load(text, file, true)? {
        (s, None) => Ok(s),
        (_, Some((_, span))) => Err(Ctx { file, text }.err(
            span,
            "tiled",
            "this scenario takes its level from a Tiled map, which this loader does not read \
             (it does no I/O): load it with `load_scenario_and_map` and \
             `ricochet_tiled::add_map` (the `ricochet` binary's run, check, validate, serve and test do)",
        )),
    }
}

/// [`load_scenario`], also returning the scenario's `[tiled]` table (when it has one) for
/// `ricochet-tiled` to read the map: the scenario returned lacks the map's bodies until then.
///
/// # Errors
/// The first problem, located, as for [`load_scenario`].
pub fn load_scenario_and_map(
    text: &str,
    file: &str,
) -> Result<(Scenario, Option<TiledDef>), ScenarioError> {
    let (s, t) = load(text, file, true)?;
    Ok((s, t.map(|(def, _)| def)))
}

/// A scenario, and its `[tiled]` table with where it is written.
type Loaded = (Scenario, Option<(TiledDef, Range<usize>)>);

/// [`load_scenario`], with `[[bodies]]` tables parsed one at a time (`chunked`) or with the
/// whole file (the tests check that both give the same scenario or the same error).
fn load(text: &str, file: &str, chunked: bool) -> Result<Loaded, ScenarioError> {
    let ctx = Ctx { file, text };
    let syntax = |e: toml::de::Error, offset: usize| {
        let span = e
            .span()
            .map_or(offset..offset, |r| r.start + offset..r.end + offset);
        let field = ctx.field_at(span.start);
        ctx.err(span, field, e.message().trim_end().to_owned())
    };
    // `[[bodies]]` tables are parsed one at a time, below; the rest now.
    let (raw, chunks): (ScenarioFile, Vec<Range<usize>>) =
        match split_bodies(text).filter(|_| chunked) {
            Some((skeleton, chunks)) => {
                let raw: ScenarioFile = toml::from_str(&skeleton).map_err(|e| syntax(e, 0))?;
                if !raw.bodies.is_empty() {
                    // Bodies written both ways (an unusual header spelling): parse it all.
                    (toml::from_str(text).map_err(|e| syntax(e, 0))?, Vec::new())
                } else {
                    (raw, chunks)
                }
            }
            None => (toml::from_str(text).map_err(|e| syntax(e, 0))?, Vec::new()),
        };
    let body_at = |k: usize| -> Result<Spanned<BodyFile>, ScenarioError> {
        let Some(c) = chunks.get(k) else {
            return Ok(raw.bodies[k].clone());
        };
        let parsed: BodyTable = toml::from_str(&text[c.clone()]).map_err(|e| syntax(e, c.start))?;
        let body = parsed
            .bodies
            .into_iter()
            .next()
            .unwrap_or_else(|| Spanned::new(0..0, BodyFile::default()));
        let span = body.span();
        Ok(Spanned::new(
            span.start + c.start..span.end + c.start,
            body.into_inner(),
        ))
    };
    let n_bodies = if chunks.is_empty() {
        raw.bodies.len()
    } else {
        chunks.len()
    };
    let (world, frames) = world_settings(&ctx, &raw)?;
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
        if let Some((f, problem)) = ignored_field(def.kind, t.get_ref(), t.get_ref()) {
            return Err(ctx.err(t.span(), format!("{field}.{f}"), problem));
        }
        // Every template: a script's spawn, a ship's bullet, a split, and a live input's
        // spawn in `serve` may create its body.
        if let Some(problem) = oversized(&world, &def) {
            return Err(ctx.err(t.span(), format!("{field}.shape"), problem));
        }
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
    // A split chain must end, and not multiply bodies past what a frame can hold.
    if let Some((name, problem)) = split_problem(&templates) {
        let span = raw.templates.get(&name).map_or(0..0, Spanned::span);
        return Err(ctx.err(span, format!("templates.{name}.split"), problem));
    }
    let mut bodies = Vec::with_capacity(n_bodies);
    for i in 0..n_bodies {
        let b = &body_at(i)?;
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
        let def = body_def(
            &ctx,
            &world.layers,
            &merged,
            b.span(),
            &field,
            &default_name,
        )?;
        if let Some((f, problem)) = ignored_field(def.kind, &merged, b.get_ref()) {
            return Err(ctx.err(b.span(), format!("{field}.{f}"), problem));
        }
        if let Some(problem) = oversized(&world, &def) {
            return Err(ctx.err(b.span(), format!("{field}.shape"), problem));
        }
        if let Some(problem) = static_outside(&world, &def) {
            return Err(ctx.err(b.span(), format!("{field}.position"), problem));
        }
        bodies.push(def);
    }
    if let Some(r) = &raw.world.active_region {
        let focus = r.focus.get_ref();
        if let Some(problem) = shared_name(&names_sorted(&bodies), focus, "the one to follow") {
            return Err(ctx.err(r.focus.span(), "world.active_region.focus", problem));
        }
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
    let script = script(&ctx, &raw, &world, &templates, &bodies, frames)?;
    let tiled = match &raw.tiled {
        None => None,
        Some(t) => Some((tiled::tiled_def(&ctx, t, &world, &templates)?, t.span())),
    };
    let scenario = Scenario {
        name: raw.name.clone().unwrap_or_else(|| {
            std::path::Path::new(file).file_stem().map_or_else(
                || "scenario".to_owned(),
                |s| s.to_string_lossy().into_owned(),
            )
        }),
        world,
        frames,
        templates,
        tiles: Vec::new(),
        bodies,
        script,
    };
    Ok((scenario, tiled))
}

#[cfg(test)]
mod tests {
    use super::load;

    /// Every shipped scenario and every bad one gives the same scenario, or the same error,
    /// parsed a body table at a time as parsed whole.
    #[test]
    fn parsing_body_tables_one_at_a_time_changes_nothing() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        let mut files = Vec::new();
        for dir in ["scenarios", "tests/data/bad-scenarios"] {
            for e in std::fs::read_dir(root.join(dir)).unwrap() {
                let p = e.unwrap().path();
                if p.extension().is_some_and(|x| x == "toml") {
                    files.push(p);
                }
            }
        }
        assert!(files.len() > 30, "{files:?}");
        for p in files {
            let text = std::fs::read_to_string(&p).unwrap();
            let name = p.display().to_string();
            assert_eq!(
                load(&text, &name, true),
                load(&text, &name, false),
                "{name}"
            );
        }
    }
}
