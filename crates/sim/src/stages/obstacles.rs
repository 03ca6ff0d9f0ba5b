//! The per-axis passes' obstacle lookups (`separate.rs`): which boxes may stop the box being
//! settled, where they are, and how far a push may go before a static box is in its way.
//!
//! Static boxes come from the tile map (`broad_phase/tile_map.rs`), built once, with their
//! bounds: a million tiles' columns are never read. Kinematic boxes, and dynamic boxes once
//! settled, come from the mover grid rebuilt every pass (`broad_phase/mover_grid.rs`), and
//! only when some settling box may stop on them ([`solid_layers`]). A lookup lists both in
//! dense-index order, which is the order a loop over every body would meet them in.

use ricochet_geom::{Bounds, Primitive, Shape, Vec2};

use crate::broad_phase::{MoverGrid, TileMap};
use crate::def::{LayerId, Layers, Response};
use crate::stages::SLOP;
use crate::world::World;

/// A box that may stop the one being settled: its dense index, bounds and layer (static
/// boxes come from the grid with these, so a million tiles' columns are never read).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Obstacle {
    /// Its dense index.
    pub index: u32,
    /// Its bounds now.
    pub bounds: Bounds,
    /// Its layer.
    pub layer: LayerId,
    /// Whether it may have moved this frame (from the mover grid, not the static one).
    pub moving: bool,
}

/// The exact bounds of box `i`: bit for bit `Shape::bounds`, without its general path for a
/// box on the body origin (the usual case).
pub(crate) fn box_bounds(w: &World, i: usize) -> Bounds {
    match w.shape(i) {
        Shape::Primitive(Primitive::Aabb(b)) if b.center == Vec2::ZERO => {
            // `position + 0` is `position` (up to the sign of a zero, which compares equal).
            Bounds::around(w.position[i], b.half_extents)
        }
        s => s.bounds(&w.pose(i)),
    }
}

/// Body `i`'s bounds if its shape is a single box ([`box_bounds`]), `None` otherwise: one
/// look at the shape for both questions.
pub(crate) fn bounds_if_box(w: &World, i: usize) -> Option<Bounds> {
    match w.shape(i) {
        Shape::Primitive(Primitive::Aabb(b)) if b.center == Vec2::ZERO => {
            Some(Bounds::around(w.position[i], b.half_extents))
        }
        s @ Shape::Primitive(Primitive::Aabb(_)) => Some(s.bounds(&w.pose(i))),
        _ => None,
    }
}

/// The half extents of box `i` when it sits on its body's origin: then its bounds are
/// `Bounds::around(position, half)` ([`box_bounds`]).
pub(crate) fn on_origin(w: &World, i: usize) -> Option<Vec2> {
    match w.shape(i) {
        Shape::Primitive(Primitive::Aabb(b)) if b.center == Vec2::ZERO => Some(b.half_extents),
        _ => None,
    }
}

/// How much `a` and `b` overlap along `axis` (negative when apart).
pub(crate) fn overlap(a: &Bounds, b: &Bounds, axis: usize) -> f64 {
    a.max[axis].min(b.max[axis]) - a.min[axis].max(b.min[axis])
}

/// The dense index of the static body of rank `s` among the static bodies: `s` plus the
/// moving bodies before it. `movers` are the moving bodies' dense indices, ascending, so
/// mover `k` has `movers[k] - k` static bodies before it (a non-decreasing count).
pub(crate) fn static_index(movers: &[u32], s: u32) -> u32 {
    // Usually every static body comes first (a level's tiles before its actors).
    if movers.first().is_none_or(|&m| m > s) {
        return s;
    }
    let (mut lo, mut hi) = (0, movers.len());
    while lo < hi {
        let mid = usize::midpoint(lo, hi);
        if movers[mid] - mid as u32 <= s {
            lo = mid + 1;
        } else {
            hi = mid;
        }
    }
    s + lo as u32
}

/// Every body that may be an obstacle for a box with bounds `q`, as dense indices from
/// `from` on, ascending and without repeats, into `found`.
pub(crate) fn obstacles(
    (statics, movers): (&TileMap, &MoverGrid),
    w: &World,
    q: &Bounds,
    from: u32,
    found: &mut Vec<Obstacle>,
) {
    found.clear();
    let moving = w.movers();
    statics.query(q, |s, bounds, layer| {
        let index = static_index(moving, s);
        if index >= from {
            found.push(Obstacle {
                index,
                bounds: *bounds,
                layer,
                moving: false,
            });
        }
    });
    if movers.is_empty() {
        return finish(found);
    }
    movers.query(q, |i| {
        if i >= from {
            found.push(Obstacle {
                index: i,
                bounds: box_bounds(w, i as usize),
                layer: w.layer[i as usize],
                moving: true,
            });
        }
    });
    finish(found);
}

/// Sorts the obstacles found by index and drops repeats.
fn finish(found: &mut Vec<Obstacle>) {
    found.sort_unstable_by_key(|o| o.index);
    found.dedup_by_key(|o| o.index);
}

/// By layer, whether a box of it may stop one of the pass's settling boxes (`order`): some
/// settling box's layer `separate`s from it.
pub(crate) fn solid_layers(
    w: &World,
    layers: &Layers,
    order: impl Iterator<Item = u32>,
) -> Vec<bool> {
    let n = layers.names().len();
    let mut settling = vec![false; n];
    for i in order {
        settling[usize::from(w.layer[i as usize])] = true;
    }
    (0..n)
        .map(|m| {
            (0..n).any(|l| settling[l] && layers.response(l as u8, m as u8) == Response::Separate)
        })
        .collect()
}

/// Statics win: the push `by` along `axis` that moves box `i` (bounds `bi`) out of the
/// dynamic box `bj` by the smaller overlap, unless a static box is in its way; then out of
/// `bj`'s other side if that way is clear, else as far as the first static box lets it go
/// (flush on it, still overlapping `bj`: a push from another dynamic body never moves a box
/// into a static one, as along the normal, `push.rs`).
pub(crate) fn statics_win(
    statics: &TileMap,
    (w, layers): (&World, &Layers),
    (i, bi, bj): (usize, &Bounds, &Bounds),
    axis: usize,
    by: f64,
) -> f64 {
    let allowed = clear_way(statics, (w, layers), (i, bi), axis, by);
    if allowed.to_bits() == by.to_bits() {
        return by;
    }
    let other_way = if by < 0.0 {
        bj.max[axis] - bi.min[axis]
    } else {
        -(bi.max[axis] - bj.min[axis])
    };
    if clear_way(statics, (w, layers), (i, bi), axis, other_way).to_bits() == other_way.to_bits() {
        return other_way;
    }
    allowed
}

/// How much of the move `by` along `axis` box `i` (bounds `bi`) can make before it meets a
/// static box it `separate`s from: one ahead of it, overlapping its span on the other axis
/// by more than [`SLOP`] (a static box it overlaps now is not in its way: the pass pushes it
/// out of that one at its turn).
fn clear_way(
    statics: &TileMap,
    (w, layers): (&World, &Layers),
    (i, bi): (usize, &Bounds),
    axis: usize,
    by: f64,
) -> f64 {
    let other = 1 - axis;
    let mut path = *bi;
    if by < 0.0 {
        path.min[axis] += by;
    } else {
        path.max[axis] += by;
    }
    let mut allowed = by;
    statics.query(&path, |_, b, layer| {
        if layers.response(w.layer[i], layer) != Response::Separate || overlap(bi, b, other) <= SLOP
        {
            return;
        }
        let gap = if by < 0.0 {
            bi.min[axis] - b.max[axis]
        } else {
            b.min[axis] - bi.max[axis]
        };
        if gap < -SLOP {
            return;
        }
        let room = gap.max(0.0);
        allowed = if by < 0.0 {
            allowed.max(-room)
        } else {
            allowed.min(room)
        };
    });
    allowed
}
