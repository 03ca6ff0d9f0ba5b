//! Riders: a box standing on a moving box moves with it, Celeste- and TowerFall-style
//! ("solids carry riders and push actors").
//!
//! - **Who rides what.** `resolve_y` records each dynamic box's *carrier*
//!   ([`World::carrier`]): the kinematic or dynamic box that pushed it up last in the pass,
//!   or, when nothing pushed it up, the carrier it still rests on flush ([`still_rides`]).
//!   A static body carries nothing (it never moves), so standing on one records `None`. A
//!   box frozen by the active region, put to sleep or teleported rides nothing until a
//!   `resolve_y` finds what it stands on again.
//! - **Carried.** In the next frame's `move_x` and `move_y`, before its own `v * dt`, a rider
//!   moves by its carrier's displacement along the axis ([`displacement`]): the same
//!   `v * dt` the kinematic carrier adds to its own position in that stage, so a rider keeps
//!   its offset from the carrier. A box on a dynamic box rides whatever that box rides (a
//!   crate on a crate on a lift goes with the lift); a dynamic carrier's own motion does not
//!   carry (only solids carry).
//! - **Pushed and crushed.** A kinematic box moving into a dynamic one pushes it out in the
//!   per-axis pass, like any obstacle. A box a kinematic body pushed or carried this frame
//!   that still overlaps a static or kinematic box after its pass has no room: the pass
//!   raises [`crate::GameEvent::Crushed`] (`separate.rs`) and leaves the box where the
//!   pushes left it; the game decides what happens to it.
//!
//! Everything here reads velocities and entities, never the order bodies are visited in, so
//! it is deterministic whatever the order of the loops that call it.

use ricochet_geom::Bounds;

use crate::def::BodyKind;
use crate::entity::Entity;
use crate::world::World;

/// How many carriers a chain of riders is followed through (a crate on a crate on ... on a
/// lift). Carriers are recorded bottom-up in one pass, so a chain never loops; the bound
/// only guards against a stale record.
const MAX_CHAIN: usize = 64;

/// The kinematic body at the bottom of the chain of carriers that starts at `carrier` (a
/// box's [`World::carrier`]), if it moves this frame (neither frozen nor asleep), as a dense
/// index. `None` for no carrier, one that is gone, frozen or asleep, or a chain that ends on
/// no kinematic body.
pub(crate) fn kinematic_root(w: &World, carrier: Option<Entity>) -> Option<usize> {
    let mut next = carrier;
    for _ in 0..MAX_CHAIN {
        let j = w.index_of(next?)?;
        if w.frozen(j) || w.asleep(j) {
            return None;
        }
        match w.kind[j] {
            BodyKind::Kinematic => return Some(j),
            BodyKind::Dynamic => next = w.carrier(j),
            BodyKind::Static => return None,
        }
    }
    None
}

/// How far body `i` is carried along `axis` this frame: its kinematic carrier's
/// `velocity[axis] * dt`, exactly what `move_x`/`move_y` add to the carrier itself; `0` when
/// it rides nothing that moves.
pub(crate) fn displacement(w: &World, i: usize, axis: usize, dt: f64) -> f64 {
    if w.carrier(i).is_none() {
        return 0.0;
    }
    kinematic_root(w, w.carrier(i)).map_or(0.0, |k| w.velocity(k)[axis] * dt)
}

/// Whether a box with bounds `rider` still rests on a carrier with bounds `carrier`: its
/// bottom within [`crate::SLOP`] of the carrier's top, overlapping it along x by more than
/// `SLOP`. A rider carried exactly (no gravity to press it down) is never pushed up, and still
/// rides.
pub(crate) fn still_rides(rider: &Bounds, carrier: &Bounds) -> bool {
    let slop = crate::stages::SLOP;
    (rider.min.y - carrier.max.y).abs() <= slop
        && rider.max.x.min(carrier.max.x) - rider.min.x.max(carrier.min.x) > slop
}
