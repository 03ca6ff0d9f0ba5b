//! After a box's per-axis pass (`separate.rs`): whether it still rides what it rode into
//! the frame, and whether a kinematic box that moved it left it no room (riders:
//! `stages/carry.rs`).

use crate::broad_phase::{MoverGrid, TileMap};
use crate::def::{BodyKind, Layers, Response};
use crate::entity::Entity;
use crate::event::GameEvent;
use crate::stages::obstacles::{Obstacle, box_bounds, obstacles, overlap};
use crate::stages::{SLOP, carry};
use crate::world::World;

/// After box `i`'s pass along `axis` (riders: `stages/carry.rs`). In `resolve_y`, a box that
/// nothing pushed up keeps `old_carrier` if it still rests on it flush. Then, if a kinematic
/// box moved it this frame (`pushed_by`, the first that pushed it in this pass, or the
/// kinematic carrier it rode into the frame), and it still overlaps a static or kinematic
/// box by more than [`SLOP`] on both axes, it had no room: the [`GameEvent::Crushed`] to
/// raise. It is left where the pushes put it; the game decides.
///
/// Always in line for the usual case (a box that rode nothing and that no kinematic body
/// pushed: nothing to do), which is a call a box and axis otherwise: whether the compiler
/// inlined it moved with how it cut the crate, by 50,000 instructions a frame at
/// platformer-10000-1000.
#[inline(always)]
pub(crate) fn rider(
    w: &mut World,
    layers: &Layers,
    lookup: (&TileMap, &MoverGrid),
    found: &mut Vec<Obstacle>,
    at: (usize, usize),
    (old_carrier, pushed_by): (Option<Entity>, Option<usize>),
) -> Option<GameEvent> {
    if old_carrier.is_none() && pushed_by.is_none() {
        return None;
    }
    rode(w, layers, lookup, found, at, (old_carrier, pushed_by))
}

/// [`rider`] of a box that rode something or that a kinematic body pushed.
fn rode(
    w: &mut World,
    layers: &Layers,
    lookup: (&TileMap, &MoverGrid),
    found: &mut Vec<Obstacle>,
    (i, axis): (usize, usize),
    (old_carrier, pushed_by): (Option<Entity>, Option<usize>),
) -> Option<GameEvent> {
    let bi = box_bounds(w, i);
    if axis == 1
        && w.carrier(i).is_none()
        && let Some(c) = old_carrier.and_then(|e| w.index_of(e))
        && carry::still_rides(&bi, &box_bounds(w, c))
    {
        *w.carrier_mut(i) = old_carrier;
    }
    let by = pushed_by.or_else(|| carry::kinematic_root(w, old_carrier))?;
    obstacles(lookup, w, &bi, 0, found);
    let no_room = found.iter().any(|o| {
        let j = o.index as usize;
        j != i
            && w.kind[j] != BodyKind::Dynamic
            && layers.response(w.layer[i], o.layer) == Response::Separate
            && overlap(&bi, &o.bounds, 0) > SLOP
            && overlap(&bi, &o.bounds, 1) > SLOP
    });
    no_room.then(|| GameEvent::Crushed {
        body: w.entity[i],
        by: w.entity[by],
        axis: axis as u8,
    })
}
