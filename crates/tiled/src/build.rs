//! A loaded map → tile rows, solid pieces and spawns. Tiled's pixels (y down, origin at the
//! map's top-left) become world units: `x = px * s`, `y = (map height in px - py) * s`, with
//! `s = units_per_tile / tile width in px`, so the map's bottom-left corner is at (0, 0).

use std::collections::BTreeMap;

use ricochet_geom::{Primitive, Shape, Vec2};
use ricochet_sim::{BodyDef, TileRows, TiledDef};
use tiled::{LayerType, ObjectData, ObjectShape, PropertyValue};

use crate::objects::{object_outlines, spawn};
use crate::shapes::{ELLIPSE_POINTS, Outline, chains, primitives};
use crate::{MAX_ELLIPSE_RATIO, MAX_POLYGON_POINTS, MapSummary, PieceKind, TiledError, TiledPiece};

/// What a map became.
pub(crate) struct Built {
    /// Tile rows, each with what its tiles become.
    pub(crate) tiles: Vec<(PieceKind, TileRows)>,
    pub(crate) pieces: Vec<TiledPiece>,
    pub(crate) spawns: Vec<BodyDef>,
    pub(crate) spawned: BTreeMap<String, usize>,
}

impl Built {
    pub(crate) fn summary(&self) -> MapSummary {
        MapSummary {
            tiles: self
                .tiles
                .iter()
                .filter(|t| t.0 == PieceKind::Solid)
                .map(|t| t.1.len())
                .sum(),
            solids: self
                .pieces
                .iter()
                .filter(|p| p.kind == PieceKind::Solid)
                .count(),
            one_way: self
                .pieces
                .iter()
                .filter(|p| p.kind == PieceKind::OneWay)
                .count()
                + self
                    .tiles
                    .iter()
                    .filter(|t| t.0 == PieceKind::OneWay)
                    .map(|t| t.1.len())
                    .sum::<usize>(),
            chains: self
                .pieces
                .iter()
                .filter(|p| p.kind == PieceKind::Chain)
                .count(),
            spawns: self.spawned.clone(),
        }
    }
}

/// One `solid` or `one_way` entry: `LAYER`, `LAYER?PROP` or `LAYER?PROP=VALUE`.
pub(crate) struct Entry {
    /// What the shapes it takes become.
    kind: PieceKind,
    layer: String,
    prop: Option<String>,
    value: Option<String>,
    used: bool,
}

impl Entry {
    fn parse(s: &str, kind: PieceKind) -> Entry {
        let (layer, filter) = s.split_once('?').map_or((s, None), |(l, f)| (l, Some(f)));
        let (prop, value) = match filter {
            None => (None, None),
            Some(f) => match f.split_once('=') {
                Some((p, v)) => (Some(p.to_owned()), Some(v.to_owned())),
                None => (Some(f.to_owned()), None),
            },
        };
        Entry {
            kind,
            layer: layer.to_owned(),
            prop,
            value,
            used: false,
        }
    }
}

/// What a tile or an object is known by, for the filters: its class (or type), its name, and
/// its properties, the first source that has one winning (object, template, tileset entry).
pub(crate) struct Traits<'a> {
    pub(crate) class: &'a str,
    pub(crate) name: &'a str,
    pub(crate) props: Vec<&'a tiled::Properties>,
}

fn value_text(v: &PropertyValue) -> Option<String> {
    Some(match v {
        PropertyValue::BoolValue(b) => b.to_string(),
        PropertyValue::FloatValue(f) => f.to_string(),
        PropertyValue::IntValue(i) => i.to_string(),
        PropertyValue::StringValue(s) | PropertyValue::FileValue(s) => s.clone(),
        PropertyValue::ObjectValue(o) => o.to_string(),
        _ => return None,
    })
}

impl Traits<'_> {
    /// What the first entry that takes this tile or object makes of it (`solid` entries
    /// come first: a shape both list is solid), or `None`.
    pub(crate) fn kind(&self, entries: &[&Entry]) -> Option<PieceKind> {
        entries.iter().find(|e| self.takes(e)).map(|e| e.kind)
    }

    fn takes(&self, e: &Entry) -> bool {
        {
            let Some(prop) = &e.prop else { return true };
            let found: Option<String> = match prop.as_str() {
                "class" | "type" => Some(self.class.to_owned()),
                "name" => Some(self.name.to_owned()),
                _ => self
                    .props
                    .iter()
                    .find_map(|p| p.get(prop.as_str()))
                    .and_then(value_text),
            };
            match (&e.value, found) {
                (Some(v), Some(f)) => *v == f,
                (None, Some(f)) => f == "true",
                (_, None) => false,
            }
        }
    }
}

pub(crate) struct Ctx<'a> {
    pub(crate) map: &'a tiled::Map,
    pub(crate) def: &'a TiledDef,
    pub(crate) templates: &'a BTreeMap<String, BodyDef>,
    pub(crate) file: &'a str,
    /// World units per pixel.
    pub(crate) s: f64,
    /// The map's height in pixels.
    pub(crate) h_px: f64,
}

impl Ctx<'_> {
    pub(crate) fn world(&self, px: f64, py: f64) -> Vec2 {
        Vec2::new(px * self.s, (self.h_px - py) * self.s)
    }

    pub(crate) fn err(&self, place: String, problem: impl Into<String>) -> TiledError {
        TiledError {
            file: self.file.to_owned(),
            place,
            problem: problem.into(),
        }
    }
}

/// An object's outlines, its local point `(u, v)` (pixels from its anchor, in its own
/// rotated frame, y down) mapped to the world by `to_world` after the object's rotation.
pub(crate) fn outlines(
    obj: &ObjectData,
    to_world: &dyn Fn(f64, f64) -> Vec2,
) -> Result<Vec<Outline>, String> {
    let (sin, cos) = (
        libm::sin(f64::from(obj.rotation).to_radians()),
        libm::cos(f64::from(obj.rotation).to_radians()),
    );
    let (x, y) = (f64::from(obj.x), f64::from(obj.y));
    let f = |u: f64, v: f64| to_world(x + u * cos - v * sin, y + u * sin + v * cos);
    let size = |w: f32, h: f32| -> Result<(f64, f64), String> {
        if w > 0.0 && h > 0.0 {
            Ok((f64::from(w), f64::from(h)))
        } else {
            Err(format!(
                "its size {w} × {h} px has no area; give it a width and a height"
            ))
        }
    };
    Ok(match &obj.shape {
        ObjectShape::Rect { width, height } => {
            let (w, h) = size(*width, *height)?;
            vec![Outline::Ring(vec![
                f(0.0, 0.0),
                f(w, 0.0),
                f(w, h),
                f(0.0, h),
            ])]
        }
        ObjectShape::Ellipse { width, height } => {
            let (w, h) = size(*width, *height)?;
            let c = f(w / 2.0, h / 2.0);
            let (ax, ay) = (f(w, h / 2.0) - c, f(w / 2.0, h) - c);
            let (long, short) = (ax.length().max(ay.length()), ax.length().min(ay.length()));
            if (long - short) <= 1e-12 * long && ax.dot(ay).abs() <= 1e-9 * long * long {
                vec![Outline::Circle {
                    center: c,
                    radius: long,
                }]
            } else if long > MAX_ELLIPSE_RATIO * short {
                return Err(format!(
                    "an ellipse {w} × {h} px is more than {MAX_ELLIPSE_RATIO} times longer than \
                     wide: its polygon would stray more than 5% of its width; draw it as a \
                     rectangle or polygon"
                ));
            } else {
                let ring = (0..ELLIPSE_POINTS)
                    .map(|k| {
                        let t = 2.0 * std::f64::consts::PI * k as f64 / ELLIPSE_POINTS as f64;
                        f(
                            w / 2.0 * (1.0 + libm::cos(t)),
                            h / 2.0 * (1.0 + libm::sin(t)),
                        )
                    })
                    .collect();
                vec![Outline::Ring(ring)]
            }
        }
        ObjectShape::Capsule { width, height } => {
            let (w, h) = size(*width, *height)?;
            let r = w.min(h) / 2.0;
            let (a, b) = if w >= h {
                ((r, r), (w - r, r))
            } else {
                ((r, r), (r, h - r))
            };
            let (a, b) = (f(a.0, a.1), f(b.0, b.1));
            let radius = (f(r, 0.0) - f(0.0, 0.0)).length();
            if a == b {
                vec![Outline::Circle { center: a, radius }]
            } else {
                vec![Outline::Capsule { a, b, radius }]
            }
        }
        ObjectShape::Polygon { points } => {
            if points.len() > MAX_POLYGON_POINTS {
                return Err(format!(
                    "a polygon of {} points; at most {MAX_POLYGON_POINTS}: split it",
                    points.len()
                ));
            }
            vec![Outline::Ring(
                points
                    .iter()
                    .map(|&(u, v)| f(f64::from(u), f64::from(v)))
                    .collect(),
            )]
        }
        ObjectShape::Polyline { points } => vec![Outline::Line(
            points
                .iter()
                .map(|&(u, v)| f(f64::from(u), f64::from(v)))
                .collect(),
        )],
        ObjectShape::Point(..) => {
            return Err(
                "a point has no area: give it a class, type or name listed in \
                        [tiled.spawn], or move it out of the solid layer"
                    .to_owned(),
            );
        }
        ObjectShape::Text { .. } => {
            return Err(
                "a text object has no collision shape; move it out of the solid layer".to_owned(),
            );
        }
    })
}

/// A tile's outlines: its tileset's collision objects, or its whole rectangle; `place` maps a
/// tile-local pixel (from its top-left, y down, after the flips) to the world.
pub(crate) fn tile_outlines(
    tile: Option<&tiled::Tile<'_>>,
    tileset: &tiled::Tileset,
    flips: (bool, bool, bool),
    place: &dyn Fn(f64, f64) -> Vec2,
) -> Result<Vec<Outline>, String> {
    let (fh, fv, fd) = flips;
    let (tw, th) = (
        f64::from(tileset.tile_width),
        f64::from(tileset.tile_height),
    );
    let (ww, hh) = if fd { (th, tw) } else { (tw, th) };
    // Tiled flips the diagonal first, then horizontally, then vertically.
    let flip = |u: f64, v: f64| {
        let (u, v) = if fd { (v, u) } else { (u, v) };
        place(if fh { ww - u } else { u }, if fv { hh - v } else { v })
    };
    let objects = tile
        .and_then(|t| t.collision.as_ref())
        .map(|c| c.object_data());
    match objects {
        Some(objects) if !objects.is_empty() => {
            let mut all = Vec::new();
            for o in objects {
                all.extend(
                    outlines(o, &flip).map_err(|e| format!("collision object {}: {e}", o.id()))?,
                );
            }
            Ok(all)
        }
        _ => Ok(vec![Outline::Ring(vec![
            flip(0.0, 0.0),
            flip(tw, 0.0),
            flip(tw, th),
            flip(0.0, th),
        ])]),
    }
}

fn shape_of(parts: Vec<Primitive>) -> Result<Shape, String> {
    if parts.len() == 1 {
        Ok(Shape::Primitive(parts[0]))
    } else {
        Shape::compound(parts).map_err(|e| e.to_string())
    }
}

/// The outlines' body: its position (the centre of their bounds) and shape.
pub(crate) fn body_of(outs: &[Outline]) -> Result<(Vec2, Shape), String> {
    let mut lo = Vec2::splat(f64::INFINITY);
    let mut hi = Vec2::splat(f64::NEG_INFINITY);
    for o in outs {
        let pts: Vec<Vec2> = match o {
            Outline::Circle { center, radius }
            | Outline::Capsule {
                a: center, radius, ..
            } => {
                let mut v = vec![
                    *center - Vec2::splat(*radius),
                    *center + Vec2::splat(*radius),
                ];
                if let Outline::Capsule { b, .. } = o {
                    v.push(*b - Vec2::splat(*radius));
                    v.push(*b + Vec2::splat(*radius));
                }
                v
            }
            Outline::Ring(r) | Outline::Line(r) => r.clone(),
        };
        for p in pts {
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    let origin = (lo + hi) * 0.5;
    let mut parts = Vec::new();
    for o in outs {
        parts.extend(primitives(o, origin)?);
    }
    Ok((origin, shape_of(parts)?))
}

/// Builds the level: every layer a `solid` entry names, and every object [tiled.spawn] names.
pub(crate) fn build(
    map: &tiled::Map,
    def: &TiledDef,
    templates: &BTreeMap<String, BodyDef>,
    file: &str,
) -> Result<Built, TiledError> {
    let mut ctx = Ctx {
        map,
        def,
        templates,
        file,
        s: def.units_per_tile / f64::from(map.tile_width.max(1)),
        h_px: f64::from(map.height) * f64::from(map.tile_height),
    };
    if map.orientation != tiled::Orientation::Orthogonal {
        return Err(ctx.err("map".to_owned(), format!(
            "a {:?} map: only orthogonal maps are supported; change Map > Map Properties > Orientation",
            map.orientation
        )));
    }
    if map.tile_width == 0 || map.tile_height == 0 {
        return Err(ctx.err(
            "map".to_owned(),
            "its tiles have no size (tilewidth or tileheight is 0)",
        ));
    }
    ctx.s = def.units_per_tile / f64::from(map.tile_width);
    let mut entries: Vec<Entry> = def
        .solid
        .iter()
        .map(|s| Entry::parse(s, PieceKind::Solid))
        .chain(
            def.one_way
                .iter()
                .map(|s| Entry::parse(s, PieceKind::OneWay)),
        )
        .collect();
    let mut built = Built {
        tiles: Vec::new(),
        pieces: Vec::new(),
        spawns: Vec::new(),
        spawned: BTreeMap::new(),
    };
    let mut names = Vec::new();
    for layer in map.layers() {
        walk(
            &ctx,
            layer,
            (0.0, 0.0),
            &mut entries,
            &[],
            &mut built,
            &mut names,
        )?;
    }
    if let Some(e) = entries.iter().find(|e| !e.used) {
        return Err(ctx.err(
            format!(
                "[tiled] {} entry for layer \"{}\"",
                if e.kind == PieceKind::OneWay {
                    "one_way"
                } else {
                    "solid"
                },
                e.layer
            ),
            format!(
                "the map has no layer named \"{}\"; its layers: {}",
                e.layer,
                if names.is_empty() {
                    "none".to_owned()
                } else {
                    names.join(", ")
                }
            ),
        ));
    }
    Ok(built)
}

fn walk(
    ctx: &Ctx<'_>,
    layer: tiled::Layer<'_>,
    offset: (f64, f64),
    entries: &mut [Entry],
    inherited: &[usize],
    built: &mut Built,
    names: &mut Vec<String>,
) -> Result<(), TiledError> {
    let offset = (
        offset.0 + f64::from(layer.offset_x),
        offset.1 + f64::from(layer.offset_y),
    );
    names.push(format!("\"{}\"", layer.name));
    for e in entries.iter_mut() {
        if e.layer == layer.name {
            e.used = true;
        }
    }
    // This layer's entries: those naming it, and those naming a group it is in.
    let mut mine_idx: Vec<usize> = inherited.to_vec();
    mine_idx.extend((0..entries.len()).filter(|&i| entries[i].layer == layer.name));
    let mine: Vec<&Entry> = mine_idx.iter().map(|&i| &entries[i]).collect();
    let place = format!("layer \"{}\"", layer.name);
    match layer.layer_type() {
        LayerType::Group(g) => {
            for child in g.layers() {
                walk(ctx, child, offset, entries, &mine_idx, built, names)?;
            }
        }
        LayerType::Objects(objects) => {
            for obj in objects.objects() {
                let at = format!("{place}, object {} \"{}\"", obj.id(), obj.name);
                if let Some(t) = ctx
                    .def
                    .spawn
                    .get(&obj.user_type)
                    .or_else(|| ctx.def.spawn.get(&obj.name))
                {
                    spawn(ctx, &obj, t, offset, built).map_err(|p| ctx.err(at.clone(), p))?;
                    continue;
                }
                if mine.is_empty() {
                    continue;
                }
                let tile = obj.get_tile();
                let tile_entry = tile.as_ref().and_then(|t| t.get_tile());
                let mut props = vec![&obj.properties];
                if let Some(t) = &tile_entry {
                    props.push(&t.properties);
                }
                let class = if obj.user_type.is_empty() {
                    tile_entry.as_ref().map_or("", |t| t.user_type.as_str())
                } else {
                    obj.user_type.as_str()
                };
                let traits = Traits {
                    class,
                    name: &obj.name,
                    props,
                };
                let Some(kind) = traits.kind(&mine) else {
                    continue;
                };
                let outs =
                    object_outlines(ctx, &obj, offset).map_err(|p| ctx.err(at.clone(), p))?;
                let name = if obj.name.is_empty() {
                    layer.name.clone()
                } else {
                    obj.name.clone()
                };
                if let [Outline::Line(points)] = outs.as_slice() {
                    if kind == PieceKind::OneWay {
                        return Err(ctx.err(
                            at,
                            "a polyline in a `one_way` entry: a one-way platform is a ledge \
                             (its top is its bounding box's), not a line; draw a rectangle, \
                             or list the layer in `solid` to make the polyline a chain",
                        ));
                    }
                    for (position, shape) in chains(points).map_err(|p| ctx.err(at.clone(), p))? {
                        built.pieces.push(TiledPiece {
                            kind: PieceKind::Chain,
                            name: name.clone(),
                            shape,
                            position,
                        });
                    }
                    continue;
                }
                let (position, shape) = body_of(&outs).map_err(|p| ctx.err(at.clone(), p))?;
                built.pieces.push(TiledPiece {
                    kind,
                    name,
                    shape,
                    position,
                });
            }
        }
        LayerType::Tiles(tiles) if !mine.is_empty() => {
            crate::tiles::tile_layer(ctx, &tiles, &layer.name, offset, &mine, built)?;
        }
        LayerType::Tiles(_) => {}
        LayerType::Image(_) if !mine.is_empty() => {
            return Err(ctx.err(
                place,
                "an image layer has no collision shapes; list a tile or object layer in `solid`",
            ));
        }
        LayerType::Image(_) => {}
    }
    Ok(())
}
