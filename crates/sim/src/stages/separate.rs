//! The `resolve_x` and `resolve_y` stages: per-axis separation, as a BoxCollider does it.
//!
//! After every body has moved along one axis, each dynamic box in a `separate` layer pair is
//! checked against the other boxes it may not overlap. Where two overlap by more than
//! [`SLOP`] on both axes, the dynamic one is pushed out along the moved axis by the smaller of
//! the two overlaps on that axis, its velocity into the obstacle on that axis is zeroed, and a
//! `hit_x`/`hit_y` event is raised. A push upwards sets `grounded`. Two dynamic boxes share
//! the push, half each. Only boxes (a single AABB) are resolved per axis; every other shape in
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
    for i in 0..n {
        let w = &sim.world;
        if w.kind[i] != BodyKind::Dynamic || !is_box(&w.shape[i]) {
            continue;
        }
        for j in 0..n {
            let w = &sim.world;
            if j == i
                || !is_box(&w.shape[j])
                || layers.response(w.layer[i], w.layer[j]) != Response::Separate
                // A pair of dynamic boxes is resolved once, from the lower id.
                || (w.kind[j] == BodyKind::Dynamic && j < i)
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
            let push = push_out(&bi, &bj, axis);
            let shared = w.kind[j] == BodyKind::Dynamic;
            let mut moved = Vec2::ZERO;
            moved[axis] = if shared { 0.5 * push } else { push };
            let w = &mut sim.world;
            apply_push(w, i, axis, moved[axis]);
            if shared {
                apply_push(w, j, axis, -moved[axis]);
            }
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
    }
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
