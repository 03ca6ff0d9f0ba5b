//! `[tiled]`: checked here as far as the scenario alone can say (its layer, templates and
//! scale); the map itself is read by `ricochet-tiled`, since this crate does no I/O.

use std::collections::BTreeMap;

use super::context::{Ctx, unknown};
use super::file::TiledFile;
use crate::check::ScenarioError;
use crate::def::{BodyDef, Platform, Response, WorldDef};
use crate::scenario::TiledDef;
use toml::Spanned;

/// The `[tiled]` table as plain data, or the first problem with it.
pub(super) fn tiled_def(
    ctx: &Ctx<'_>,
    raw: &Spanned<TiledFile>,
    world: &WorldDef,
    templates: &BTreeMap<String, BodyDef>,
) -> Result<TiledDef, ScenarioError> {
    let t = raw.get_ref();
    let layer = world.layers.id(t.layer.get_ref()).ok_or_else(|| {
        unknown(
            ctx,
            t.layer.span(),
            "tiled.layer".to_owned(),
            "layer",
            t.layer.get_ref(),
            world.layers.names().iter(),
        )
    })?;
    let units_per_tile = match &t.units_per_tile {
        None => 1.0,
        Some(u) => {
            let v = *u.get_ref();
            // A tile must stay a valid shape: at least `MIN_SIZE`, at most `MAX_COORDINATE`.
            if !(v.is_finite() && v > 0.0 && v <= 1e6) {
                return Err(ctx.err(
                    u.span(),
                    "tiled.units_per_tile",
                    format!("must be a number above 0 and at most 1e6, got {v}"),
                ));
            }
            v
        }
    };
    if t.map.get_ref().is_empty() {
        return Err(ctx.err(
            t.map.span(),
            "tiled.map",
            "name the map file (.tmx, .tmj or .json), relative to the scenario file",
        ));
    }
    let mut spawn = BTreeMap::new();
    for (key, template) in &t.spawn {
        if !templates.contains_key(template.get_ref()) {
            return Err(unknown(
                ctx,
                template.span(),
                format!("tiled.spawn.{key}"),
                "template",
                template.get_ref(),
                templates.keys(),
            ));
        }
        spawn.insert(key.clone(), template.get_ref().clone());
    }
    let entries = |list: &[Spanned<String>], what: &str| -> Result<Vec<String>, ScenarioError> {
        list.iter()
            .enumerate()
            .map(|(i, e)| {
                let s = e.get_ref();
                let layer = s.split('?').next().unwrap_or_default();
                if layer.is_empty() || s.matches('?').count() > 1 || s.ends_with('?') {
                    return Err(ctx.err(
                        e.span(),
                        format!("tiled.{what}[{i}]"),
                        format!(
                            "\"{s}\" is not LAYER, LAYER?PROP or LAYER?PROP=VALUE (a map layer's \
                             name, optionally a property its tiles or objects must have)"
                        ),
                    ));
                }
                Ok(s.clone())
            })
            .collect()
    };
    let one_way = entries(&t.one_way, "one_way")?;
    let one_way_layer = match (&t.one_way_layer, t.one_way.first()) {
        (None, None) => layer,
        (None, Some(first)) => {
            return Err(ctx.err(
                first.span(),
                "tiled.one_way_layer",
                "`one_way` lists map layers: say which scenario layer their platforms go to \
                 with `one_way_layer = \"...\"` (the second layer of a `one_way` [[collide]] pair)",
            ));
        }
        (Some(l), _) => {
            let id = world.layers.id(l.get_ref()).ok_or_else(|| {
                unknown(
                    ctx,
                    l.span(),
                    "tiled.one_way_layer".to_owned(),
                    "layer",
                    l.get_ref(),
                    world.layers.names().iter(),
                )
            })?;
            let n = world.layers.names().len();
            let platform = (0..n)
                .any(|a| world.layers.response(a as u8, id) == Response::OneWay(Platform::Second));
            if !platform {
                return Err(ctx.err(
                    l.span(),
                    "tiled.one_way_layer",
                    format!(
                        "no [[collide]] pair makes layer \"{}\" one-way: add one with \
                         response = \"one_way\" and b = \"{}\"",
                        l.get_ref(),
                        l.get_ref()
                    ),
                ));
            }
            id
        }
    };
    Ok(TiledDef {
        map: t.map.get_ref().clone(),
        units_per_tile,
        solid: entries(&t.solid, "solid")?,
        one_way,
        layer,
        one_way_layer,
        spawn,
    })
}
