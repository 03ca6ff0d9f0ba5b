//! The `resolve_x` and `resolve_y` stages: per-axis separation, as a BoxCollider does it.
//!
//! After every body has moved along one axis, each dynamic box in a `separate` layer pair is
//! checked against the other boxes it may not overlap. Where two overlap by more than
//! [`SLOP`] on both axes, the dynamic one is pushed out along the moved axis by the smaller of
//! the two overlaps on that axis, its velocity into the obstacle on that axis is zeroed, and a
//! `hit_x`/`hit_y` event is raised. A push upwards sets `grounded`. Dynamic boxes settle
//! lowest (leftmost) first, and a settled box is solid to the rest, so stacks resolve
//! bottom-up in one pass. Only boxes (a single AABB) are resolved per axis; every other shape in
//! a `separate` pair is pushed along the contact normal by the `detect` stage.

use ricochet_geom::{Bounds, Primitive, Shape, Vec2, contact};

use crate::def::{BodyKind, Controller, Response};
use crate::output::{ContactRecord, EventRecord, FrameOutput, Phase};
use crate::pipeline::{SLOP, Simulation};

/// Whether a shape is resolved per axis: a single axis-aligned box.
pub(crate) fn is_box(shape: &Shape) -> bool {
    matches!(shape, Shape::Primitive(Primitive::Aabb(_)))
}

pub(crate) fn has_work(sim: &Simulation) -> bool {
    let w = &sim.world;
    let layers = &sim.scenario.world.layers;
    layers.any(|r| r == Response::Separate)
        && (0..w.len()).any(|i| w.kind[i] == BodyKind::Dynamic && is_box(&w.shape[i]))
}

pub(crate) fn resolve_x(sim: &mut Simulation, out: &mut FrameOutput) {
    resolve(sim, out, 0);
}

pub(crate) fn resolve_y(sim: &mut Simulation, out: &mut FrameOutput) {
    resolve(sim, out, 1);
}

/// The push along `axis` that moves box `m` out of box `o`: the smaller overlap, signed.
fn push_out(m: &Bounds, o: &Bounds, axis: usize) -> f64 {
    let towards_min = m.max[axis] - o.min[axis]; // push m down/left by this
    let towards_max = o.max[axis] - m.min[axis]; // push m up/right by this
    if towards_min < towards_max {
        -towards_min
    } else {
        towards_max
    }
}

fn overlap(a: &Bounds, b: &Bounds, axis: usize) -> f64 {
    a.max[axis].min(b.max[axis]) - a.min[axis].max(b.min[axis])
}

fn resolve(sim: &mut Simulation, out: &mut FrameOutput, axis: usize) {
    let phase = if axis == 0 { Phase::X } else { Phase::Y };
    let layers = sim.scenario.world.layers.clone();
    let n = sim.world.len();
    // Dynamic boxes settle in order along the axis, lowest (or leftmost) first, and a settled
    // box is solid to the ones after it: a stack resolves bottom-up in one pass, each box
    // landing flush on the one below, with no box pushed back into what held it.
    let mut order: Vec<usize> = (0..n)
        .filter(|&i| sim.world.kind[i] == BodyKind::Dynamic && is_box(&sim.world.shape[i]))
        .collect();
    let w = &sim.world;
    let low = |i: usize| w.shape[i].bounds(&w.pose(i)).min[axis];
    order.sort_by(|&p, &q| low(p).total_cmp(&low(q)).then(p.cmp(&q)));
    let mut settled = vec![false; n];
    let first = out.contacts.len();
    for i in order {
        #[expect(
            clippy::needless_range_loop,
            reason = "j indexes a dozen columns, and `settled` changes between rounds of i"
        )]
        for j in 0..n {
            let w = &sim.world;
            if j == i
                || !is_box(&w.shape[j])
                || layers.response(w.layer[i], w.layer[j]) != Response::Separate
                // An unsettled dynamic box meets this one when its own turn comes.
                || (w.kind[j] == BodyKind::Dynamic && !settled[j])
            {
                continue;
            }
            let bi = w.shape[i].bounds(&w.pose(i));
            let bj = w.shape[j].bounds(&w.pose(j));
            if overlap(&bi, &bj, 0) <= SLOP || overlap(&bi, &bj, 1) <= SLOP {
                continue;
            }
            let (a, b) = if i < j { (i, j) } else { (j, i) };
            let (pose_a, pose_b) = (w.pose(a), w.pose(b));
            let c = contact(&w.shape[a], &pose_a, &w.shape[b], &pose_b);
            let mut moved = Vec2::ZERO;
            moved[axis] = push_out(&bi, &bj, axis);
            let w = &mut sim.world;
            apply_push(w, i, axis, moved[axis]);
            out.contacts.push(ContactRecord {
                a: w.entity[a],
                b: w.entity[b],
                phase,
                normal: c.normal,
                depth: c.depth,
                point: c.point,
                pose_a,
                pose_b,
                response: Response::Separate,
                resolved: moved,
            });
            out.events.push(EventRecord {
                kind: if axis == 0 { "hit_x" } else { "hit_y" },
                message: format!(
                    "{} #{} pushed {} by {} out of {} #{}",
                    w.name[i],
                    w.entity[i],
                    if axis == 0 { "along x" } else { "along y" },
                    moved[axis],
                    w.name[j],
                    w.entity[j]
                ),
            });
        }
        settled[i] = true;
    }
    // The log's convention: a pass's contacts sorted by (a, b).
    out.contacts[first..].sort_by_key(|c| (c.a, c.b));
}

/// Moves body `i` by `push` along `axis`, stops its motion into the obstacle, and notes
/// landing (pushed up) and walkers turning round (pushed along x).
fn apply_push(w: &mut crate::World, i: usize, axis: usize, push: f64) {
    w.position[i][axis] += push;
    let v = &mut w.velocity[i][axis];
    if (push < 0.0 && *v > 0.0) || (push > 0.0 && *v < 0.0) {
        *v = 0.0;
    }
    if axis == 1 && push > 0.0 {
        w.grounded[i] = true;
    }
    if axis == 0
        && let Some(Controller::Walker { speed }) = &mut w.controller[i]
        && ((push < 0.0 && *speed > 0.0) || (push > 0.0 && *speed < 0.0))
    {
        *speed = -*speed;
    }
}
