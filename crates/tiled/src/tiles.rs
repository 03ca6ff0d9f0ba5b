//! Tile layers: each tile's shape (its tileset's collision objects, or its whole rectangle,
//! flipped as its gid says), and runs of identical tiles along a row as [`TileRows`], so a
//! dense map costs a few numbers a run rather than a body definition a tile.

use std::collections::BTreeMap;

use ricochet_geom::Vec2;
use ricochet_sim::TileRows;
use tiled::TileLayer;

use crate::TiledError;
use crate::build::{Built, Ctx, Entry, Traits, body_of, tile_outlines};
use crate::{MAX_CELLS, PieceKind};

/// A tile layer as runs of identical tiles along each row, one [`TileRows`] per distinct
/// tile (gid and flips), in first-seen order.
pub(crate) fn tile_layer(
    ctx: &Ctx<'_>,
    layer: &TileLayer<'_>,
    name: &str,
    offset: (f64, f64),
    entries: &[&Entry],
    built: &mut Built,
) -> Result<(), TiledError> {
    let (mtw, mth) = (
        f64::from(ctx.map.tile_width),
        f64::from(ctx.map.tile_height),
    );
    // The cells to visit: a finite layer's grid, or the bounding box of an infinite one's chunks.
    let (x0, y0, w, h) = match layer {
        TileLayer::Finite(f) => (0i64, 0i64, i64::from(f.width()), i64::from(f.height())),
        TileLayer::Infinite(inf) => {
            let mut keys: Vec<(i32, i32)> = inf.chunk_data().map(|(k, _)| k).collect();
            keys.sort_unstable();
            if keys.is_empty() {
                return Ok(());
            }
            let cw = i64::from(tiled::ChunkData::WIDTH);
            let ch = i64::from(tiled::ChunkData::HEIGHT);
            let (mut lx, mut ly, mut hx, mut hy) = (i64::MAX, i64::MAX, i64::MIN, i64::MIN);
            for (cx, cy) in keys {
                lx = lx.min(i64::from(cx) * cw);
                ly = ly.min(i64::from(cy) * ch);
                hx = hx.max(i64::from(cx) * cw + cw);
                hy = hy.max(i64::from(cy) * ch + ch);
            }
            (lx, ly, hx - lx, hy - ly)
        }
    };
    if (w as u64).saturating_mul(h as u64) > MAX_CELLS {
        return Err(ctx.err(
            format!("layer \"{name}\""),
            format!(
                "covers {w} × {h} cells, more than {MAX_CELLS}; split the level into several maps"
            ),
        ));
    }
    let get = |x: i64, y: i64| -> Option<&tiled::LayerTileData> {
        let (x, y) = (x as i32, y as i32);
        match layer {
            TileLayer::Finite(f) => f.get_tile_data(x, y),
            TileLayer::Infinite(i) => i.get_tile_data(x, y),
        }
    };
    type Key = (usize, u32, bool, bool, bool);
    // Per distinct tile: its shape about the centre of cell (0, 0), and its rows.
    let mut kinds: BTreeMap<Key, usize> = BTreeMap::new();
    let mut rows: Vec<(Vec2, TileRows)> = Vec::new();
    let mut skip: BTreeMap<Key, bool> = BTreeMap::new();
    // What each of `rows` becomes.
    let mut row_kinds: Vec<PieceKind> = Vec::new();
    for y in y0..y0 + h {
        let mut run: Option<(Key, i64, u32)> = None;
        let flush = |run: &mut Option<(Key, i64, u32)>,
                     rows: &mut Vec<(Vec2, TileRows)>,
                     kinds: &BTreeMap<Key, usize>| {
            if let Some((key, start, n)) = run.take() {
                let (base, r) = &mut rows[kinds[&key]];
                let at = *base + Vec2::new(start as f64 * mtw * ctx.s, -(y as f64) * mth * ctx.s);
                r.rows.push((at, n));
            }
        };
        for x in x0..x0 + w {
            let Some(t) = get(x, y) else {
                flush(&mut run, &mut rows, &kinds);
                continue;
            };
            let key: Key = (t.tileset_index(), t.id(), t.flip_h, t.flip_v, t.flip_d);
            let at = || format!("layer \"{name}\", tile ({x}, {y})");
            if let std::collections::btree_map::Entry::Vacant(slot) = skip.entry(key) {
                let tileset = &ctx.map.tilesets()[t.tileset_index()];
                if tileset.tilecount > 0 && t.id() >= tileset.tilecount {
                    return Err(ctx.err(at(), format!(
                        "tile {} of tileset \"{}\", which has {} tiles; fix the tileset or the map",
                        t.id(), tileset.name, tileset.tilecount
                    )));
                }
                let entry = tileset.get_tile(t.id());
                let traits = Traits {
                    class: entry.as_ref().map_or("", |e| e.user_type.as_str()),
                    name: "",
                    props: entry.iter().map(|e| &e.properties).collect(),
                };
                let kind = traits.kind(entries);
                slot.insert(kind.is_none());
                if let Some(kind) = kind {
                    // Cell (0, 0)'s tile: drawn with its bottom-left on the cell's, moved by
                    // the tileset's offset.
                    let (tx, ty) = (
                        f64::from(tileset.offset_x) + offset.0,
                        mth - f64::from(tileset.tile_height)
                            + f64::from(tileset.offset_y)
                            + offset.1,
                    );
                    let place = |u: f64, v: f64| ctx.world(tx + u, ty + v);
                    let outs = tile_outlines(
                        entry.as_ref(),
                        tileset,
                        (t.flip_h, t.flip_v, t.flip_d),
                        &place,
                    )
                    .map_err(|p| {
                        ctx.err(
                            at(),
                            format!("tile {} of tileset \"{}\": {p}", t.id(), tileset.name),
                        )
                    })?;
                    let (base, shape) = body_of(&outs).map_err(|p| {
                        ctx.err(
                            at(),
                            format!("tile {} of tileset \"{}\": {p}", t.id(), tileset.name),
                        )
                    })?;
                    kinds.insert(key, rows.len());
                    row_kinds.push(kind);
                    rows.push((
                        base,
                        TileRows {
                            name: name.to_owned(),
                            layer: if kind == PieceKind::OneWay {
                                ctx.def.one_way_layer
                            } else {
                                ctx.def.layer
                            },
                            shape,
                            step: Vec2::new(mtw * ctx.s, 0.0),
                            rows: Vec::new(),
                        },
                    ));
                }
            }
            if skip[&key] {
                flush(&mut run, &mut rows, &kinds);
                continue;
            }
            match &mut run {
                Some((k, start, n)) if *k == key && *start + i64::from(*n) == x => *n += 1,
                _ => {
                    flush(&mut run, &mut rows, &kinds);
                    run = Some((key, x, 1));
                }
            }
        }
        flush(&mut run, &mut rows, &kinds);
    }
    built.tiles.extend(
        row_kinds
            .into_iter()
            .zip(rows)
            .map(|(k, (_, r))| (k, r))
            .filter(|(_, r)| !r.rows.is_empty()),
    );
    Ok(())
}
