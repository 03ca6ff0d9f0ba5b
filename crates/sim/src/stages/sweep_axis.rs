//! The swept move of `resolve_x` and `resolve_y`: a box never passes through an obstacle
//! along the axis it just moved on, whatever its speed.
//!
//! `move_x` (or `move_y`) moved the box from its start coordinate along the axis
//! ([`crate::World::start_position`]: the frame's motion stages before it change no other
//! coordinate) to where it is now, by `v * dt` and, for a rider, its carrier's displacement.
//! The obstacles it may have crossed are those whose span on the other axis overlaps the
//! box's by more than [`SLOP`], that the box did not overlap at the start (relative to the
//! obstacle's own start, for a moving one), and whose near face it went past by more than
//! `SLOP`. The box meets the nearest one first (the smallest fraction of the relative motion;
//! ties by id), and stops flush against it.
//!
//! Today's push covers every case in which no tunnel is possible, and it is kept bit for bit:
//! when the box still overlaps that first obstacle along the axis and the push out by the
//! smaller overlap takes it back towards where it came from, the pass goes on as it always
//! did ([`first_hit`] answers `None`). Only a box that went right through (no overlap left)
//! or deep enough to be pushed out of the far side is stopped by the sweep. A box that moved
//! at most half its own size along the axis is not swept at all: from outside a static box
//! it goes in by at most that, less than half the two boxes' size, so the push is always
//! right (against a kinematic or settled box moving towards it, the push by the smaller
//! overlap decides, as before).

use ricochet_geom::Bounds;

use crate::stages::SLOP;

/// An obstacle the sweep may meet: its bounds now, and how far it moved along the axis
/// since the frame's start (zero for a static body).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Swept {
    /// The obstacle's bounds now.
    pub bounds: Bounds,
    /// Its start coordinate along the axis minus its coordinate now.
    pub back: f64,
}

/// Where the sweep stops a box: the obstacle (its place in the list handed to
/// [`first_hit`]) and the face of it the box ends flush against.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Stop {
    /// The obstacle's place in the candidates.
    pub at: usize,
    /// The obstacle's face the box touches: its `min` when the box moved towards `+axis`
    /// relative to it, its `max` otherwise.
    pub face: f64,
    /// Whether the box moved towards `+axis` relative to the obstacle.
    pub towards_max: bool,
}

/// The first obstacle a box with bounds `now` along `axis`, which started `back` further
/// along it (its start coordinate minus its coordinate now), crosses or goes deep enough into
/// to be pushed out of its far side, among `obstacles` (already filtered: the pairs that
/// `separate`, in id order). `None` when it crossed none, or when today's push out by the
/// smaller overlap puts it back on its own side of the first one it meets.
pub(crate) fn first_hit(
    now: &Bounds,
    back: f64,
    axis: usize,
    obstacles: impl Iterator<Item = Swept>,
) -> Option<Stop> {
    let other = 1 - axis;
    let mut best: Option<(f64, Stop, Bounds)> = None;
    for (at, o) in obstacles.enumerate() {
        // The box's start relative to the obstacle's start: `rel` further back.
        let rel = back - o.back;
        if rel == 0.0 {
            continue;
        }
        if overlap(now, &o.bounds, other) <= SLOP {
            continue;
        }
        let towards_max = rel < 0.0;
        // Gaps before and after the move, positive while apart.
        let (g0, g1) = if towards_max {
            (
                o.bounds.min[axis] - (now.max[axis] + rel),
                o.bounds.min[axis] - now.max[axis],
            )
        } else {
            (
                (now.min[axis] + rel) - o.bounds.max[axis],
                now.min[axis] - o.bounds.max[axis],
            )
        };
        if g0 < -SLOP || g1 >= -SLOP {
            // Overlapping at the start (today's push decides), or never reached it.
            continue;
        }
        let t = g0.max(0.0) / (g0.max(0.0) - g1);
        if best.as_ref().is_none_or(|(bt, ..)| t < *bt) {
            let face = if towards_max {
                o.bounds.min[axis]
            } else {
                o.bounds.max[axis]
            };
            let stop = Stop {
                at,
                face,
                towards_max,
            };
            best = Some((t, stop, o.bounds));
        }
    }
    let (_, stop, o) = best?;
    // Today's push: out by the smaller overlap. Right whenever it goes back the way the box
    // came; then the pass resolves it exactly as before.
    if overlap(now, &o, axis) > SLOP {
        let towards_min = now.max[axis] - o.min[axis];
        let towards_max = o.max[axis] - now.min[axis];
        let pushed_down = towards_min < towards_max;
        if pushed_down == stop.towards_max {
            return None;
        }
    }
    Some(stop)
}

/// How much `a` and `b` overlap along `axis` (negative when apart).
fn overlap(a: &Bounds, b: &Bounds, axis: usize) -> f64 {
    a.max[axis].min(b.max[axis]) - a.min[axis].max(b.min[axis])
}

#[cfg(test)]
mod tests {
    use ricochet_geom::Vec2;

    use super::*;

    fn floor() -> Swept {
        Swept {
            bounds: Bounds::around(Vec2::new(0.0, 0.0), Vec2::new(5.0, 0.025)),
            back: 0.0,
        }
    }

    #[test]
    fn a_box_that_went_through_a_thin_floor_stops_on_it() {
        // From y = 10 to y = -10: the floor is behind it.
        let now = Bounds::around(Vec2::new(0.0, -10.0), Vec2::splat(0.4));
        let stop = first_hit(&now, 20.0, 1, [floor()].into_iter()).unwrap();
        assert_eq!(stop.face, 0.025);
        assert!(!stop.towards_max);
    }

    #[test]
    fn a_shallow_landing_is_left_to_the_push() {
        let now = Bounds::around(Vec2::new(0.0, 0.4), Vec2::splat(0.4));
        assert_eq!(first_hit(&now, 0.1, 1, [floor()].into_iter()), None);
    }

    #[test]
    fn a_box_beside_the_floor_or_overlapping_at_the_start_is_not_swept() {
        let beside = Bounds::around(Vec2::new(6.0, -10.0), Vec2::splat(0.4));
        assert_eq!(first_hit(&beside, 20.0, 1, [floor()].into_iter()), None);
        let inside = Bounds::around(Vec2::new(0.0, -10.0), Vec2::splat(0.4));
        assert_eq!(first_hit(&inside, 10.0, 1, [floor()].into_iter()), None);
    }
}
