//! Controls, forces and motion: semi-implicit Euler, exactly `v += a*dt; x += v*dt`.

use ricochet_geom::Vec2;

use crate::def::{BodyKind, Controller};
use crate::output::FrameOutput;
use crate::pipeline::Simulation;

pub(crate) fn has_grounded(sim: &Simulation) -> bool {
    sim.world.grounded.iter().any(|g| *g)
}

/// Every body starts the frame's motion airborne; `resolve_y` (a push upwards) or `detect`
/// (a `separate` normal pointing up) grounds it again. The script ran first, so a `jump`
/// saw the previous frame's answer.
pub(crate) fn unground(sim: &mut Simulation, _out: &mut FrameOutput) {
    sim.world.grounded.fill(false);
}

pub(crate) fn has_controls(sim: &Simulation) -> bool {
    sim.world.controller.iter().any(Option::is_some)
}

/// Inputs become velocities: a ship's turn input sets its angular velocity, a runner's or
/// walker's sets its x velocity. Thrust is a force, applied in `forces`.
pub(crate) fn controls(sim: &mut Simulation, _out: &mut FrameOutput) {
    let w = &mut sim.world;
    for i in 0..w.len() {
        match &w.controller[i] {
            Some(Controller::Ship { turn_rate, .. }) => {
                w.angular_velocity[i] = w.inputs[i].turn * turn_rate;
            }
            Some(Controller::Runner { run_speed, .. }) => {
                w.velocity[i].x = w.inputs[i].run * run_speed;
            }
            Some(Controller::Walker { speed }) => w.velocity[i].x = *speed,
            None => {}
        }
    }
}

/// The ship's engine force along its heading, when the engine is on.
fn thrust(sim: &Simulation, i: usize) -> Vec2 {
    let w = &sim.world;
    match &w.controller[i] {
        Some(Controller::Ship { thrust, .. }) if w.inputs[i].thrust => {
            let (s, c) = libm::sincos(w.angle[i]);
            Vec2::new(c, s) * *thrust
        }
        _ => Vec2::ZERO,
    }
}

pub(crate) fn has_forces(sim: &Simulation) -> bool {
    let w = &sim.world;
    let g = sim.scenario.world.gravity;
    (0..w.len()).any(|i| {
        w.kind[i] == BodyKind::Dynamic
            && (w.force[i] != Vec2::ZERO
                || w.inputs[i].thrust
                || (g != Vec2::ZERO && w.gravity_scale[i] != 0.0))
    })
}

/// `a = sum(f) / m` with gravity as the force `m * g * gravity_scale`; `v += a * dt`.
pub(crate) fn forces(sim: &mut Simulation, _out: &mut FrameOutput) {
    let dt = sim.dt();
    let g = sim.scenario.world.gravity;
    for i in 0..sim.world.len() {
        if sim.world.kind[i] != BodyKind::Dynamic {
            continue;
        }
        let m = sim.world.mass[i];
        let sum = sim.world.force[i] + thrust(sim, i) + g * (m * sim.world.gravity_scale[i]);
        let a = sum / m;
        sim.world.velocity[i] += a * dt;
    }
}

pub(crate) fn has_motion(sim: &Simulation) -> bool {
    let w = &sim.world;
    (0..w.len()).any(|i| w.kind[i] != BodyKind::Static && w.velocity[i] != Vec2::ZERO)
}

fn move_axis(sim: &mut Simulation, axis: usize) {
    let dt = sim.dt();
    let w = &mut sim.world;
    for i in 0..w.len() {
        if w.kind[i] != BodyKind::Static {
            w.position[i][axis] += w.velocity[i][axis] * dt;
        }
    }
}

/// `x += vx * dt`.
pub(crate) fn move_x(sim: &mut Simulation, _out: &mut FrameOutput) {
    move_axis(sim, 0);
}

/// `y += vy * dt`.
pub(crate) fn move_y(sim: &mut Simulation, _out: &mut FrameOutput) {
    move_axis(sim, 1);
}

pub(crate) fn has_turning(sim: &Simulation) -> bool {
    let w = &sim.world;
    (0..w.len()).any(|i| w.kind[i] != BodyKind::Static && w.angular_velocity[i] != 0.0)
}

/// `angle += angular_velocity * dt`.
pub(crate) fn turn(sim: &mut Simulation, _out: &mut FrameOutput) {
    let dt = sim.dt();
    let w = &mut sim.world;
    for i in 0..w.len() {
        if w.kind[i] != BodyKind::Static {
            w.angle[i] += w.angular_velocity[i] * dt;
        }
    }
}
