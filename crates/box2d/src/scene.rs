//! [`Box2dScene`]: a Box2D world holding one body and one shape per body of a [`Simulation`].

use std::collections::BTreeMap;
use std::ffi::c_void;

use boxdd::{
    BodyId, BodyType, Foundation, MotionLocks, Position, Profile, ShapeDef, ShapeId, World,
};
use ricochet_sim::{BodyKind, Entity, Simulation};

use crate::Box2dError;
use crate::convert::{LocalShape, Placement, local_shape, placement};
use crate::filter::layer_filter;

/// Sub-steps per Box2D step: Box2D's recommended default (`b2World_Step(world, dt, 4)`).
pub const SUB_STEPS: i32 = 4;

/// A boxdd error as ours, with what was being done.
pub(crate) fn box2d(what: &'static str) -> impl FnOnce(boxdd::Error) -> Box2dError {
    move |e| Box2dError::Box2d(format!("{what}: {e}"))
}

/// The figures of Box2D's last step (`b2World_GetProfile`), milliseconds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepTimes {
    /// Broad phase (`pairs`: new pairs from the proxies that moved) plus narrow phase
    /// (`collide`: every contact's manifold updated). In the Box2D revision boxdd 0.6 pins,
    /// `collide` no longer includes `pairs`; their sum is what rapier's collision pipeline
    /// does.
    pub collide_ms: f64,
    /// The whole `b2World_Step`: the above, the solver, the continuous pass, sensors.
    pub step_ms: f64,
}

impl StepTimes {
    fn from_profile(p: &Profile) -> StepTimes {
        StepTimes {
            collide_ms: f64::from(p.pairs) + f64::from(p.collide),
            step_ms: f64::from(p.step),
        }
    }
}

/// A Box2D world holding one body per body of a [`Simulation`]: what a good Box2D user builds
/// for a game that moves its own bodies and asks Box2D for the contacts. See the crate docs
/// for the configuration and why.
pub struct Box2dScene {
    pub(crate) world: World,
    /// Every body's Box2D body, by dense index.
    bodies: Vec<BodyId>,
    /// Every body's Box2D shape, by dense index.
    shapes: Vec<ShapeId>,
    /// Every non-static body: its dense index and the placement Box2D holds.
    moving: Vec<(usize, Placement)>,
    /// Every body's entity, by dense index (the shape's user data is the index plus one).
    entities: Vec<Entity>,
    /// Seconds per step, as Box2D takes it.
    dt: f32,
    /// The last step's figures.
    times: StepTimes,
}

impl Box2dScene {
    /// A Box2D body and shape for every body of `sim`, at their current poses. Call
    /// [`step`](Box2dScene::step) once before timing anything: the first step pairs every
    /// shape from scratch.
    pub fn new(sim: &Simulation) -> Result<Box2dScene, Box2dError> {
        let foundation = Foundation::initialize_default().map_err(|e| {
            Box2dError::Box2d(format!("initialising Box2D's process-global state: {e}"))
        })?;
        let def = foundation
            .world_builder()
            .gravity([0.0, 0.0])
            .enable_sleep(false)
            .build()
            .map_err(box2d("world definition"))?;
        let world = foundation
            .create_world(def)
            .map_err(box2d("creating the world"))?;
        let w = sim.world();
        let layers = &sim.scenario().world.layers;
        let mut scene = Box2dScene {
            world,
            bodies: Vec::with_capacity(w.len()),
            shapes: Vec::with_capacity(w.len()),
            moving: Vec::new(),
            entities: w.entity.clone(),
            dt: sim.scenario().world.dt as f32,
            times: StepTimes::default(),
        };
        // Every motion locked: Box2D pairs and solves the body as dynamic, but its solver never
        // moves it; its pose comes from Ricochet alone.
        let locked = MotionLocks::new(true, true, true);
        for i in 0..w.len() {
            let at = placement(w.shape(i), &w.pose(i))?;
            let shape = local_shape(w.shape(i))?;
            let kind = match w.kind[i] {
                BodyKind::Static => BodyType::Static,
                BodyKind::Kinematic => BodyType::Kinematic,
                BodyKind::Dynamic => BodyType::Dynamic,
            };
            let mut body = scene
                .world
                .body_builder()
                .body_type(kind)
                .position(Position::new(at.position.x, at.position.y))
                .angle(at.angle)
                .enable_sleep(false)
                // A recycled contact's separation is extrapolated along its old normal: it
                // reports the pairs near the given poses, not at them (see the crate docs).
                .enable_contact_recycling(false);
            if kind == BodyType::Dynamic {
                body = body.motion_locks(locked);
            }
            let body = body.build().map_err(box2d("body definition"))?;
            let id = scene
                .world
                .create_body(body)
                .map_err(box2d("creating a body"))?;
            let def = ShapeDef::builder()
                .filter(layer_filter(layers, w.layer[i])?)
                // A static shape finds its pairs when the moving ones do: no scan at creation.
                .invoke_contact_creation(kind != BodyType::Static)
                .build()
                .map_err(box2d("shape definition"))?;
            let shape_id = {
                let mut b = scene.world.body(id).map_err(box2d("a new body"))?;
                match &shape {
                    LocalShape::Circle(c) => b.create_circle(&def, c),
                    LocalShape::Capsule(c) => b.create_capsule(&def, c),
                    LocalShape::Polygon(p) => b.create_polygon(&def, p),
                }
                .map_err(box2d("creating a shape"))?
            };
            scene
                .world
                .shape(shape_id)
                .and_then(|mut s| s.set_user_data_ptr_raw(index_tag(i)))
                .map_err(box2d("tagging a shape"))?;
            scene.bodies.push(id);
            scene.shapes.push(shape_id);
            if kind != BodyType::Static {
                scene.moving.push((i, at));
            }
        }
        Ok(scene)
    }

    /// Copies every moving body's pose from `sim` into its Box2D body
    /// (`b2Body_SetTransform`), only for the bodies whose placement changed. Not part of
    /// Box2D's step: `b2Body_SetTransform` moves a shape's broad-phase proxy at once (a tree
    /// remove and insert) when the shape leaves its fat box, so that part of Box2D's broad
    /// phase is done here, and the bench times it apart. So is boxdd's checked API (each body
    /// borrowed and validated): measured on `asteroids-10000`, setting every body again at the
    /// pose it holds costs 3.2 ms a frame, this copy 8.6 ms.
    ///
    /// A body whose placement did not change is left alone: after each step Box2D recomputes
    /// a body's origin from its centre of mass and renormalises its rotation in `f32`, so such
    /// a body may drift by about `1e-8` (bench scenes move every moving body every frame).
    ///
    /// Fails when the simulation gained or lost bodies: the bench scenes keep their count.
    pub fn sync(&mut self, sim: &Simulation) -> Result<(), Box2dError> {
        let w = sim.world();
        if w.entity != self.entities {
            return Err(Box2dError::Conversion(
                "the simulation spawned or removed bodies; the bench needs a stable body set"
                    .to_owned(),
            ));
        }
        for (i, held) in &mut self.moving {
            let at = placement(w.shape(*i), &w.pose(*i))?;
            if at == *held {
                continue;
            }
            self.world
                .body(self.bodies[*i])
                .and_then(|mut b| {
                    b.set_position_and_rotation(
                        Position::new(at.position.x, at.position.y),
                        at.angle,
                    )
                })
                .map_err(box2d("moving a body"))?;
            *held = at;
        }
        Ok(())
    }

    /// One `b2World_Step` of the scenario's `dt` in [`SUB_STEPS`] sub-steps; its figures are
    /// then [`times`](Box2dScene::times).
    pub fn step(&mut self) -> Result<(), Box2dError> {
        let done = self
            .world
            .step(self.dt, SUB_STEPS)
            .map_err(box2d("stepping"))?;
        if let Some(e) = done.post_step_error() {
            return Err(Box2dError::Box2d(format!("after the step: {e}")));
        }
        drop(done);
        let profile = self.world.profile().map_err(box2d("reading the profile"))?;
        self.times = StepTimes::from_profile(&profile);
        Ok(())
    }

    /// The last step's figures.
    #[must_use]
    pub fn times(&self) -> StepTimes {
        self.times
    }

    /// How many bodies Box2D holds.
    #[must_use]
    pub fn len(&self) -> usize {
        self.entities.len()
    }

    /// Whether Box2D holds no body.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.entities.is_empty()
    }

    /// Every pair Box2D reports touching after the last [`step`](Box2dScene::step): a
    /// contact whose manifold has points (`b2Body_GetContactData`, the state Box2D's contact
    /// begin and end events report). Keyed `(a, b)` with `a < b`, the value is the manifold's
    /// smallest point separation (negative: penetration; up to Box2D's speculative distance,
    /// `4 × 0.005`, when apart). Every such pair has a dynamic body, so only moving bodies'
    /// contacts are visited.
    pub fn touching(&mut self) -> Result<BTreeMap<(Entity, Entity), f64>, Box2dError> {
        let mut pairs = BTreeMap::new();
        for k in 0..self.moving.len() {
            let i = self.moving[k].0;
            let contacts = self
                .world
                .body(self.bodies[i])
                .and_then(|b| b.contact_data())
                .map_err(box2d("reading contacts"))?;
            for c in contacts {
                let Some(separation) = c
                    .manifold
                    .points()
                    .iter()
                    .map(|p| f64::from(p.separation))
                    .reduce(f64::min)
                else {
                    continue;
                };
                let ea = self.entity_of(i, c.shape_id_a)?;
                let eb = self.entity_of(i, c.shape_id_b)?;
                pairs.insert((ea.min(eb), ea.max(eb)), separation);
            }
        }
        Ok(pairs)
    }

    /// The entity whose shape this is: the body at dense index `i`'s, or the one its user data
    /// names.
    pub(crate) fn entity_of(&mut self, i: usize, shape: ShapeId) -> Result<Entity, Box2dError> {
        if self.shapes[i] == shape {
            return Ok(self.entities[i]);
        }
        let tag = self
            .world
            .shape(shape)
            .and_then(|s| s.user_data_ptr_raw())
            .map_err(box2d("reading a shape's tag"))?;
        tag.addr()
            .checked_sub(1)
            .and_then(|i| self.entities.get(i).copied())
            .ok_or_else(|| Box2dError::Box2d("a contact names an untagged shape".to_owned()))
    }

    /// The transform Box2D holds for the body at dense index `i` (tests only).
    #[cfg(test)]
    pub(crate) fn body_transform(&mut self, i: usize) -> boxdd::WorldTransform {
        let id = self.bodies[i];
        self.world
            .body(id)
            .and_then(|b| b.transform())
            .expect("a live body")
    }
}

/// A dense index as a shape's user data: the index plus one, never dereferenced (Box2D and
/// boxdd only store it), so that no tag is null.
fn index_tag(i: usize) -> *mut c_void {
    std::ptr::without_provenance_mut(i + 1)
}
