//! Free flight in both engines: the scenario's moving bodies with every collision response
//! off, stepped by Ricochet and by rapier's `PhysicsPipeline`, compared frame by frame.

use rapier2d_f64::math::Vector;
use rapier2d_f64::prelude::{MassProperties, PhysicsWorld, RigidBodyBuilder, RigidBodyHandle};
use ricochet_geom::Vec2;
use ricochet_sim::{BodyKind, Layers, Scenario, Simulation};

use crate::convert::{from_vector, to_vector};

/// Position bound of [`compare_motion`], relative: at frame `n` a body passes when its
/// position differs by at most `MOTION_POSITION_RELATIVE * n * scale`, where `scale` is the
/// largest of `1`, `|x_0|`, `n |v_0| dt` and `n² |a| dt²` (the magnitudes the sums of
/// semi-implicit Euler run through). Each step rounds a handful of additions and
/// multiplications in each engine, each off by half an ulp of `scale` at most; the two engines
/// also order the force arithmetic differently (`(f + m g s) / m` against `f * (1/m) + g s`).
/// Measured: bit-identical positions on every scenario and on a test of odd masses, forces
/// and gravity scales, so any difference at all is rounding; the bound is the rounding
/// budget, not a fit.
pub const MOTION_POSITION_RELATIVE: f64 = 1e-14;

/// Angle bound of [`compare_motion`], radians per frame: at frame `n` a body passes when its
/// angle differs by at most `MOTION_ANGLE_PER_FRAME * n * (1 + |θ_n|)`, once rapier's
/// linearised rotation is accounted for (see [`compare_motion`]).
pub const MOTION_ANGLE_PER_FRAME: f64 = 1e-14;

/// One body's free flight compared.
#[derive(Clone, Debug, PartialEq)]
pub struct BodyMotion {
    /// The body's name in the scenario.
    pub name: String,
    /// `dynamic` or `kinematic`.
    pub kind: &'static str,
    /// Largest distance between the two engines' positions, world units.
    pub max_position_error: f64,
    /// The same, divided by the frame's bound (`<= 1` passes).
    pub worst_position_ratio: f64,
    /// Largest difference between the angles, radians, after the rotation correction.
    pub max_angle_error: f64,
    /// The same, divided by the frame's bound (`<= 1` passes).
    pub worst_angle_ratio: f64,
    /// Largest difference between rapier's raw angle and Ricochet's, radians: rapier turns a
    /// body by `atan(ω dt)` per step, not `ω dt` (see [`compare_motion`]).
    pub raw_angle_difference: f64,
}

impl BodyMotion {
    /// Whether both errors stayed within their bounds at every frame.
    #[must_use]
    pub fn passed(&self) -> bool {
        self.worst_position_ratio <= 1.0 && self.worst_angle_ratio <= 1.0
    }
}

/// Free-flight trajectories of a scenario compared between Ricochet and rapier.
#[derive(Clone, Debug, PartialEq)]
pub struct MotionReport {
    /// Frames stepped after frame 0.
    pub frames: u64,
    /// Every dynamic and kinematic body of the scenario, in id order.
    pub bodies: Vec<BodyMotion>,
    /// Largest position error over all bodies and frames.
    pub max_position_error: f64,
    /// Largest angle error (after the rotation correction) over all bodies and frames.
    pub max_angle_error: f64,
}

impl MotionReport {
    /// Whether every body stayed within the bounds at every frame.
    #[must_use]
    pub fn passed(&self) -> bool {
        self.bodies.iter().all(BodyMotion::passed)
    }
}

/// The scenario with nothing but motion left: every layer pair ignored, no script, no
/// controllers, no lifetimes, no world bounds (rapier has no wrap-around).
fn free_flight(scenario: &Scenario) -> Scenario {
    let mut s = scenario.clone();
    s.world.layers = Layers::new(s.world.layers.names().to_vec());
    s.world.bounds = None;
    // Free flight checks integration: every body integrates, none is frozen or asleep.
    s.world.active_region = None;
    s.world.sleep_after = None;
    s.script.clear();
    for b in &mut s.bodies {
        b.controller = None;
        b.lifetime = None;
    }
    s
}

/// `a - b` wrapped into `(-π, π]`.
fn angle_difference(a: f64, b: f64) -> f64 {
    let tau = std::f64::consts::TAU;
    let d = (a - b).rem_euclid(tau);
    if d > std::f64::consts::PI { d - tau } else { d }
}

/// Rapier set up to integrate Ricochet's model (see [`compare_motion`]): the scenario's
/// moving bodies, by index into `s.bodies`, and their handles.
fn rapier_world(s: &Scenario) -> (PhysicsWorld, Vec<(usize, RigidBodyHandle)>) {
    let mut world = PhysicsWorld::new();
    world.gravity = to_vector(s.world.gravity);
    world.integration_parameters.dt = s.world.dt;
    world.integration_parameters.num_solver_iterations = 1;
    world.integration_parameters.normalized_max_linear_velocity = f64::MAX;
    let mut handles = Vec::new();
    for (index, b) in s.bodies.iter().enumerate() {
        let builder = match b.kind {
            BodyKind::Static => continue,
            BodyKind::Dynamic => RigidBodyBuilder::dynamic().gravity_scale(b.gravity_scale),
            BodyKind::Kinematic => RigidBodyBuilder::kinematic_velocity_based(),
        };
        let body = builder
            .translation(to_vector(b.position))
            .rotation(b.angle)
            .linvel(to_vector(b.velocity))
            .angvel(b.angular_velocity)
            .additional_mass_properties(MassProperties::new(Vector::ZERO, b.mass, b.mass))
            .can_sleep(false)
            .ccd_enabled(false)
            .build();
        let handle = world.insert_body(body);
        if b.kind == BodyKind::Dynamic {
            // Rapier keeps user forces until `reset_forces`: added once, they act every step.
            world.bodies[handle].add_force(to_vector(b.force), true);
        }
        handles.push((index, handle));
    }
    (world, handles)
}

/// Rapier's free flight of the scenario's moving bodies (every collision response off, as in
/// [`compare_motion`]) after `frames` steps: `(index into scenario.bodies, position)`. Used
/// by `ricochet accuracy` to put rapier's error beside Ricochet's on the same scene and dt.
#[must_use]
pub fn rapier_free_flight(scenario: &Scenario, frames: u64) -> Vec<(usize, Vec2)> {
    let (mut world, handles) = rapier_world(&free_flight(scenario));
    for _ in 0..frames {
        world.step();
    }
    handles
        .into_iter()
        .map(|(i, h)| (i, from_vector(world.bodies[h].translation())))
        .collect()
}

/// The worse of two errors, NaN winning: a comparison that can't be made (an infinite or NaN
/// state on either side) must fail, never pass because `f64::max` drops NaN.
fn worst(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

/// `err / bound`, or NaN (a failure) when the bound itself is not a finite positive number.
fn ratio(err: f64, bound: f64) -> f64 {
    if bound.is_finite() && bound > 0.0 {
        err / bound
    } else {
        f64::NAN
    }
}

/// Runs the scenario's dynamic and kinematic bodies in free flight (every layer pair
/// ignored, no script, controllers, lifetimes, world bounds, culling or sleeping) for
/// `frames` steps in both Ricochet and rapier, and compares positions and angles after
/// every step.
///
/// Rapier is set up to integrate the same model: one substep per step
/// (`num_solver_iterations = 1`) of `dt`, the scenario's gravity, no damping, no CCD, no
/// sleeping, no speed cap, no colliders; each body's mass at its origin (Ricochet has no
/// centre of mass: a body turns about its origin), its velocity, angular velocity,
/// `gravity_scale`, and its constant force added once (rapier keeps user forces until
/// `reset_forces`). Kinematic bodies are velocity-based kinematic bodies.
///
/// Rapier's solver turns a body by the linearised rotation `(1 + i ω dt)`, normalised: by
/// `atan(ω dt)` per step rather than `ω dt` (`integrate_linearized`), about `(ω dt)³ / 3`
/// less per step, dynamic and kinematic bodies alike. So the angle is compared against
/// rapier's angle plus `n (ω dt - atan(ω dt))`; [`BodyMotion::raw_angle_difference`] keeps
/// the uncorrected figure.
#[must_use]
pub fn compare_motion(scenario: &Scenario, frames: u64) -> MotionReport {
    let s = free_flight(scenario);
    let dt = s.world.dt;
    let mut sim = Simulation::new(&s);
    sim.step(); // frame 0: the initial state, nothing moves

    let (mut world, handles) = rapier_world(&s);

    struct Tracked {
        index: usize,
        handle: RigidBodyHandle,
        x0: Vec2,
        v0: Vec2,
        accel: Vec2,
        omega: f64,
        report: BodyMotion,
    }
    let tracked_bodies = handles.into_iter().map(|(index, handle)| {
        let b = &s.bodies[index];
        let accel = if b.kind == BodyKind::Dynamic {
            b.force / b.mass + s.world.gravity * b.gravity_scale
        } else {
            Vec2::ZERO
        };
        Tracked {
            index,
            handle,
            x0: b.position,
            v0: b.velocity,
            accel,
            omega: b.angular_velocity,
            report: BodyMotion {
                name: b.name.clone(),
                kind: b.kind.name(),
                max_position_error: 0.0,
                worst_position_ratio: 0.0,
                max_angle_error: 0.0,
                worst_angle_ratio: 0.0,
                raw_angle_difference: 0.0,
            },
        }
    });
    let mut tracked: Vec<Tracked> = tracked_bodies.collect();
    // A scenario's tile rows are spawned first (ids 0 on), its bodies after them: body `i`
    // is the world's slot `tiles + i` (nothing is removed in free flight).
    let tiles: usize = s.tiles.iter().map(ricochet_sim::TileRows::len).sum();

    for n in 1..=frames {
        sim.step();
        world.step();
        let nf = n as f64;
        for t in &mut tracked {
            let rb = &world.bodies[t.handle];
            let p_rapier = from_vector(rb.translation());
            let a_rapier = rb.rotation().angle();
            let p = sim.world().position[tiles + t.index];
            let a = sim.world().angle[tiles + t.index];

            let scale = 1.0_f64
                .max(t.x0.length())
                .max(nf * t.v0.length() * dt)
                .max(nf * nf * t.accel.length() * dt * dt);
            let err = (p_rapier - p).length();
            let bound = MOTION_POSITION_RELATIVE * nf * scale;
            let r = &mut t.report;
            r.max_position_error = worst(r.max_position_error, err);
            r.worst_position_ratio = worst(r.worst_position_ratio, ratio(err, bound));

            let raw = angle_difference(a_rapier, a);
            r.raw_angle_difference = r.raw_angle_difference.max(raw.abs());
            let step = t.omega * dt;
            let lag = nf * (step - libm::atan(step));
            let corrected = angle_difference(a_rapier + lag, a).abs();
            let abound = MOTION_ANGLE_PER_FRAME * nf * (1.0 + a.abs());
            r.max_angle_error = worst(r.max_angle_error, corrected);
            r.worst_angle_ratio = worst(r.worst_angle_ratio, ratio(corrected, abound));
        }
    }

    let bodies: Vec<BodyMotion> = tracked.into_iter().map(|t| t.report).collect();
    MotionReport {
        frames,
        max_position_error: bodies.iter().map(|b| b.max_position_error).fold(0.0, worst),
        max_angle_error: bodies.iter().map(|b| b.max_angle_error).fold(0.0, worst),
        bodies,
    }
}
