//! The `[world]` table and the top-level settings: timestep, frames, layers and the
//! layer-pair matrix, gravity, bounds, broad phase, sleeping and the active region.

use crate::broad_phase::BroadPhaseKind;
use crate::def::{
    ActiveRegion, Doomed, LayerId, Layers, MAX_FRAMES, Platform, Response, RunLengthError,
    WorldBounds, WorldDef,
};
use crate::limits::{climb_angle_ok, climb_angle_problem};
use crate::load::context::{Ctx, ScenarioError, finite, unknown, vec2};
use crate::load::file::ScenarioFile;
use ricochet_geom::{Number, Numbers};

fn timestep(ctx: &Ctx<'_>, raw: &ScenarioFile) -> Result<f64, ScenarioError> {
    match (&raw.hz, &raw.dt) {
        (Some(h), Some(_)) => Err(ctx.err(h.span(), "hz", "give `hz` or `dt`, not both")),
        (Some(h), None) => {
            let v = *h.get_ref();
            if !(finite(v) && v > 0.0) {
                return Err(ctx.err(
                    h.span(),
                    "hz",
                    format!("must be a finite number > 0, got {}", Number(v)),
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
                    format!("must be a finite number of seconds > 0, got {}", Number(v)),
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
            ("one_way", None) => Response::OneWay(Platform::Second),
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
            ("ignore" | "report" | "separate" | "one_way", Some(_)) => {
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
                    format!(
                        "expected ignore, report, destroy, separate or one_way, got \"{other}\""
                    ),
                ));
            }
        };
        if a == b && matches!(response, Response::OneWay(_)) {
            return Err(ctx.err(
                c.span(),
                format!("{field}.response"),
                format!("a `one_way` pair needs two layers (the second is the platforms'), got \"{}\" twice", r.a),
            ));
        }
        layers.set(a, b, response);
        if let Some(sweep) = r.sweep {
            layers.set_sweep(a, b, sweep);
        }
        if let Some(touches) = r.touches {
            if response == Response::Ignore {
                return Err(ctx.err(
                    c.span(),
                    format!("{field}.touches"),
                    "an `ignore` pair is never tested, so it never touches: leave `touches` out",
                ));
            }
            layers.set_touches(a, b, touches);
        }
    }
    Ok(layers)
}

/// The timestep, frame count and `[world]` settings. The active region's focus is checked
/// later, once the bodies are known.
pub(crate) fn world_settings(
    ctx: &Ctx<'_>,
    raw: &ScenarioFile,
) -> Result<(WorldDef, u64), ScenarioError> {
    let dt = timestep(ctx, raw)?;
    let frames = match &raw.frames {
        None => 600,
        Some(f) => {
            let v = *f.get_ref();
            if u64::try_from(v).is_ok_and(|v| v > MAX_FRAMES) || v < 0 {
                return Err(ctx.err(
                    f.span(),
                    "frames",
                    format!("must be 0 to {MAX_FRAMES}, got {v}"),
                ));
            }
            v.unsigned_abs()
        }
    };
    let layers = layers(ctx, raw)?;
    let mut world = WorldDef {
        dt,
        layers,
        ..WorldDef::default()
    };
    if let Err(e) = world.last_time_ns(frames) {
        // Point at what the user can change: the timestep when it alone can't be logged,
        // else the frame count.
        let step = raw
            .hz
            .as_ref()
            .map(|h| (h.span(), "hz"))
            .or_else(|| raw.dt.as_ref().map(|d| (d.span(), "dt")));
        let at = match (e, &raw.frames) {
            (RunLengthError::TooLong { .. }, Some(f)) => Some((f.span(), "frames")),
            _ => step,
        };
        let (span, field) = at.unwrap_or((0..0, "dt"));
        return Err(ctx.err(span, field, e.to_string()));
    }
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
            "strips" => BroadPhaseKind::Strips,
            "quadtree" => BroadPhaseKind::Quadtree,
            "tree" => BroadPhaseKind::Tree,
            other => {
                return Err(ctx.err(
                    k.span(),
                    "world.broad_phase",
                    format!(
                        "expected auto, brute-force, sort-and-sweep, grid, strips, quadtree or tree, got \"{other}\""
                    ),
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
    if let Some(a) = &raw.world.max_climb_angle {
        let v = *a.get_ref();
        if !climb_angle_ok(v) {
            return Err(ctx.err(a.span(), "world.max_climb_angle", climb_angle_problem(v)));
        }
        world.max_climb_angle = v;
    }
    if let Some(r) = &raw.world.active_region {
        let h = *r.half_extents.get_ref();
        if !h.iter().all(|x| finite(*x) && *x > 0.0) {
            return Err(ctx.err(
                r.half_extents.span(),
                "world.active_region.half_extents",
                format!(
                    "must be finite numbers > 0 on both axes, got {}",
                    Numbers(h)
                ),
            ));
        }
        // The focus is checked once the bodies are known, below.
        world.active_region = Some(ActiveRegion {
            focus: r.focus.get_ref().clone(),
            half_extents: vec2(h),
        });
    }
    Ok((world, frames))
}
