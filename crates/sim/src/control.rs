//! What a game does with a running simulation between two steps, addressing bodies by
//! [`Entity`]: create it from definitions built in code, spawn and remove bodies, read a
//! body, and move it. Like Box2D's `b2Body_GetPosition`/`b2Body_SetTransform`: a body that
//! is gone (or whose slot now holds another body) is an error, never another body's data.
//!
//! Writes keep the world's caches right: moving a static body bumps the static generation,
//! so the broad phase and the per-axis stages rebuild their static structures, and wakes
//! the sleepers (what they rested on may have moved); moving any body wakes it.

use ricochet_geom::{Pose, Shape, Vec2};

use crate::action::Action;
use crate::def::{BodyDef, WorldDef};
use crate::entity::Entity;
use crate::output::FrameOutput;
use crate::pipeline::Simulation;
use crate::scenario::{Scenario, TileRows};

/// A body whose state is no longer a finite number (an overflow: gravity of 1e308, a force
/// past what `f64` holds): nothing after it can be trusted, so a run stops there.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error("body {body} has a non-finite {field}: {value:?}")]
pub struct NonFinite {
    /// The body (the lowest id with a non-finite field).
    pub body: Entity,
    /// `position`, `velocity`, `angle`, `angular_velocity`, or `kinetic_energy` (the
    /// body at which the frame's `/stats.kinetic_energy` sum overflowed).
    pub field: &'static str,
    /// The value (`[x, y]` as written, `[angle, 0]`, or `[sum so far, 0]`).
    pub value: [f64; 2],
}

/// Why a definition built in code or a call on a body was refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ControlError {
    /// The entity is not alive (removed, or never spawned in this simulation).
    #[error("no live body has id {}:{}", .0.index, .0.generation)]
    NoSuchBody(Entity),
    /// A world setting is out of range.
    #[error("world.{field}: {problem}")]
    World {
        /// The field (`dt`, `gravity`, `bounds`).
        field: &'static str,
        /// What is wrong.
        problem: &'static str,
    },
    /// A value passed for a body is not finite or beyond the coordinates Ricochet accepts.
    #[error(
        "{field}: must be finite and within ±{:e}",
        ricochet_geom::MAX_COORDINATE
    )]
    OutOfRange {
        /// The field (`position`, `velocity`, `angle`).
        field: &'static str,
    },
    /// The call is for another kind of body (a target pose moves kinematic bodies only).
    #[error("body {body} is {is}, not {needs}")]
    WrongKind {
        /// The body.
        body: Entity,
        /// Its kind.
        is: &'static str,
        /// The kind the call needs.
        needs: &'static str,
    },
}

fn world_error(field: &'static str, problem: &'static str) -> ControlError {
    ControlError::World { field, problem }
}

/// Checks what a scenario file's loader checks of the world settings.
fn check_world(world: &WorldDef) -> Result<(), ControlError> {
    if !(world.dt.is_finite() && world.dt > 0.0) {
        return Err(world_error("dt", "must be a finite number of seconds > 0"));
    }
    if world.dt_ns().is_err() {
        return Err(world_error(
            "dt",
            "must be at least 1 ns and fit in a log's 64-bit nanoseconds",
        ));
    }
    if !(world.gravity.x.is_finite() && world.gravity.y.is_finite()) {
        return Err(world_error("gravity", "must be finite"));
    }
    if let Some(b) = &world.bounds {
        let ok = b.min.is_finite() && b.max.is_finite() && b.min.x < b.max.x && b.min.y < b.max.y;
        if !ok {
            return Err(world_error(
                "bounds",
                "min and max must be finite with min < max on both axes",
            ));
        }
    }
    if let Some(r) = &world.active_region
        && !(r.half_extents.is_finite() && r.half_extents.min_element() > 0.0)
    {
        return Err(world_error(
            "active_region",
            "half_extents must be finite and > 0 on both axes",
        ));
    }
    Ok(())
}

fn within(field: &'static str, v: Vec2) -> Result<Vec2, ControlError> {
    if v.is_finite() && v.abs().max_element() <= ricochet_geom::MAX_COORDINATE {
        Ok(v)
    } else {
        Err(ControlError::OutOfRange { field })
    }
}

impl Simulation {
    /// An empty simulation of `world`, for a scene built in code: add templates with
    /// [`Simulation::add_template`] and bodies with [`Simulation::spawn`].
    ///
    /// # Errors
    /// A world setting a scenario file would be refused for (`dt` not finite and > 0,
    /// non-finite gravity, empty bounds or active region).
    pub fn from_def(world: WorldDef) -> Result<Simulation, ControlError> {
        check_world(&world)?;
        Ok(Simulation::from_scenario(Scenario {
            world,
            ..Scenario::default()
        }))
    }

    /// Adds (or replaces) a template: what a ship's `bullet` and a body's `split` name.
    pub fn add_template(&mut self, name: &str, def: BodyDef) {
        self.scenario.templates.insert(name.to_owned(), def);
    }

    /// Creates a body now; it takes the lowest free id.
    ///
    /// A mass outside [`crate::MIN_MASS`] to [`crate::MAX_MASS`] and a controller value
    /// past ±[`crate::MAX_CONTROLLER_VALUE`] are brought to the nearest limit (the loader's
    /// limits, which [`Simulation::restore`] checks: a game's own snapshot restores), as
    /// for every body a simulation creates (a scene's, a script's spawn, a bullet, a
    /// split's child). Anything else is taken as given. [`Simulation::try_spawn`] refuses such a
    /// definition instead, with the loader's error, as it refuses a non-finite value or a
    /// body too large for a wrapping world: use it for definitions built from data.
    pub fn spawn(&mut self, def: &BodyDef) -> Entity {
        let e = self.world.spawn(def);
        self.world.refresh_active();
        self.queries.invalidate(&self.world);
        e
    }

    /// Spawns every tile of `tiles` now, row by row, each row's tiles in order (a tile map
    /// as data, as a scenario's [`TileRows`]): each tile a static body of scenery. Returns
    /// their ids in that order, which is id order (each takes the lowest free id).
    pub fn spawn_tiles(&mut self, tiles: &TileRows) -> Vec<Entity> {
        let mut ids = Vec::with_capacity(tiles.len());
        self.world.spawn_tiles(tiles, |e| ids.push(e));
        self.world.refresh_active();
        self.queries.invalidate(&self.world);
        ids
    }

    /// Whether `e` is alive.
    #[must_use]
    pub fn contains(&self, e: Entity) -> bool {
        self.world.index_of(e).is_some()
    }

    /// The live body with this name and the lowest id.
    #[must_use]
    pub fn entity_named(&self, name: &str) -> Option<Entity> {
        self.world.find(name).map(|i| self.world.entity[i])
    }

    fn index(&self, e: Entity) -> Result<usize, ControlError> {
        self.world.index_of(e).ok_or(ControlError::NoSuchBody(e))
    }

    /// Moves a body to `position` now (a teleport: swept tests of this frame start there).
    /// A static body moved this way is re-indexed by the broad phase at the next step.
    ///
    /// # Errors
    /// The body is not alive, or the position is not finite or beyond the world limit.
    pub fn set_position(&mut self, e: Entity, position: Vec2) -> Result<(), ControlError> {
        let i = self.index(e)?;
        let position = within("position", position)?;
        self.world.teleport(i, position, self.world.angle[i]);
        self.queries.invalidate(&self.world);
        Ok(())
    }

    /// Turns a body to `angle` (radians, counter-clockwise) now.
    ///
    /// # Errors
    /// The body is not alive, or the angle is not finite.
    pub fn set_angle(&mut self, e: Entity, angle: f64) -> Result<(), ControlError> {
        let i = self.index(e)?;
        if !angle.is_finite() {
            return Err(ControlError::OutOfRange { field: "angle" });
        }
        self.world.teleport(i, self.world.position[i], angle);
        self.queries.invalidate(&self.world);
        Ok(())
    }

    /// Sets a moving body's velocity (a static body never moves: its velocity stays zero).
    ///
    /// # Errors
    /// The body is not alive, or the velocity is not finite.
    pub fn set_velocity(&mut self, e: Entity, velocity: Vec2) -> Result<(), ControlError> {
        let i = self.index(e)?;
        if !velocity.is_finite() {
            return Err(ControlError::OutOfRange { field: "velocity" });
        }
        self.world.set_velocity(i, velocity);
        Ok(())
    }

    /// Gives a body another shape now. Its bounds follow at once: a static body is
    /// re-indexed by the broad phase and the per-axis stages at the next step (and wakes the
    /// sleepers, as a teleport does); a moving body wakes. Like [`Simulation::spawn`], the
    /// shape is not checked against a wrap world's size.
    ///
    /// # Errors
    /// The body is not alive.
    pub fn set_shape(&mut self, e: Entity, shape: Shape) -> Result<(), ControlError> {
        let i = self.index(e)?;
        self.world.set_shape(i, &shape);
        self.queries.invalidate(&self.world);
        Ok(())
    }

    /// Sets a body's [`crate::BodyDef::user_data`]: the game's own, which no stage reads.
    ///
    /// # Errors
    /// The body is not alive.
    pub fn set_user_data(&mut self, e: Entity, data: u128) -> Result<(), ControlError> {
        let i = self.index(e)?;
        self.world.set_user_data(i, data);
        Ok(())
    }

    /// Moves a kinematic body to `pose` over the next moving step (rapier's
    /// `set_next_kinematic_position`, Box2D's `b2Body_SetTargetTransform`): at the start of
    /// that step its velocity becomes `(pose.position - position) / dt` and its angular
    /// velocity `(pose.angle - angle) / dt`, so it arrives there (to rounding: `x + vx * dt`)
    /// and what rides it is carried, as by any kinematic motion. The angle is taken as given
    /// (`angle + 2π` turns a whole turn). A step with no new target stops it: its velocity
    /// and angular velocity go back to zero, so a pose-driven platform holds still between
    /// targets. A target set again before that step replaces the last; frame 0 moves
    /// nothing, so a target set before it waits for frame 1.
    ///
    /// # Errors
    /// The body is not alive, not kinematic, or the pose is not finite or beyond the
    /// world limit.
    pub fn set_target_pose(&mut self, e: Entity, pose: Pose) -> Result<(), ControlError> {
        let i = self.index(e)?;
        let kind = self.world.kind[i];
        if kind != crate::BodyKind::Kinematic {
            return Err(ControlError::WrongKind {
                body: e,
                is: kind.name(),
                needs: "kinematic",
            });
        }
        within("position", pose.position)?;
        if !pose.angle.is_finite() {
            return Err(ControlError::OutOfRange { field: "angle" });
        }
        match self.targets.binary_search_by_key(&e, |t| t.0) {
            Ok(k) => self.targets[k].1 = pose,
            Err(k) => self.targets.insert(k, (e, pose)),
        }
        Ok(())
    }

    /// Sets the constant force on a body (newtons: mass units · units/s²), and wakes it.
    ///
    /// # Errors
    /// The body is not alive, or the force is not finite.
    pub fn set_force(&mut self, e: Entity, force: Vec2) -> Result<(), ControlError> {
        let i = self.index(e)?;
        if !force.is_finite() {
            return Err(ControlError::OutOfRange { field: "force" });
        }
        self.world.set_force(i, force);
        self.world.wake(i);
        self.world.refresh_active();
        Ok(())
    }

    /// Sends an input to a body: it takes effect at the start of the next step (after that
    /// frame's script events; several actions in the order sent), and the step's output
    /// reports it as a [`crate::GameEvent::Input`] (or [`crate::GameEvent::Removed`] for
    /// [`Action::Destroy`]). A ship that fires spawns its bullet then.
    ///
    /// # Errors
    /// The body is not alive, or a value is out of range (a non-finite vector, a turn or
    /// move input outside -1 to 1); nothing is queued.
    pub fn apply(&mut self, e: Entity, action: Action) -> Result<(), ControlError> {
        self.index(e)?;
        if let Some(field) = action.out_of_range() {
            return Err(ControlError::OutOfRange { field });
        }
        self.pending.push((e, action));
        Ok(())
    }

    /// The first moving body, in id order, whose position, velocity, angle or angular
    /// velocity is not finite, if any; else the body at which the kinetic energy the step
    /// reports (`FrameStats::kinetic_energy`) overflows, if it does. Static bodies never
    /// change, and every value a body starts with is checked finite, so only moving bodies
    /// are looked at (call it after each step when a run must stop at the first overflow:
    /// then every value a log holds is finite).
    #[must_use]
    pub fn first_non_finite(&self) -> Option<NonFinite> {
        self.first_non_finite_of(self.world.kinetic_energy())
    }

    /// [`Self::first_non_finite`] right after the step that returned `out`, with nothing
    /// changed since (as a game loop checks each frame): the kinetic energy's total is the
    /// one that step reported, not summed again (the sum is serial, in a fixed order: on
    /// 10,000 bodies it cost as much as the rest of the check). An `out` that is not the
    /// last step's is not trusted: the total is summed again.
    #[must_use]
    pub fn first_non_finite_after(&self, out: &FrameOutput) -> Option<NonFinite> {
        if out.frame.checked_add(1) == Some(self.frame) {
            self.first_non_finite_of(out.stats.kinetic_energy)
        } else {
            self.first_non_finite()
        }
    }

    /// [`Self::first_non_finite`], given the world's kinetic energy now (`total`).
    fn first_non_finite_of(&self, total: f64) -> Option<NonFinite> {
        let w = &self.world;
        self.first_non_finite_state().or_else(|| {
            w.kinetic_energy_overflow(total).map(|i| NonFinite {
                body: w.entity[i],
                field: "kinetic_energy",
                value: [total, 0.0],
            })
        })
    }

    fn first_non_finite_state(&self) -> Option<NonFinite> {
        let w = &self.world;
        if w.moving_state_finite() {
            return None;
        }
        w.movers().iter().find_map(|&i| {
            let i = i as usize;
            let (p, v) = (w.position[i], w.velocity(i));
            let (a, av) = (w.angle[i], w.angular_velocity(i));
            let bad = if !p.is_finite() {
                Some(("position", [p.x, p.y]))
            } else if !v.is_finite() {
                Some(("velocity", [v.x, v.y]))
            } else if !a.is_finite() {
                Some(("angle", [a, 0.0]))
            } else if !av.is_finite() {
                Some(("angular_velocity", [av, 0.0]))
            } else {
                None
            };
            bad.map(|(field, value)| NonFinite {
                body: w.entity[i],
                field,
                value,
            })
        })
    }

    /// Removes a body now, without a split and without an event (the game removed it).
    ///
    /// # Errors
    /// The body is not alive.
    pub fn despawn(&mut self, e: Entity) -> Result<(), ControlError> {
        let i = self.index(e)?;
        self.world.despawn(i);
        self.queries.invalidate(&self.world);
        Ok(())
    }
}
