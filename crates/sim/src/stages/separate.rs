//! The `resolve_x` and `resolve_y` stages: per-axis separation, as a BoxCollider does it.
//!
//! After every body has moved along one axis, each dynamic box in a `separate` layer pair is
//! checked against the other boxes it may not overlap. Where two overlap by more than
//! [`SLOP`] on both axes, the dynamic one is pushed out along the moved axis by the smaller of
//! the two overlaps on that axis, its velocity into the obstacle on that axis is zeroed, and the
//! contact is recorded (phase `x` or `y`). A push upwards sets `grounded`, and records the kinematic
//! or dynamic box that pushed it as the carrier the box rides next frame; a box that a
//! kinematic body pushed or carried and that is left overlapping a wall raises `crush`
//! (riders: `stages/carry.rs`). Dynamic boxes settle lowest (leftmost) first, and a settled
//! box is solid to the rest, so stacks resolve bottom-up in one pass. Statics win: a push out
//! of another dynamic box never moves a box into a static one (`statics_win`). Only boxes (a single
//! AABB) are resolved per axis; every other shape in a `separate` pair is pushed along the
//! contact normal by the `detect` stage.
//!
//! Before the pushes, a box that moved along the axis is swept (`sweep_axis.rs`): it stops
//! flush against the first box it would have crossed, so no speed takes it through a tile.
//! The first lookup covers the box's start and end along the axis.
//!
//! Finding the obstacles (`obstacles.rs`): static boxes sit in a tile map built once (rebuilt
//! only when the static bodies change: `broad_phase/tile_map.rs`); kinematic boxes, and
//! dynamic boxes once settled, go into a small grid rebuilt every pass, if a settling box may
//! stop on them. Each dynamic box looks up both and meets its obstacles in id order at its
//! current position; after a push it looks again from the obstacle after the one it was
//! pushed out of. That is exactly the order of a loop over every body, at the cost of the
//! few it is near. The order the boxes settle in is kept from frame to frame
//! (`pass_order.rs`), and a pair of boxes' contact is computed directly (`box_contact.rs`).

use ricochet_geom::{Bounds, Primitive, Shape, Vec2};

use crate::broad_phase::{MoverGrid, StaticBox, TileMap};
use crate::def::{BodyKind, Controller, Layers, Response};
use crate::output::{ContactRecord, Phase};
use crate::stages::box_contact::box_contact;
use crate::stages::obstacles::{
    Obstacle, bounds_if_box, box_bounds, obstacles, on_origin, overlap, solid_layers, statics_win,
};
use crate::stages::pass_order::{self, PassOrder};
use crate::stages::rider::rider;
use crate::stages::slope::SlopeState;
use crate::stages::sweep_axis::{self, Swept};
use crate::stages::{SLOP, StageCtx};
use crate::world::World;

/// Whether a shape is resolved per axis: a single axis-aligned box.
pub(crate) fn is_box(shape: &Shape) -> bool {
    shape.is_single_aabb()
}

/// Whether a layer pair `separate`s and an active dynamic box may need resolving.
pub(crate) fn has_work(w: &World, st: &SeparateState) -> bool {
    st.any_layer
        && w.active().iter().any(|&i| {
            let i = i as usize;
            w.kind[i] == BodyKind::Dynamic && is_box(w.shape(i))
        })
}

/// The `resolve_x` stage: the pass along x. A runner or walker walking from a ramp onto a
/// static box no higher than the ramp would have risen is not stopped by its side
/// (`slopes`: `stages/slope.rs`); `resolve_y` lifts it on top.
pub(crate) fn resolve_x(ctx: &mut StageCtx, st: &mut SeparateState, slopes: &SlopeState) {
    resolve(ctx, st, 0, Some(slopes));
}

/// The `resolve_y` stage: the pass along y.
pub(crate) fn resolve_y(ctx: &mut StageCtx, st: &mut SeparateState) {
    resolve(ctx, st, 1, None);
}

/// What the per-axis stages keep between passes.
#[derive(Debug, Default, Clone)]
pub(crate) struct SeparateState {
    /// Whether any layer pair `separate`s.
    any_layer: bool,
    /// Layers with a `separate` pair.
    separating: Vec<bool>,
    /// The static generation `statics` was built at.
    static_generation: Option<u64>,
    /// Static boxes of separating layers, each with its rank among all the static bodies
    /// (its dense index follows: `obstacles::static_index`) and its layer: a tile map.
    statics: TileMap,
    movers: MoverGrid,
    found: Vec<Obstacle>,
    /// Each axis's order of the dynamic boxes, kept from the last frame.
    orders: [PassOrder; 2],
    /// The pass's dynamic boxes in order.
    order: Vec<pass_order::Entry>,
    /// Their larger sides, for the mover grid's cell size.
    extents: Vec<f64>,
    /// Sleeping boxes pushed against, woken after the pass.
    woken: Vec<usize>,
    /// The pass's contacts' `(a, b)` and places as sort keys ([`sort_contacts`]).
    keys: Vec<u128>,
    /// The pass's contacts, while they are put in order.
    records: Vec<ContactRecord>,
}

impl SeparateState {
    /// Whether any layer pair is resolved per axis: only then can a box stand on a carrier
    /// (`resolve_y` is the only place a carrier is recorded).
    pub(crate) fn carries(&self) -> bool {
        self.any_layer
    }

    /// The state for a scene with these layers.
    pub(crate) fn new(layers: &Layers) -> SeparateState {
        let n = layers.names().len();
        let separating: Vec<bool> = (0..n)
            .map(|l| (0..n).any(|m| layers.response(l as u8, m as u8) == Response::Separate))
            .collect();
        SeparateState {
            any_layer: separating.iter().any(|s| *s),
            separating,
            ..SeparateState::default()
        }
    }

    /// Rebuilds the static grid if the static bodies changed.
    fn refresh_statics(&mut self, w: &World) {
        if self.static_generation == Some(w.static_generation()) {
            return;
        }
        self.static_generation = Some(w.static_generation());
        self.statics = TileMap::default();
        let separating = &self.separating;
        // Each static box of a separating layer, with its rank among the static bodies (the
        // tile map reads them a few times instead of copying a million of them).
        let boxes = || {
            (0..w.len())
                .filter(|&i| w.kind[i] == BodyKind::Static)
                .enumerate()
                .filter(|&(_, i)| is_box(w.shape(i)) && separating[usize::from(w.layer[i])])
                .map(|(rank, i)| StaticBox {
                    bounds: box_bounds(w, i),
                    centre: on_origin(w, i).map(|half| (w.position[i], half)),
                    handle: rank as u32,
                    tag: w.layer[i],
                })
        };
        self.statics = TileMap::new(boxes);
    }
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

/// Whether `inner` lies within `outer`.
fn contains(outer: &Bounds, inner: &Bounds) -> bool {
    outer.min.x <= inner.min.x
        && outer.min.y <= inner.min.y
        && inner.max.x <= outer.max.x
        && inner.max.y <= outer.max.y
}

/// One per-axis pass: settles every dynamic box along `axis`, lowest first.
fn resolve(ctx: &mut StageCtx, st: &mut SeparateState, axis: usize, slopes: Option<&SlopeState>) {
    let phase = if axis == 0 { Phase::X } else { Phase::Y };
    let out = &mut *ctx.out;
    let layers = &ctx.def.layers;
    st.refresh_statics(ctx.world);
    let w = &*ctx.world;
    // Dynamic boxes settle in order along the axis, lowest (or leftmost) first, and a settled
    // box is solid to the ones after it: a stack resolves bottom-up in one pass, each box
    // landing flush on the one below, with no box pushed back into what held it.
    let mut order = std::mem::take(&mut st.order);
    let mut extents = std::mem::take(&mut st.extents);
    extents.clear();
    let separating = &st.separating;
    st.orders[axis].sort(
        w.movers(),
        |_, i| {
            let k = i as usize;
            let settles = w.kind[k] == BodyKind::Dynamic
                && separating[usize::from(w.layer[k])]
                && !w.frozen(k)
                && !w.asleep(k);
            let b = bounds_if_box(w, k).filter(|_| settles)?;
            extents.push((b.max - b.min).max_element());
            Some(b.min[axis])
        },
        &mut order,
    );
    // The layers a moving box may be solid to: those some settling box `separate`s from. A
    // box of any other layer is never an obstacle, so it stays out of the mover grid (the
    // platformer's actors only `report` to each other: the grid stays empty and is never
    // looked at).
    let solid = solid_layers(w, layers, order.iter().map(|e| e.1));
    // Kinematic boxes and sleeping ones are solid from the start; dynamic ones once settled.
    st.movers.reset(&mut extents, order.len());
    let movers_solid = solid.iter().any(|&s| s);
    for &i in w.movers().iter().filter(|_| movers_solid) {
        let k = i as usize;
        if is_box(w.shape(k))
            && !w.frozen(k)
            && st.separating[usize::from(w.layer[k])]
            && solid[usize::from(w.layer[k])]
            && (w.kind[k] == BodyKind::Kinematic || w.asleep(k))
        {
            st.movers.insert(&box_bounds(w, k), i);
        }
    }
    let first = out.contacts.len();
    // About one contact a box a pass: grown once, not record by record.
    out.contacts.reserve(order.len());
    let mut found = std::mem::take(&mut st.found);
    let mut woken = std::mem::take(&mut st.woken);
    for &(_, i, _) in &order {
        let i = i as usize;
        // One lookup usually does: it covers the box moved by up to its own size along the
        // axis, more than one push can move it (a push is at most the box's overlap).
        // After pushes that took it further, it looks again.
        let mut region: Option<Bounds> = None;
        let mut next = 0;
        // What it rode into the frame, and the first kinematic box that pushes it (riders:
        // `stages/carry.rs`). `resolve_y` records what holds it up now.
        let old_carrier = ctx.world.carrier(i);
        if axis == 1 {
            *ctx.world.carrier_mut(i) = None;
        }
        let mut pushed_by = None;
        // Where the box started along the axis, relative to where it is now: the first
        // lookup covers the whole swept interval, and the sweep runs once on it. A box that
        // moved at most half its size cannot get past a static box's middle (it goes in by
        // at most that, less than half the pair's size), so today's push is right for it
        // and the sweep is skipped (`sweep_axis.rs`).
        let back = ctx.world.start_position(i)[axis] - ctx.world.position[i][axis];
        // Its bounds, kept up to date after each push.
        let mut bi = box_bounds(ctx.world, i);
        let mut swept = 2.0 * back.abs() <= bi.max[axis] - bi.min[axis];
        'look: loop {
            if !region.is_some_and(|r| contains(&r, &bi)) {
                let mut r = bi;
                let reach = bi.max[axis] - bi.min[axis];
                r.min[axis] -= reach;
                r.max[axis] += reach;
                if !swept {
                    let mut start = bi;
                    start.min[axis] += back;
                    start.max[axis] += back;
                    r = r.union(start);
                }
                // After a push at `found[next - 1]`, the obstacles after it.
                let from = if next > 0 {
                    found[next - 1].index + 1
                } else {
                    0
                };
                obstacles((&st.statics, &st.movers), ctx.world, &r, from, &mut found);
                region = Some(r);
                next = 0;
            }
            // The obstacle, the new coordinate, the push, and whether it is a swept stop.
            let mut push: Option<(usize, f64, f64, bool)> = None;
            if !swept {
                // The swept move (`sweep_axis.rs`): stop flush at the first obstacle crossed.
                swept = true;
                let w = &*ctx.world;
                let solid = |o: &&Obstacle| {
                    o.index as usize != i
                        && layers.response(w.layer[i], o.layer) == Response::Separate
                };
                let candidates = found.iter().filter(solid).map(|o| Swept {
                    bounds: o.bounds,
                    back: if o.moving {
                        let j = o.index as usize;
                        w.start_position(j)[axis] - w.position[j][axis]
                    } else {
                        0.0
                    },
                });
                if let Some(stop) = sweep_axis::first_hit(&bi, back, axis, candidates) {
                    let o = found.iter().filter(solid).nth(stop.at).copied();
                    let o = o.expect("the stop is one of the candidates");
                    let to = flush(w, i, &bi, axis, stop);
                    push = Some((o.index as usize, to, to - w.position[i][axis], true));
                }
            }
            while push.is_none() && next < found.len() {
                let o = found[next];
                let (j, bj) = (o.index as usize, o.bounds);
                next += 1;
                let w = &*ctx.world;
                if j == i || layers.response(w.layer[i], o.layer) != Response::Separate {
                    continue;
                }
                if overlap(&bi, &bj, 0) <= SLOP || overlap(&bi, &bj, 1) <= SLOP {
                    continue;
                }
                if !o.moving && slopes.is_some_and(|s| s.steps_onto(w, ctx.def, i, (&bi, &bj))) {
                    continue;
                }
                let mut by = push_out(&bi, &bj, axis);
                if o.moving && w.kind[j] == BodyKind::Dynamic {
                    by = statics_win(&st.statics, (w, layers), (i, &bi, &bj), axis, by);
                }
                push = Some((j, w.position[i][axis] + by, by, false));
            }
            let Some((j, to, by, after)) = push else {
                break;
            };
            let w = &*ctx.world;
            let (a, b) = if i < j { (i, j) } else { (j, i) };
            // A box that was still already (resting on the sleeper) does not wake it.
            if w.asleep(j) && !w.still(i) {
                woken.push(j);
            }
            let kind = w.kind[j];
            if kind == BodyKind::Kinematic && pushed_by.is_none() {
                pushed_by = Some(j);
            }
            // A push's contact is logged where the pair overlapped; a swept stop's where it
            // touches.
            let pair_contact = |w: &World| {
                let (pose_a, pose_b) = (w.pose(a), w.pose(b));
                let c = box_contact(w.shape(a), &pose_a, w.shape(b), &pose_b);
                (c, pose_a, pose_b)
            };
            let before = (!after).then(|| pair_contact(w));
            let mut moved = Vec2::ZERO;
            moved[axis] = by;
            let w = &mut *ctx.world;
            apply_push(w, i, axis, to, by);
            let (c, pose_a, pose_b) = before.unwrap_or_else(|| pair_contact(w));
            if axis == 1 && moved[axis] > 0.0 {
                // Held up: by a static body (it may sleep), or by a carrier it rides.
                *w.on_static_mut(i) |= kind == BodyKind::Static;
                *w.carrier_mut(i) = (kind != BodyKind::Static).then(|| w.entity[j]);
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
            // The box moved: go on from the next obstacle, at its new place (after a swept
            // stop, from the first: it stands where the pass may start again).
            bi = box_bounds(w, i);
            continue 'look;
        }
        let riding = (old_carrier, pushed_by);
        let lookup = (&st.statics, &st.movers);
        if let Some(event) = rider(ctx.world, layers, lookup, &mut found, (i, axis), riding) {
            out.events.push(event);
        }
        if solid[usize::from(ctx.world.layer[i])] {
            st.movers.insert(&box_bounds(ctx.world, i), i as u32);
        }
    }
    for j in woken.drain(..) {
        ctx.world.wake(j);
    }
    st.found = found;
    st.order = order;
    st.extents = extents;
    st.woken = woken;
    // The log's convention: a pass's contacts sorted by (a, b).
    sort_contacts(&mut out.contacts, first, &mut st.keys, &mut st.records);
}

/// Sorts `contacts[first..]` by `(a, b)`, stably: as keys with their places (an unstable
/// sort of unique keys), then each record moved once (a record is about 130 bytes; a sort
/// of the records moves each `log n` times). A key is `a`'s index, `b`'s index and the
/// place in one `u128`: two live bodies never share an index, so that is the order of
/// `(a, b)` (index, then generation) and the place, compared in one go.
fn sort_contacts(
    contacts: &mut Vec<ContactRecord>,
    first: usize,
    keys: &mut Vec<u128>,
    records: &mut Vec<ContactRecord>,
) {
    keys.clear();
    keys.extend(contacts[first..].iter().zip(0u32..).map(|(c, k)| {
        (u128::from(c.a.index) << 64) | (u128::from(c.b.index) << 32) | u128::from(k)
    }));
    if keys.is_sorted() {
        return;
    }
    keys.sort_unstable();
    records.clear();
    records.extend(contacts.drain(first..));
    contacts.extend(keys.iter().map(|&k| records[k as u32 as usize].clone()));
}

/// The coordinate along `axis` that puts box `i` (bounds `bi`) flush against the sweep's
/// `stop`: exactly `face ∓ half extent` for a box on the body origin.
fn flush(w: &World, i: usize, bi: &Bounds, axis: usize, stop: sweep_axis::Stop) -> f64 {
    let p = w.position[i][axis];
    match w.shape(i) {
        Shape::Primitive(Primitive::Aabb(b)) if b.center == Vec2::ZERO => {
            if stop.towards_max {
                stop.face - b.half_extents[axis]
            } else {
                stop.face + b.half_extents[axis]
            }
        }
        _ if stop.towards_max => p + (stop.face - bi.max[axis]),
        _ => p + (stop.face - bi.min[axis]),
    }
}

/// Moves body `i` to `to` along `axis` (a push by `push`), stops its motion into the obstacle, and notes
/// landing (pushed up) and walkers turning round (pushed along x).
fn apply_push(w: &mut crate::World, i: usize, axis: usize, to: f64, push: f64) {
    w.position_mut(i)[axis] = to;
    let v = &mut w.velocity_mut(i)[axis];
    if (push < 0.0 && *v > 0.0) || (push > 0.0 && *v < 0.0) {
        *v = 0.0;
    }
    if axis == 1 && push > 0.0 {
        *w.grounded_mut(i) = true;
    }
    if axis == 0
        && let Some(Controller::Walker { speed }) = w.controller_mut(i)
        && ((push < 0.0 && *speed > 0.0) || (push > 0.0 && *speed < 0.0))
    {
        *speed = -*speed;
    }
}
