//! Controls, forces and motion: semi-implicit Euler, exactly `v += a*dt; x += v*dt`, a rider
//! first carried by what it stands on (`stages/carry.rs`).

use ricochet_geom::Vec2;

use crate::def::{BodyKind, Controller, WorldDef};
use crate::stages::carry;
use crate::world::{Inputs, World};

/// Whether an active body is grounded.
pub(crate) fn has_grounded(w: &World) -> bool {
    w.any_active_grounded()
}

/// Every body starts the frame's motion airborne; `resolve_y` (a push upwards) or `detect`
/// (a `separate` normal pointing up) grounds it again. The script ran first, so a `jump`
/// saw the previous frame's answer.
/// Sleeping and frozen bodies keep theirs: they are exactly where they were.
pub(crate) fn unground(w: &mut World) {
    for k in 0..w.active().len() {
        let i = w.active()[k] as usize;
        *w.grounded_mut(i) = false;
        *w.on_static_mut(i) = false;
    }
}

/// Whether an active body has a controller.
pub(crate) fn has_controls(w: &World) -> bool {
    w.any_controller() && w.any_active_controller()
}

/// Inputs become velocities: a ship's turn input sets its angular velocity, a runner's or
/// walker's sets its x velocity. Thrust is a force, applied in `forces`.
pub(crate) fn controls(w: &mut World) {
    if !w.any_controller() {
        return;
    }
    #[cfg(debug_assertions)]
    let expected: Vec<usize> = (w.active().iter().map(|&i| i as usize))
        .filter(|&i| w.controller(i).is_some())
        .collect();
    #[cfg(debug_assertions)]
    let mut visited = Vec::new();
    // The bodies with a controller, in the active bodies' (dense) order: each body's new
    // velocity reads only its own inputs, so the order changes nothing anyway.
    for k in 0..w.controlled_count() {
        let Some(i) = w.active_controlled(k) else {
            continue;
        };
        #[cfg(debug_assertions)]
        visited.push(i);
        match w.controller(i) {
            Some(Controller::Ship { turn_rate, .. }) => {
                *w.angular_velocity_mut(i) = w.inputs(i).turn * turn_rate;
            }
            Some(Controller::Runner { run_speed, .. }) => {
                w.velocity_mut(i).x = w.inputs(i).run * run_speed;
            }
            Some(Controller::Walker { speed }) => w.velocity_mut(i).x = *speed,
            None => {}
        }
    }
    #[cfg(debug_assertions)]
    assert_eq!(visited, expected, "the active bodies with a controller");
}

/// The ship's engine force along its heading, when the engine is on.
fn thrust(controller: &Controller, inputs: &Inputs, angle: f64) -> Vec2 {
    match controller {
        Controller::Ship { thrust, .. } if inputs.thrust => {
            let (s, c) = heading(angle);
            Vec2::new(c, s) * *thrust
        }
        _ => Vec2::ZERO,
    }
}

/// `(sin, cos)` of a heading, through `libm`: the same bits on every platform.
#[cfg(not(feature = "gate-self-test-std-sin"))]
fn heading(angle: f64) -> (f64, f64) {
    libm::sincos(angle)
}

/// The determinism gate's self-test only (`scripts/determinism-gate.sh --self-test`): the
/// platform's `sin` and `cos`, which differ between glibc and wasm32 in the last bit for some
/// angles, so the gate must fail. Never on in a real build.
#[cfg(feature = "gate-self-test-std-sin")]
#[expect(
    clippy::disallowed_methods,
    reason = "the gate's self-test puts platform trigonometry in on purpose"
)]
fn heading(angle: f64) -> (f64, f64) {
    angle.sin_cos()
}

/// Whether any force (gravity, thrust, a constant force) acts on a body.
pub(crate) fn has_forces(w: &World, def: &WorldDef) -> bool {
    let g = def.gravity;
    let dynamic = |i: usize| w.kind[i] == BodyKind::Dynamic;
    // Gravity first (its first dynamic body usually answers), then thrust (only controlled
    // bodies have inputs), then a constant force on an active body.
    (g != Vec2::ZERO
        && w.active().iter().any(|&i| {
            let i = i as usize;
            dynamic(i) && w.gravity_scale(i) != 0.0
        }))
        || (w.any_controller() && w.any_thrust_input())
        // One contiguous column beats a gather through the active list; a static body's
        // force only makes the stage run for nothing.
        || w.any_force()
}

/// `a = sum(f) / m` with gravity as the force `m * g * gravity_scale`; `v += a * dt`.
pub(crate) fn forces(w: &mut World, def: &WorldDef) {
    w.accelerate(def.dt, def.gravity, thrust);
}

/// Whether an active body has a velocity.
pub(crate) fn has_motion(w: &World) -> bool {
    w.active()
        .iter()
        .any(|&i| w.velocity(i as usize) != Vec2::ZERO)
}

/// `position[axis] += velocity[axis] * dt` for every active body, a rider first carried by
/// its carrier's displacement along the axis (`stages/carry.rs`).
/// Without per-axis layer pairs (`carries` false) no body has a carrier, and the loop reads
/// no carrier column.
fn move_axis(w: &mut World, dt: f64, axis: usize, carries: bool) {
    for k in 0..w.active().len() {
        let i = w.active()[k] as usize;
        if carries && w.carrier(i).is_some() {
            let d = carry::displacement(w, i, axis, dt);
            // Nothing is added for no motion: `-0.0 + 0.0` would change a zero's sign.
            if d != 0.0 {
                w.position[i][axis] += d;
            }
        }
        w.position[i][axis] += w.velocity(i)[axis] * dt;
    }
}

/// A rider's `x += carrier's vx * dt`, then everyone's `x += vx * dt`.
pub(crate) fn move_x(w: &mut World, dt: f64, carries: bool) {
    move_axis(w, dt, 0, carries);
}

/// A rider's `y += carrier's vy * dt`, then everyone's `y += vy * dt`.
pub(crate) fn move_y(w: &mut World, dt: f64, carries: bool) {
    move_axis(w, dt, 1, carries);
}

/// Whether an active body has an angular velocity.
pub(crate) fn has_turning(w: &World) -> bool {
    w.active()
        .iter()
        .any(|&i| w.angular_velocity(i as usize) != 0.0)
}

/// `angle += angular_velocity * dt`.
pub(crate) fn turn(w: &mut World, dt: f64) {
    for k in 0..w.active().len() {
        let i = w.active()[k] as usize;
        w.angle[i] += w.angular_velocity(i) * dt;
    }
}
