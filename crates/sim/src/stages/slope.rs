//! Slopes for the `runner` and `walker` controllers: how a controlled body stands on, walks
//! up and down, and is stopped by a surface that is neither flat nor vertical.
//!
//! Every `separate` contact of a controlled dynamic body with a static or kinematic body is
//! read by its normal `up` (out of the surface, towards the body), whatever the surface's
//! shape: a polygon ramp, a rotated box, a circle, any static's contact.
//! - `up = (0, 1)` exactly (flat ground), `up.y < 0` (ceilings, overhangs) and every contact
//!   of a body without a controller: the push along the normal, as before (`push.rs`).
//! - Ground: `up.y > 0`, `up.x != 0` and at most [`WorldDef::max_climb_angle`] from the
//!   vertical (`up.y >= cos(angle) - `[`CLIMB_TOLERANCE`]). The body is lifted straight up
//!   by `depth / up.y`, which takes it exactly out of the surface without moving it along
//!   x (so it never slides down when idle), and only its downward velocity is removed (its
//!   run along x never becomes an upward speed, so it does not fly off the crest). It is
//!   grounded. Rapier's character controller climbs the same way (`max_slope_climb_angle`),
//!   converting the blocked part of a horizontal move into a climb.
//! - Wall: `up.y >= 0`, `up.x != 0` and steeper than the climb angle. The body is pushed
//!   straight out along x by `depth / up.x`, its velocity into the surface along x removed
//!   (it keeps falling), and a walker moving into it turns round. Not grounded.
//!
//! The snap to the ground (rapier's `snap_to_ground`): a controlled body that started the
//! frame grounded, is not moving up, and ended the frame's motion and `detect` in the air,
//! is swept straight down by at most `|dx| * tan(max_climb_angle)` (the height a climbable
//! slope drops over the frame's move along x, `dx`) plus [`SLOP`]. If it meets a static
//! surface it could stand on within that, it is put there (flush, within the time of
//! impact's gap) and grounded: walking down a ramp it never leaves the ground, and walking
//! off a ledge it falls as before (a ledge drops further than the reach). The snap only
//! runs in a scene with a static body that is not an axis-aligned box in a `separate`
//! layer: a scene of box tiles runs exactly as it always did.
//!
//! A crest onto a box tile: in such a scene, `resolve_x` does not stop a body noted for the
//! snap at the side of a static box whose top is above its bottom by no more than that
//! reach ([`SlopeState::steps_onto`]); `resolve_y` lifts it on top. A ramp meeting a tile
//! of its plateau's height would otherwise hold the body back for a frame at the crest.

use std::f64::consts::PI;

use ricochet_geom::{Pose, Sweep, Vec2, time_of_impact};

use crate::def::{BodyKind, Controller, Response, WorldDef};
use crate::entity::Entity;
use crate::stages::SLOP;
use crate::stages::push::Statics;
use crate::stages::separate::is_box;
use crate::world::World;

/// How much a surface's normal may fall short of the climb angle's cosine and still be
/// ground: a 45° ramp's computed normal is `cos 45°` within a few ulps either side, and
/// must be climbable at the default 45°. `1e-9` of a cosine is about `1.4e-9` rad at 45°.
pub const CLIMB_TOLERANCE: f64 = 1e-9;

/// The world's climb angle ([`WorldDef::max_climb_angle`], degrees); its cosine and
/// tangent through libm (the same bits everywhere), computed only when a controlled body
/// meets a sloped surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Climb(f64);

impl Climb {
    /// The world's climb angle.
    pub(crate) fn of(def: &WorldDef) -> Climb {
        Climb(def.max_climb_angle)
    }

    fn radians(self) -> f64 {
        self.0 * (PI / 180.0)
    }

    /// Whether a surface of upward normal `up` (`up.y > 0`) is ground.
    fn climbable(self, up: Vec2) -> bool {
        up.y >= libm::cos(self.radians()) - CLIMB_TOLERANCE
    }

    /// How far a climbable slope drops over `dx` along x.
    fn drop_over(self, dx: f64) -> f64 {
        dx * libm::tan(self.radians())
    }
}

/// What a sloped surface is to a controlled body.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Surface {
    /// It stands and walks on it.
    Ground,
    /// Too steep: it is stopped along x.
    Wall,
}

/// Whether `i` is a dynamic body with a `runner` or `walker` controller.
fn walks(w: &World, i: usize) -> bool {
    w.kind[i] == BodyKind::Dynamic
        && matches!(
            w.controller(i),
            Some(Controller::Runner { .. } | Controller::Walker { .. })
        )
}

/// What the surface of body `other`, of upward normal `up` (out of it, towards `i`), is to
/// body `i`: `None` when the push along the normal answers (see the module docs).
pub(crate) fn surface(
    w: &World,
    i: usize,
    other: usize,
    up: Vec2,
    climb: Climb,
) -> Option<Surface> {
    if up.x == 0.0 || up.y < 0.0 || w.kind[other] == BodyKind::Dynamic || !walks(w, i) {
        return None;
    }
    Some(if up.y > 0.0 && climb.climbable(up) {
        Surface::Ground
    } else {
        Surface::Wall
    })
}

/// Moves body `i` out of `other` (by `depth` along `up`) as `surface` says, and returns the
/// move.
pub(crate) fn stand(
    w: &mut World,
    (i, other): (usize, usize),
    up: Vec2,
    depth: f64,
    surface: Surface,
) -> Vec2 {
    match surface {
        Surface::Ground => {
            let lift = Vec2::new(0.0, depth / up.y);
            w.position_mut(i).y += lift.y;
            let v = w.velocity_mut(i);
            if v.y < 0.0 {
                v.y = 0.0;
            }
            *w.grounded_mut(i) = true;
            *w.on_static_mut(i) |= w.kind[other] == BodyKind::Static;
            lift
        }
        Surface::Wall => {
            let push = Vec2::new(depth / up.x, 0.0);
            w.position_mut(i).x += push.x;
            let v = w.velocity_mut(i);
            if v.x * up.x < 0.0 {
                v.x = 0.0;
            }
            if let Some(Controller::Walker { speed }) = w.controller_mut(i)
                && *speed * up.x < 0.0
            {
                *speed = -*speed;
            }
            push
        }
    }
}

/// What the snap to the ground keeps: whether the scene has a surface to snap to, and the
/// frame's controlled bodies that started it grounded.
#[derive(Debug, Default, Clone)]
pub(crate) struct SlopeState {
    /// The static generation `any_slope` was found at.
    static_generation: Option<u64>,
    /// Whether a static body of a `separate` layer is not an axis-aligned box.
    any_slope: bool,
    /// This frame's controlled bodies grounded at its start (before `unground`).
    grounded: Vec<Entity>,
    /// The static bodies a snap is swept against.
    statics: Statics,
}

impl SlopeState {
    /// Before `unground`: notes the active controlled bodies grounded now (at the end of
    /// the last frame), in a scene with a sloped static body.
    pub(crate) fn start_frame(&mut self, w: &World, def: &WorldDef) {
        self.grounded.clear();
        if !w.any_controller() {
            return;
        }
        if self.static_generation != Some(w.static_generation()) {
            self.static_generation = Some(w.static_generation());
            let layers = &def.layers;
            let n = layers.names().len();
            let separating: Vec<bool> = (0..n)
                .map(|l| (0..n).any(|m| layers.response(l as u8, m as u8) == Response::Separate))
                .collect();
            self.any_slope = (0..w.len()).any(|i| {
                w.kind[i] == BodyKind::Static
                    && separating[usize::from(w.layer[i])]
                    && !is_box(w.shape(i))
            });
        }
        if !self.any_slope {
            return;
        }
        for &i in w.active() {
            let i = i as usize;
            if w.grounded(i) && walks(w, i) {
                self.grounded.push(w.entity[i]);
            }
        }
    }

    /// Whether `resolve_x` lets body `i` (bounds `bi`) walk onto the static box `bj` it
    /// overlaps instead of stopping it: `i` is a runner or walker that started the frame
    /// grounded in a scene with a sloped static (noted by [`SlopeState::start_frame`]), and
    /// its bottom is below the box's top by no more than a climbable slope rises over its
    /// move along x this frame (plus [`SLOP`]). That is a ramp's crest meeting a tile of
    /// the plateau's height: without it the tile's side would hold the body back for the
    /// frame it is still below the crest. `resolve_y` then lifts it on top.
    pub(crate) fn steps_onto(
        &self,
        w: &World,
        def: &WorldDef,
        i: usize,
        (bi, bj): (&ricochet_geom::Bounds, &ricochet_geom::Bounds),
    ) -> bool {
        let rise = bj.max.y - bi.min.y;
        if self.grounded.is_empty() || rise <= 0.0 || !self.grounded.contains(&w.entity[i]) {
            return false;
        }
        let dx = (w.position[i].x - w.start_position(i).x).abs();
        rise <= Climb::of(def).drop_over(dx) + SLOP
    }

    /// Whether a body may snap this frame.
    pub(crate) fn has_work(&self) -> bool {
        !self.grounded.is_empty()
    }

    /// After `detect`: snaps each body noted by [`SlopeState::start_frame`] that is now in
    /// the air and not moving up down onto the ground within its reach (module docs).
    pub(crate) fn snap(&mut self, w: &mut World, def: &WorldDef) {
        let climb = Climb::of(def);
        let layers = &def.layers;
        self.statics.refresh(w, layers);
        for k in 0..self.grounded.len() {
            let Some(i) = w.index_of(self.grounded[k]) else {
                continue;
            };
            if w.grounded(i) || w.velocity(i).y > 0.0 || w.frozen(i) || w.asleep(i) {
                continue;
            }
            let from = w.position[i];
            let reach = climb.drop_over((from.x - w.start_position(i).x).abs()) + SLOP;
            let (shape, angle) = (w.shape(i), w.angle[i]);
            let mut region = shape.bounds(&Pose::new(from, angle));
            region.min.y -= reach;
            self.statics.near(w, layers, i, &region);
            let sweep = Sweep {
                start: from,
                end: Vec2::new(from.x, from.y - reach),
                angle,
            };
            let mut best: Option<(f64, Vec2)> = None;
            for &s in self.statics.found() {
                let s = s as usize;
                let pose = w.pose(s);
                let fixed = Sweep {
                    start: pose.position,
                    end: pose.position,
                    angle: pose.angle,
                };
                let Some(hit) = time_of_impact(shape, &sweep, w.shape(s), &fixed) else {
                    continue;
                };
                let up = -hit.contact.normal;
                let ground = up.y > 0.0 && (up.x == 0.0 || climb.climbable(up));
                if ground && best.is_none_or(|(t, _)| hit.t < t) {
                    best = Some((hit.t, hit.pose_a.position));
                }
            }
            if let Some((_, at)) = best {
                w.position_mut(i).y = at.y;
                let v = w.velocity_mut(i);
                if v.y < 0.0 {
                    v.y = 0.0;
                }
                *w.grounded_mut(i) = true;
                *w.on_static_mut(i) = true;
            }
        }
    }
}
