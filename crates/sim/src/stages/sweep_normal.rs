//! Swept `separate` for every shape that is not resolved per axis: time of impact, then the
//! push along the normal (`push.rs`).
//!
//! A `separate` pair of one dynamic body and one static or kinematic body, in `detect`, whose
//! relative motion over the frame is more than half the sum of the two bodies'
//! [`Shape::min_width`](ricochet_geom::Shape::min_width) may have tunnelled: a convex body
//! that moved less than that from outside the other cannot get past its middle, so the
//! end-pose test pushes it back the way it came, and nothing changes for it. Above it, the
//! pair is also tested by [`time_of_impact`] from the frame's start to its end (straight
//! lines, end angles). When the bodies touched on the way (not overlapping at the start) and the
//! contact normal at the end pose (overlapping or not) opposes the normal at the touch (the
//! body went through, or deep enough to be pushed out of the far side), the dynamic body
//! is put back at its pose at
//! the time of impact and pushed there like any `separate` pair: its velocity into the
//! surface removed, `grounded` set on landing. The contact is logged with phase `swept` at
//! the touching poses.

use ricochet_geom::{Contact, Impact, Sweep, Vec2, contact, time_of_impact};

use crate::def::{BodyKind, Response};
use crate::output::{ContactRecord, Phase};
use crate::stages::push::separate_along_normal;
use crate::stages::slope::Climb;
use crate::stages::{SLOP, StageCtx};
use crate::world::World;

/// The time of impact that stops the dynamic body of pair `(i, j)`, whose contact at the
/// end poses is `end`; `None` when the end-pose push is right (or the pair is not one the
/// sweep covers). Counts its time-of-impact test in `tests`.
pub(crate) fn stop(
    w: &World,
    (i, j): (usize, usize),
    end: &Contact,
    tests: &mut u64,
) -> Option<Impact> {
    let dynamic = |k: usize| w.kind[k] == BodyKind::Dynamic;
    if dynamic(i) == dynamic(j) || w.asleep(i) || w.asleep(j) {
        return None;
    }
    let moved = |k: usize| w.position[k] - w.start_position(k);
    let relative = moved(i) - moved(j);
    let reach = 0.5 * (w.shape(i).min_width() + w.shape(j).min_width());
    if relative == Vec2::ZERO || relative.length() <= reach {
        return None;
    }
    *tests += 1;
    let sweep = |k: usize| Sweep {
        start: w.start_position(k),
        end: w.position[k],
        angle: w.angle[k],
    };
    let impact = time_of_impact(w.shape(i), &sweep(i), w.shape(j), &sweep(j))?;
    if impact.t <= 0.0 && impact.contact.depth > SLOP {
        // Overlapping when the frame began: the push decides, as before. (Touching then is
        // swept like any other touch: a body flush on a floor that falls through it stays.)
        return None;
    }
    if end.normal.dot(impact.contact.normal) > 0.0 {
        // At the end poses the obstacle is still on the side the body touched it from:
        // the push there (if any) goes back the way the body came, and a body that slid
        // along a surface onto the next tile (touching both) is not stopped at the seam.
        return None;
    }
    Some(impact)
}

/// Puts the dynamic body of `(i, j)` at its pose at `impact`, pushes it there along the
/// normal (by the depth left against a kinematic body that moved on, or by nothing, which
/// still removes the velocity into the surface and grounds a landing), and logs the
/// contact (phase `swept`, at the touching poses).
pub(crate) fn apply(ctx: &mut StageCtx, (i, j): (usize, usize), impact: &Impact) {
    let climb = Climb::of(ctx.def);
    let w = &mut *ctx.world;
    let (d, at) = if w.kind[i] == BodyKind::Dynamic {
        (i, impact.pose_a.position)
    } else {
        (j, impact.pose_b.position)
    };
    let end = w.position[d];
    *w.position_mut(d) = at;
    let c = contact(w.shape(i), &w.pose(i), w.shape(j), &w.pose(j));
    let (normal, depth) = if c.depth > SLOP {
        (c.normal, c.depth)
    } else {
        (impact.contact.normal, 0.0)
    };
    // One dynamic body against a static or kinematic one: no push between dynamic bodies.
    separate_along_normal(w, None, (i, j), (normal, depth), climb);
    let resolved = w.position[d] - end;
    let (ea, eb) = (w.entity[i], w.entity[j]);
    ctx.out.contacts.push(ContactRecord {
        a: ea,
        b: eb,
        phase: Phase::Swept,
        normal: impact.contact.normal,
        depth: impact.contact.depth,
        point: impact.contact.point,
        pose_a: impact.pose_a,
        pose_b: impact.pose_b,
        response: Response::Separate,
        resolved,
    });
}
