//! The limits a definition is checked against: the masses a dynamic body may have, the
//! length and timestep a log can hold, and how large a body may be in a wrapping world.
//! Each says why it is where it is; `load/` turns a value past one into a named error.

use ricochet_geom::{Number, Primitive, Rot, Shape, Vec2};

use crate::def::{BodyDef, Controller, WorldBounds, WorldDef};

/// The lightest mass a dynamic body may have (mass units): an impulse of 1 gives it
/// 1e12 units/s, past which every push is an overflow waiting to happen.
pub const MIN_MASS: f64 = 1e-12;
/// The heaviest mass a dynamic body may have (mass units), [`ricochet_geom::MAX_COORDINATE`]
/// as for sizes: `mass = 1e300` made `/stats.kinetic_energy` infinite at 1e4 units/s, while a
/// body of this mass reaches it only past 1e146 units/s (and a run stops there, see
/// `Simulation::first_non_finite`).
pub const MAX_MASS: f64 = 1e15;

/// The most steps a run may have after frame 0: a scenario's `frames` and a `--frames`
/// override alike.
pub const MAX_FRAMES: u64 = 100_000_000;

/// The most frames [`crate::Simulation::keep_history`] keeps: 4.3 s at 60 Hz, past any lag
/// a game compensates (Source rewinds at most 1 s by default; Unity's Netcode keeps 32
/// frames). A kept frame costs 24 bytes a body (position 16, angle 8), 13 more (entity 8,
/// look id 4, layer 1) when a body was added, removed or reshaped since the frame before
/// (frames of one layout share one copy), and about 60 more once a query has indexed it
/// (its trees): 256 frames of 10,000 bodies hold 61 to 95 MB, up to 250 MB if every one
/// of them was queried.
pub const MAX_HISTORY: usize = 256;

/// Whether `degrees` is a [`WorldDef::max_climb_angle`] the stages can use: finite, from 0
/// to less than [`crate::def::MAX_CLIMB_ANGLE_LIMIT`].
pub(crate) fn climb_angle_ok(degrees: f64) -> bool {
    degrees.is_finite() && (0.0..crate::def::MAX_CLIMB_ANGLE_LIMIT).contains(&degrees)
}

/// The problem with a `max_climb_angle` that is not [`climb_angle_ok`].
pub(crate) fn climb_angle_problem(degrees: f64) -> String {
    format!(
        "must be a number of degrees from 0 to less than {}, got {}",
        Number(crate::def::MAX_CLIMB_ANGLE_LIMIT),
        Number(degrees)
    )
}

/// Why a run's length or timestep cannot be logged: every frame's time must be a distinct
/// whole number of nanoseconds that fits in a `u64` (`log_time = frame * dt_ns`).
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum RunLengthError {
    /// More frames than [`MAX_FRAMES`].
    #[error("must be 0 to {MAX_FRAMES} frames, got {0}")]
    TooManyFrames(u64),
    /// The timestep is below half a nanosecond: every frame would be logged at time 0.
    #[error(
        "a timestep of {} s rounds to 0 ns; logs count time in whole nanoseconds",
        Number(*.0)
    )]
    StepRoundsToZero(f64),
    /// The last frame's time is past `u64::MAX` nanoseconds (about 584 years).
    #[error(
        "frame {frames} at {} s per step is past the last time a log can hold \
         (2^64 ns, about 584 years)",
        Number(*.dt)
    )]
    TooLong {
        /// Frames after frame 0.
        frames: u64,
        /// Seconds per step.
        dt: f64,
    },
}

impl WorldDef {
    /// Whole nanoseconds per step, the unit of every log time, or why the timestep can't
    /// be logged.
    ///
    /// # Errors
    /// The step rounds to 0 ns, or is longer than a log can hold.
    pub fn dt_ns(&self) -> Result<u64, RunLengthError> {
        let ns = (self.dt * 1e9).round();
        // NaN (never: dt is checked finite) and anything below half a nanosecond.
        if ns.is_nan() || ns < 1.0 {
            return Err(RunLengthError::StepRoundsToZero(self.dt));
        }
        // 2^64 is exactly representable; anything at or past it does not fit.
        if ns >= 18_446_744_073_709_551_616.0 {
            return Err(RunLengthError::TooLong {
                frames: 1,
                dt: self.dt,
            });
        }
        Ok(ns as u64)
    }

    /// The log time of the last frame of a run of `frames` steps after frame 0, checked.
    ///
    /// # Errors
    /// Too many frames, or a timestep or length a log's `u64` nanoseconds cannot hold.
    pub fn last_time_ns(&self, frames: u64) -> Result<u64, RunLengthError> {
        if frames > MAX_FRAMES {
            return Err(RunLengthError::TooManyFrames(frames));
        }
        let dt_ns = self.dt_ns()?;
        frames.checked_mul(dt_ns).ok_or(RunLengthError::TooLong {
            frames,
            dt: self.dt,
        })
    }
}

/// The largest magnitude of a controller's values (`thrust`, `turn_rate`, `bullet_speed`,
/// `muzzle`, `run_speed`, `jump_speed`, `speed`): [`ricochet_geom::MAX_COORDINATE`], the
/// largest velocity a script or a client may set. A faster bullet (`bullet_speed = 5.5e20`
/// in a damaged snapshot) only makes every frame's swept tests longer.
pub const MAX_CONTROLLER_VALUE: f64 = ricochet_geom::MAX_COORDINATE;

/// The first of a controller's values (field name, value) that is not finite or past
/// [`MAX_CONTROLLER_VALUE`], if any: what the loader refuses, and a snapshot's restore.
#[must_use]
pub fn controller_out_of_range(c: &Controller) -> Option<(&'static str, f64)> {
    let values: &[(&'static str, f64)] = match c {
        Controller::Ship {
            thrust,
            turn_rate,
            bullet_speed,
            muzzle,
            ..
        } => &[
            ("thrust", *thrust),
            ("turn_rate", *turn_rate),
            ("bullet_speed", *bullet_speed),
            ("muzzle", *muzzle),
        ],
        Controller::Runner {
            run_speed,
            jump_speed,
        } => &[("run_speed", *run_speed), ("jump_speed", *jump_speed)],
        Controller::Walker { speed } => &[("speed", *speed)],
    };
    values
        .iter()
        .find(|(_, v)| !(v.is_finite() && v.abs() <= MAX_CONTROLLER_VALUE))
        .copied()
}

/// `def` with its mass and controller values brought within the loader's limits, if any is
/// past them (`None`: `def` is within them). NaN stays NaN: only
/// [`crate::Simulation::try_spawn`] and [`crate::Scenario::check`] refuse it.
pub(crate) fn within_limits(def: &BodyDef) -> Option<BodyDef> {
    let c = |v: &mut f64| *v = v.clamp(-MAX_CONTROLLER_VALUE, MAX_CONTROLLER_VALUE);
    let mass_out = !(MIN_MASS..=MAX_MASS).contains(&def.mass) && !def.mass.is_nan();
    let controller_out = def
        .controller
        .as_ref()
        .and_then(controller_out_of_range)
        .is_some_and(|(_, v)| !v.is_nan());
    if !(mass_out || controller_out) {
        return None;
    }
    let mut def = def.clone();
    def.mass = def.mass.clamp(MIN_MASS, MAX_MASS);
    match &mut def.controller {
        Some(Controller::Ship {
            thrust,
            turn_rate,
            bullet_speed,
            muzzle,
            ..
        }) => [thrust, turn_rate, bullet_speed, muzzle]
            .into_iter()
            .for_each(c),
        Some(Controller::Runner {
            run_speed,
            jump_speed,
        }) => [run_speed, jump_speed].into_iter().for_each(c),
        Some(Controller::Walker { speed }) => c(speed),
        None => {}
    }
    Some(def)
}

/// How far a shape reaches from its body's origin along x and along y, at any angle of the
/// body: for a part that turns with the body (all but an AABB's box), the distance of its
/// furthest point; for an AABB, its centre's distance (the centre turns) plus its half
/// extents (the box does not).
#[must_use]
pub fn shape_reach(shape: &Shape) -> Vec2 {
    shape
        .primitives()
        .iter()
        .map(|p| match p {
            Primitive::Circle(c) => Vec2::splat(c.center.length() + c.radius),
            Primitive::Aabb(b) => Vec2::splat(b.center.length()) + b.half_extents,
            Primitive::Obb(b) => {
                let rot = Rot::from_angle(b.angle);
                let h = b.half_extents;
                let far = [h, Vec2::new(h.x, -h.y), -h, Vec2::new(-h.x, h.y)]
                    .iter()
                    .map(|&k| (b.center + rot.apply(k)).length())
                    .fold(0.0, f64::max);
                Vec2::splat(far)
            }
            Primitive::Capsule(c) => Vec2::splat(c.a.length().max(c.b.length()) + c.radius),
            Primitive::Polygon(g) => {
                Vec2::splat(g.vertices().iter().map(|v| v.length()).fold(0.0, f64::max))
            }
            Primitive::Segment(g) => Vec2::splat(g.a.length().max(g.b.length())),
        })
        .fold(Vec2::ZERO, Vec2::max)
}

impl WorldBounds {
    /// In a wrapping world, whether a body of `shape` is too large for the wrap seam's
    /// rule, with its [`shape_reach`] when it is. The rule: a body reaches at most half the
    /// world's width from its position along x, and half its height along y, at any angle.
    /// Why: the seam tests `b` at `-1, 0, 1` world sizes from `a`. Two bodies whose positions
    /// are in the world are less than a world size apart on each axis, so `b`'s images two
    /// or more world sizes away are further than a world size from `a`; with each body
    /// reaching at most half a world size, no such image can touch `a`, and the deepest
    /// image of all is one the seam tests. Past that, a body meets images the seam never
    /// tests, and a contact through a shallower one is logged (issue #20, a body larger than
    /// a 10 x 10 world). `None` in a world that does not wrap.
    #[must_use]
    pub fn oversized(&self, shape: &Shape) -> Option<Vec2> {
        let reach = shape_reach(shape);
        let size = self.size();
        (self.wrap && (2.0 * reach.x > size.x || 2.0 * reach.y > size.y)).then_some(reach)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each primitive's reach, from exact geometry (3-4-5 triangles).
    #[test]
    fn a_shapes_reach_is_its_furthest_point_at_any_angle() {
        let v = Vec2::new;
        let circle = Shape::Primitive(Primitive::circle(v(3.0, 4.0), 1.0).unwrap());
        assert_eq!(shape_reach(&circle), Vec2::splat(6.0));
        // The box does not turn, its centre does: 5 + 1 along x, 5 + 2 along y.
        let aabb = Shape::Primitive(Primitive::aabb(v(3.0, 4.0), v(1.0, 2.0)).unwrap());
        assert_eq!(shape_reach(&aabb), v(6.0, 7.0));
        let obb = Shape::Primitive(Primitive::obb(Vec2::ZERO, v(3.0, 4.0), 0.7).unwrap());
        assert!((shape_reach(&obb).x - 5.0).abs() < 1e-15);
        let capsule = Shape::capsule(v(-3.0, -4.0), v(1.0, 0.0), 0.5).unwrap();
        assert_eq!(shape_reach(&capsule), Vec2::splat(5.5));
        let polygon = Shape::polygon(&[v(0.0, 0.0), v(3.0, 0.0), v(3.0, 4.0)]).unwrap();
        assert_eq!(shape_reach(&polygon), Vec2::splat(5.0));
        let parts = vec![
            Primitive::aabb(Vec2::ZERO, v(1.0, 2.0)).unwrap(),
            Primitive::circle(Vec2::ZERO, 1.5).unwrap(),
        ];
        let compound = Shape::compound(parts).unwrap();
        assert_eq!(shape_reach(&compound), v(1.5, 2.0));
        let world = |wrap| WorldBounds {
            min: Vec2::ZERO,
            max: v(12.0, 11.0),
            wrap,
        };
        // 2 * 5.5 = 11 fits both axes; 2 * 6 = 12 fits x, not the 11 of y.
        assert_eq!(world(true).oversized(&capsule), None);
        assert_eq!(world(true).oversized(&circle), Some(Vec2::splat(6.0)));
        assert_eq!(world(false).oversized(&circle), None);
    }
}
