//! One-way platforms ("jump-through"): the `one_way` pass, after `turn` and before `detect`.
//!
//! A layer pair with [`Response::OneWay`] (`response = "one_way"` in `[[collide]]`, the
//! second layer the platforms') is never tested by `detect`; this pass answers it instead.
//! The rule is Box2D's one-way sample (a pre-solve that disables the contact):
//!
//! - A **platform** is a static or kinematic body of the platform layer, of any shape; its
//!   *top* is its bounding box's top (a one-way platform is a ledge: what matters is how
//!   high it is, not its outline), and it spans its bounding box along x.
//! - A dynamic body of the other layer (of any shape: its *bottom* is its bounding box's
//!   bottom) **lands** on a platform when, at the start of the step, its bottom was at or
//!   above the platform's top less [`ABOVE_TOLERANCE`], at the end of the step it is below
//!   that top (or flush with it, within [`SLOP`]), the gap between them did not grow over
//!   the step (it is not moving up relative to the platform), it is not dropping through ([`crate::Inputs::drop`]), and the two overlapped
//!   along x (by more than `SLOP`) at the moment the bottom crossed the top (the motions
//!   taken as straight over the step). Of all the platforms it lands on, the highest top
//!   holds it. Otherwise it **passes through**: from below, from the side, or already
//!   inside.
//! - Landing: the body is put with its bottom on the top (x as its motion left it), its
//!   downward velocity is zeroed, it is `grounded`, `on_static` on a static platform, and a
//!   kinematic platform becomes its carrier, which carries it in the next frame's `move_x`
//!   and `move_y` like a rider (`stages/carry.rs`). The contact is recorded with phase `y`
//!   and the pair's `one_way` response (depth the overlap before the push).
//! - Because the test compares where the body was at the start of the step with where it is
//!   at the end, no speed takes a body through a platform it was above: the pass is swept
//!   by construction, for every shape.
//! - **Drop through**: a `drop` input ([`crate::Action::Drop`]) to a grounded body sets
//!   `drop`; while it is set the body lands on no one-way platform. The pass clears it at the
//!   end of the first step the body overlaps no platform (by more than `SLOP` on both axes).
//!
//! A scene with no `one_way` pair never runs this pass, and nothing else changes for it.
//! Cost: each dynamic body of a rider layer against each platform of its pairs, `O(bodies ×
//! platforms)`; the static platforms are listed once per static change.

use ricochet_geom::{Bounds, Primitive, Shape, Vec2};

use crate::def::{BodyKind, Layers, Platform, Response};
use crate::output::{ContactRecord, Phase};
use crate::stages::{SLOP, StageCtx};
use crate::world::World;

/// How far below a platform's top a body's bottom may have started the step and still be
/// "above" it, in world units: a body resting on a platform is flush up to rounding.
pub const ABOVE_TOLERANCE: f64 = 1e-6;

/// What the pass keeps between frames.
#[derive(Debug, Default, Clone)]
pub(crate) struct OneWayState {
    /// Whether any layer pair is `one_way`.
    any: bool,
    /// Layers whose dynamic bodies land on one-way platforms.
    riders: Vec<bool>,
    /// Layers whose static and kinematic bodies are one-way platforms.
    platforms: Vec<bool>,
    /// The static generation `statics` was listed at.
    static_generation: Option<u64>,
    /// The static platforms, by dense index.
    statics: Vec<u32>,
    /// This frame's platforms: index, bounds now, top at the start of the step.
    frame: Vec<(usize, Bounds, f64)>,
}

impl OneWayState {
    /// The state for a scene with these layers.
    pub(crate) fn new(layers: &Layers) -> OneWayState {
        let n = layers.names().len();
        let mut st = OneWayState {
            riders: vec![false; n],
            platforms: vec![false; n],
            ..OneWayState::default()
        };
        for a in 0..n {
            for b in 0..n {
                if layers.response(a as u8, b as u8) == Response::OneWay(Platform::Second) {
                    st.any = true;
                    st.riders[a] = true;
                    st.platforms[b] = true;
                }
            }
        }
        st
    }

    /// Whether the scene has a `one_way` pair (and carriers: a kinematic platform carries).
    pub(crate) fn any(&self) -> bool {
        self.any
    }
}

/// Whether the pass has work: a `one_way` pair and an active dynamic body of a rider layer.
pub(crate) fn has_work(w: &World, st: &OneWayState) -> bool {
    st.any
        && w.active().iter().any(|&i| {
            let i = i as usize;
            w.kind[i] == BodyKind::Dynamic && st.riders[usize::from(w.layer[i])]
        })
}

/// The bounds of body `i` at its pose now.
fn bounds(w: &World, i: usize) -> Bounds {
    w.shape(i).bounds(&w.pose(i))
}

/// The pass: lands the bodies that came down onto a one-way platform, clears `drop` for the
/// bodies clear of every platform.
pub(crate) fn run(ctx: &mut StageCtx, st: &mut OneWayState) {
    let layers = &ctx.def.layers;
    let w = &mut *ctx.world;
    if st.static_generation != Some(w.static_generation()) {
        st.static_generation = Some(w.static_generation());
        st.statics = (0..w.len())
            .filter(|&j| w.kind[j] == BodyKind::Static && st.platforms[usize::from(w.layer[j])])
            .map(|j| j as u32)
            .collect();
    }
    let mut frame = std::mem::take(&mut st.frame);
    frame.clear();
    let kinematic = w
        .movers()
        .iter()
        .map(|&j| j as usize)
        .filter(|&j| w.kind[j] == BodyKind::Kinematic && st.platforms[usize::from(w.layer[j])]);
    for j in st.statics.iter().map(|&j| j as usize).chain(kinematic) {
        let b = bounds(w, j);
        let top = b.max.y + (w.start_position(j).y - w.position[j].y);
        frame.push((j, b, top));
    }
    let first = ctx.out.contacts.len();
    for k in 0..w.active().len() {
        let i = w.active()[k] as usize;
        if w.kind[i] != BodyKind::Dynamic || !st.riders[usize::from(w.layer[i])] {
            continue;
        }
        let bi = bounds(w, i);
        let back = w.start_position(i) - w.position[i];
        let bottom_start = bi.min.y + back.y;
        let dropping = w.inputs(i).drop;
        let mut inside = false;
        // The platform that holds it: index, top now, bounds.
        let mut held: Option<(usize, f64, Bounds)> = None;
        for &(j, bj, top_start) in &frame {
            if j == i
                || layers.response(w.layer[i], w.layer[j]) != Response::OneWay(Platform::Second)
            {
                continue;
            }
            let top = bj.max.y;
            if dropping {
                inside |= overlaps(&bi, &bj, 0) > SLOP && overlaps(&bi, &bj, 1) > SLOP;
                continue;
            }
            // The gap between the body's bottom and the platform's top, at the start and at
            // the end of the step: the body lands when it goes from >= 0 to <= 0.
            let (g0, g1) = (bottom_start - top_start, bi.min.y - top);
            // Moving up relative to the platform (the gap grew): a jump up through it.
            if g0 < -ABOVE_TOLERANCE || g1 > SLOP || g1 > g0 {
                continue;
            }
            // When the bottom crossed the top, as a fraction of the step from its start.
            let t = if g0 > g1 {
                (g0 / (g0 - g1)).clamp(0.0, 1.0)
            } else {
                1.0
            };
            let back_j = w.start_position(j).x - w.position[j].x;
            let (bx, jx) = (back.x * (1.0 - t), back_j * (1.0 - t));
            let across = (bi.max.x + bx).min(bj.max.x + jx) - (bi.min.x + bx).max(bj.min.x + jx);
            if across <= SLOP {
                continue;
            }
            if held.is_none_or(|(_, h, _)| top > h) {
                held = Some((j, top, bj));
            }
        }
        if dropping && !inside {
            w.inputs_mut(i).drop = false;
        }
        let Some((j, top, bj)) = held else {
            // Off the one-way platform it rode, if any: it rides nothing now.
            let rode = w.carrier(i).and_then(|e| w.index_of(e));
            if rode.is_some_and(|c| {
                layers.response(w.layer[i], w.layer[c]) == Response::OneWay(Platform::Second)
            }) {
                *w.carrier_mut(i) = None;
            }
            continue;
        };
        let depth = top - bi.min.y;
        let y = match w.shape(i) {
            // Exactly flush for a box on its origin.
            Shape::Primitive(Primitive::Aabb(b)) if b.center == Vec2::ZERO => {
                top + b.half_extents.y
            }
            _ => w.position[i].y + depth,
        };
        let moved = Vec2::new(0.0, y - w.position[i].y);
        let pose_before = w.pose(i);
        w.position_mut(i).y = y;
        // As a `separate` push up: the velocity into the platform stops (a kinematic
        // platform carries the body by its own motion).
        let v = w.velocity_mut(i);
        if v.y < 0.0 {
            v.y = 0.0;
        }
        *w.grounded_mut(i) = true;
        let on_static = w.kind[j] == BodyKind::Static;
        *w.on_static_mut(i) |= on_static;
        *w.carrier_mut(i) = (!on_static).then(|| w.entity[j]);
        let (a, b, normal) = if i < j {
            (i, j, Vec2::new(0.0, -1.0))
        } else {
            (j, i, Vec2::new(0.0, 1.0))
        };
        let lo = bi.min.x.max(bj.min.x);
        let hi = bi.max.x.min(bj.max.x);
        let (pose_i, pose_j) = (pose_before, w.pose(j));
        let (pose_a, pose_b) = if i < j {
            (pose_i, pose_j)
        } else {
            (pose_j, pose_i)
        };
        ctx.out.contacts.push(ContactRecord {
            a: w.entity[a],
            b: w.entity[b],
            phase: Phase::Y,
            normal,
            depth: depth.max(0.0),
            point: Vec2::new(0.5 * (lo + hi), top),
            pose_a,
            pose_b,
            response: layers.response(w.layer[a], w.layer[b]),
            resolved: moved,
        });
    }
    // The log's convention: a pass's contacts sorted by (a, b).
    ctx.out.contacts[first..].sort_by_key(|c| (c.a, c.b));
    st.frame = frame;
}

/// How much two bounds overlap along `axis` (negative when apart).
fn overlaps(a: &Bounds, b: &Bounds, axis: usize) -> f64 {
    a.max[axis].min(b.max[axis]) - a.min[axis].max(b.min[axis])
}
