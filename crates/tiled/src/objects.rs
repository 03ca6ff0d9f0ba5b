//! A map's objects, one at a time: the outlines of a shape or tile object in world units, and
//! an object named in `[tiled.spawn]` as a body of its template (`build.rs` walks the layers).

use ricochet_sim::BodyDef;
use tiled::ObjectShape;

use crate::build::{Built, Ctx, outlines, tile_outlines};
use crate::shapes::Outline;

/// A map object's outlines (a tile object: its tile's, stretched to the object's size; its
/// anchor is its bottom-left corner).
pub(crate) fn object_outlines(
    ctx: &Ctx<'_>,
    obj: &tiled::Object<'_>,
    offset: (f64, f64),
) -> Result<Vec<Outline>, String> {
    let to_world = |px: f64, py: f64| ctx.world(px + offset.0, py + offset.1);
    let Some(tile) = obj.get_tile() else {
        return outlines(obj, &to_world);
    };
    let data = obj.tile_data().expect("a tile object has tile data");
    let tileset = tile.get_tileset();
    let entry = tile.get_tile();
    let (tw, th) = (
        f64::from(tileset.tile_width),
        f64::from(tileset.tile_height),
    );
    let (w, h) = match obj.shape {
        ObjectShape::Rect { width, height } if width > 0.0 && height > 0.0 => {
            (f64::from(width), f64::from(height))
        }
        _ => (tw, th),
    };
    let (sin, cos) = (
        libm::sin(f64::from(obj.rotation).to_radians()),
        libm::cos(f64::from(obj.rotation).to_radians()),
    );
    let (x, y) = (f64::from(obj.x), f64::from(obj.y));
    let place = |u: f64, v: f64| {
        // Tile pixels → the object's frame (anchor bottom-left), then rotated about it.
        let (lu, lv) = (u * w / tw, v * h / th - h);
        to_world(x + lu * cos - lv * sin, y + lu * sin + lv * cos)
    };
    tile_outlines(
        entry.as_ref(),
        tileset,
        (data.flip_h, data.flip_v, data.flip_d),
        &place,
    )
}

/// A spawn object: a body of `template` at the centre of the object's box.
pub(crate) fn spawn(
    ctx: &Ctx<'_>,
    obj: &tiled::Object<'_>,
    template: &str,
    offset: (f64, f64),
    built: &mut Built,
) -> Result<(), String> {
    let (w, h) = match obj.shape {
        ObjectShape::Rect { width, height }
        | ObjectShape::Ellipse { width, height }
        | ObjectShape::Capsule { width, height } => (f64::from(width), f64::from(height)),
        _ => (0.0, 0.0),
    };
    // The centre of the object's box: a tile object's anchor is its bottom-left corner.
    let (u, v) = if obj.get_tile().is_some() {
        (w / 2.0, -h / 2.0)
    } else {
        (w / 2.0, h / 2.0)
    };
    let (sin, cos) = (
        libm::sin(f64::from(obj.rotation).to_radians()),
        libm::cos(f64::from(obj.rotation).to_radians()),
    );
    let (x, y) = (f64::from(obj.x) + offset.0, f64::from(obj.y) + offset.1);
    let position = ctx.world(x + u * cos - v * sin, y + u * sin + v * cos);
    let Some(base) = ctx.templates.get(template) else {
        return Err(format!(
            "[tiled.spawn] names template \"{template}\", which the scenario lacks"
        ));
    };
    built.spawns.push(BodyDef {
        position,
        ..base.clone()
    });
    *built.spawned.entry(template.to_owned()).or_insert(0) += 1;
    Ok(())
}
