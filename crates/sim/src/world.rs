//! The world: hand-written struct-of-arrays body columns, like Box2D's and rapier's body sets.
//!
//! Every column is indexed by the same dense index, and the columns are kept sorted by
//! [`Entity`], so iterating `0..len()` visits bodies in id order. Removing a body shifts the
//! rest down (`Vec::remove`): slower than a swap-remove, but the order, and so every log,
//! never depends on what was removed before.

use ricochet_geom::{Bounds, Pose, Shape, Vec2};

use crate::broad_phase::BodyEntry;
use crate::def::{BodyDef, BodyKind, Controller, LayerId, Split};
use crate::entity::{Entity, EntityAllocator};

/// What a controller's inputs currently are.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Inputs {
    /// Ship engine on.
    pub thrust: bool,
    /// Ship turn input, -1 to 1.
    pub turn: f64,
    /// Runner horizontal input, -1 to 1.
    pub run: f64,
}

/// The body columns. Fields are public for reading; change bodies through the methods so the
/// columns stay in step.
#[derive(Clone, Debug, Default)]
pub struct World {
    ids: EntityAllocator,
    /// Entity of each body, ascending.
    pub entity: Vec<Entity>,
    /// Name.
    pub name: Vec<String>,
    /// Layer.
    pub layer: Vec<LayerId>,
    /// Collision shape, local coordinates.
    pub shape: Vec<Shape>,
    /// Dynamic, static or kinematic.
    pub kind: Vec<BodyKind>,
    /// Mass (dynamic bodies).
    pub mass: Vec<f64>,
    /// Position.
    pub position: Vec<Vec2>,
    /// Position at the start of the current frame (where a swept test starts).
    pub start_position: Vec<Vec2>,
    /// Angle, radians.
    pub angle: Vec<f64>,
    /// Velocity.
    pub velocity: Vec<Vec2>,
    /// Angular velocity.
    pub angular_velocity: Vec<f64>,
    /// Constant force.
    pub force: Vec<Vec2>,
    /// Gravity multiplier.
    pub gravity_scale: Vec<f64>,
    /// Frames left to live.
    pub lifetime: Vec<Option<u32>>,
    /// Input handling.
    pub controller: Vec<Option<Controller>>,
    /// Current inputs.
    pub inputs: Vec<Inputs>,
    /// Standing on something: pushed up by a `separate` response this frame.
    pub grounded: Vec<bool>,
    /// Standing on a static body: pushed up by one this frame (what sleeping needs).
    pub on_static: Vec<bool>,
    /// What a box stands on and rides (`stages/carry.rs`): the kinematic or dynamic box that
    /// last pushed it up in the last `resolve_y` (or that it still rests on, flush), `None`
    /// on a static body or in the air. `move_x` and `move_y` move it by that carrier's
    /// displacement before its own motion.
    pub carrier: Vec<Option<Entity>>,
    /// Ended the last frame where it started it, with zero velocity (a box resting on a
    /// sleeper does not wake it).
    pub still: Vec<bool>,
    /// Children spawned on destruction.
    pub split: Vec<Vec<Split>>,
    /// Frozen outside the active region: not moved, not tested, lifetime paused.
    pub frozen: Vec<bool>,
    /// Asleep: at rest on static geometry, not integrated until something touches it.
    pub asleep: Vec<bool>,
    /// Consecutive frames a dynamic body has ended exactly where it started, grounded.
    pub rest_frames: Vec<u32>,
    /// Each body's bounds relative to its position (see [`World::bounds`]).
    local_bounds: Vec<LocalBounds>,
    /// Dense indices of the moving (dynamic and kinematic) bodies, ascending.
    movers: Vec<u32>,
    /// Dense indices of the moving bodies that are neither frozen nor asleep, ascending.
    active: Vec<u32>,
    /// Bumped whenever a static body is added or removed.
    static_generation: u64,
    /// How many bodies have a lifetime.
    with_lifetime: usize,
    /// How many bodies are asleep.
    sleeping: usize,
    /// How many bodies have a controller.
    with_controller: usize,
    /// Per layer, how many bodies are not a single AABB (the per-axis stages own box pairs).
    non_boxes: Vec<u32>,
}

/// A body's bounds relative to its position, kept from one frame to the next.
#[derive(Clone, Copy, Debug)]
struct LocalBounds {
    /// The angle they were computed at.
    angle: f64,
    /// Good at every angle (a shape that turning does not change, or a body that has turned
    /// and is bounded by the disc that holds it at every angle).
    any_angle: bool,
    bounds: Bounds,
}

impl LocalBounds {
    /// The bounds of `shape` at `angle` and position `p`.
    #[inline]
    fn at(&mut self, shape: &Shape, angle: f64, p: Vec2) -> Bounds {
        if !self.any_angle && self.angle.to_bits() != angle.to_bits() {
            // The farthest corner of the angle-0 box is as far as any point of the shape.
            let b = shape.bounds(&Pose::default());
            let r = b.min.abs().max(b.max.abs()).length();
            // A rotated point may round one ulp past the exact radius.
            let r = r + r * 1e-12;
            self.bounds = Bounds {
                min: Vec2::splat(-r),
                max: Vec2::splat(r),
            };
            self.any_angle = true;
        }
        let b = self.bounds;
        // Translating rounds differently from placing the shape at `p` (a rounding or two,
        // each at most half an ulp of these magnitudes): pad by more than that.
        let pad = (p.abs() + b.min.abs().max(b.max.abs())) * 1e-15;
        Bounds {
            min: b.min + p - pad,
            max: b.max + p + pad,
        }
    }

    fn new(shape: &Shape, angle: f64) -> LocalBounds {
        LocalBounds {
            angle,
            any_angle: turning_keeps_bounds(shape),
            bounds: shape.bounds(&Pose::new(Vec2::ZERO, angle)),
        }
    }
}

/// Whether a shape's bounds are the same at every angle: circles and AABBs (which ignore
/// rotation) centred on the body origin.
fn turning_keeps_bounds(shape: &Shape) -> bool {
    !shape.primitives().iter().any(|p| p.turns_with_body())
}

impl World {
    /// An empty world.
    #[must_use]
    pub fn new() -> World {
        World::default()
    }

    /// Makes room for `additional` more bodies in every column at once (instead of each
    /// column doubling on its own).
    pub fn reserve(&mut self, additional: usize) {
        self.entity.reserve_exact(additional);
        self.name.reserve_exact(additional);
        self.layer.reserve_exact(additional);
        self.shape.reserve_exact(additional);
        self.kind.reserve_exact(additional);
        self.mass.reserve_exact(additional);
        self.position.reserve_exact(additional);
        self.start_position.reserve_exact(additional);
        self.angle.reserve_exact(additional);
        self.velocity.reserve_exact(additional);
        self.angular_velocity.reserve_exact(additional);
        self.force.reserve_exact(additional);
        self.gravity_scale.reserve_exact(additional);
        self.lifetime.reserve_exact(additional);
        self.controller.reserve_exact(additional);
        self.inputs.reserve_exact(additional);
        self.grounded.reserve_exact(additional);
        self.on_static.reserve_exact(additional);
        self.carrier.reserve_exact(additional);
        self.still.reserve_exact(additional);
        self.split.reserve_exact(additional);
        self.frozen.reserve_exact(additional);
        self.asleep.reserve_exact(additional);
        self.rest_frames.reserve_exact(additional);
        self.local_bounds.reserve_exact(additional);
    }

    /// How many bodies.
    #[must_use]
    pub fn len(&self) -> usize {
        self.entity.len()
    }

    /// Whether there are no bodies.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.entity.is_empty()
    }

    /// The dense index of a live entity.
    #[must_use]
    pub fn index_of(&self, e: Entity) -> Option<usize> {
        self.entity.binary_search(&e).ok()
    }

    /// The dense index of the live body with this name and the lowest id.
    #[must_use]
    pub fn find(&self, name: &str) -> Option<usize> {
        self.name.iter().position(|n| n == name)
    }

    /// Creates a body; it takes the lowest free id, and its column position follows from it.
    pub fn spawn(&mut self, def: &BodyDef) -> Entity {
        let e = self.ids.allocate();
        let i = self.entity.partition_point(|x| *x < e);
        self.entity.insert(i, e);
        self.name.insert(i, def.name.clone());
        self.layer.insert(i, def.layer);
        self.shape.insert(i, def.shape.clone());
        self.kind.insert(i, def.kind);
        self.mass.insert(i, def.mass);
        self.position.insert(i, def.position);
        self.start_position.insert(i, def.position);
        self.angle.insert(i, def.angle);
        let moves = def.kind != BodyKind::Static;
        self.velocity
            .insert(i, if moves { def.velocity } else { Vec2::ZERO });
        self.angular_velocity
            .insert(i, if moves { def.angular_velocity } else { 0.0 });
        self.force.insert(i, def.force);
        self.gravity_scale.insert(i, def.gravity_scale);
        self.lifetime.insert(i, def.lifetime);
        self.controller.insert(i, def.controller.clone());
        self.inputs.insert(i, Inputs::default());
        self.grounded.insert(i, false);
        self.on_static.insert(i, false);
        self.carrier.insert(i, None);
        self.still.insert(i, false);
        self.split.insert(i, def.split.clone());
        self.frozen.insert(i, false);
        self.asleep.insert(i, false);
        self.rest_frames.insert(i, 0);
        self.local_bounds
            .insert(i, LocalBounds::new(&def.shape, def.angle));
        let i = i as u32;
        for list in [&mut self.movers, &mut self.active] {
            let at = list.partition_point(|&k| k < i);
            for k in &mut list[at..] {
                *k += 1;
            }
            if moves {
                list.insert(at, i);
            }
        }
        if !moves {
            self.static_generation += 1;
            // New static geometry may overlap a sleeper, which would never be tested.
            self.wake_all();
        }
        self.with_lifetime += usize::from(def.lifetime.is_some());
        self.with_controller += usize::from(def.controller.is_some());
        if !def.shape.is_single_aabb() {
            let l = usize::from(def.layer);
            if self.non_boxes.len() <= l {
                self.non_boxes.resize(l + 1, 0);
            }
            self.non_boxes[l] += 1;
        }
        e
    }

    /// Removes the body at dense index `i`, keeping the order of the rest.
    pub fn despawn(&mut self, i: usize) {
        let e = self.entity.remove(i);
        self.ids.free(e);
        self.name.remove(i);
        let layer = self.layer.remove(i);
        if !self.shape.remove(i).is_single_aabb() {
            self.non_boxes[usize::from(layer)] -= 1;
        }
        self.mass.remove(i);
        self.position.remove(i);
        self.start_position.remove(i);
        self.angle.remove(i);
        self.velocity.remove(i);
        self.angular_velocity.remove(i);
        self.force.remove(i);
        self.gravity_scale.remove(i);
        if self.controller.remove(i).is_some() {
            self.with_controller -= 1;
        }
        self.inputs.remove(i);
        self.grounded.remove(i);
        self.on_static.remove(i);
        self.carrier.remove(i);
        self.still.remove(i);
        self.split.remove(i);
        self.frozen.remove(i);
        if self.asleep.remove(i) {
            self.sleeping -= 1;
        }
        self.rest_frames.remove(i);
        self.local_bounds.remove(i);
        if self.kind.remove(i) == BodyKind::Static {
            self.static_generation += 1;
        }
        if self.lifetime.remove(i).is_some() {
            self.with_lifetime -= 1;
        }
        let i = i as u32;
        for list in [&mut self.movers, &mut self.active] {
            let at = list.partition_point(|&k| k < i);
            if list.get(at) == Some(&i) {
                list.remove(at);
            }
            for k in &mut list[at..] {
                *k -= 1;
            }
        }
        // What a sleeper rested on may be gone.
        self.wake_all();
    }

    /// Moves body `i` to `position` at `angle` now, keeping the caches right: a static body
    /// bumps [`World::static_generation`] (the broad phase and the per-axis stages re-index
    /// the static bodies) and wakes every sleeper (what it rested on may have moved); a
    /// moving body wakes and no longer rides what it stood on. The frame's swept tests start
    /// from the new position.
    pub fn teleport(&mut self, i: usize, position: Vec2, angle: f64) {
        self.position[i] = position;
        self.start_position[i] = position;
        self.carrier[i] = None;
        if self.kind[i] == BodyKind::Static {
            self.angle[i] = angle;
            self.local_bounds[i] = LocalBounds::new(&self.shape[i], angle);
            self.static_generation += 1;
            self.wake_all();
        } else {
            // A turned body's bounds follow from the cache (it widens to the any-angle disc).
            self.angle[i] = angle;
            self.wake(i);
            self.refresh_active();
        }
    }

    /// Sets body `i`'s velocity and wakes it; a static body's velocity stays zero.
    pub fn set_velocity(&mut self, i: usize, velocity: Vec2) {
        if self.kind[i] != BodyKind::Static {
            self.velocity[i] = velocity;
            self.wake(i);
            self.refresh_active();
        }
    }

    /// Dense indices of the moving (dynamic and kinematic) bodies, ascending.
    #[must_use]
    pub fn movers(&self) -> &[u32] {
        &self.movers
    }

    /// Dense indices of the moving bodies that are neither frozen nor asleep, ascending:
    /// the bodies the motion stages integrate.
    #[must_use]
    pub fn active(&self) -> &[u32] {
        &self.active
    }

    /// Recomputes [`World::active`] after `frozen` or `asleep` changed.
    pub fn refresh_active(&mut self) {
        self.active.clear();
        let (frozen, asleep) = (&self.frozen, &self.asleep);
        self.active.extend(
            self.movers
                .iter()
                .filter(|&&i| !frozen[i as usize] && !asleep[i as usize]),
        );
    }

    /// Wakes body `i` if it sleeps: it is integrated again from the next frame (or the
    /// next [`World::refresh_active`]).
    pub fn wake(&mut self, i: usize) {
        if self.asleep[i] {
            self.sleeping -= 1;
        }
        self.asleep[i] = false;
        self.rest_frames[i] = 0;
    }

    /// Puts body `i` to sleep (from the next [`World::refresh_active`] on). A sleeper rides
    /// nothing: when it wakes, the next `resolve_y` finds what it stands on.
    pub fn put_to_sleep(&mut self, i: usize) {
        if !self.asleep[i] {
            self.sleeping += 1;
        }
        self.asleep[i] = true;
        self.carrier[i] = None;
    }

    /// How many bodies are asleep.
    #[must_use]
    pub fn sleeping(&self) -> usize {
        self.sleeping
    }

    /// Wakes every sleeping body, now: the active list is recomputed.
    pub fn wake_all(&mut self) {
        if self.sleeping > 0 {
            self.sleeping = 0;
            self.asleep.fill(false);
            self.rest_frames.fill(0);
            self.refresh_active();
        }
    }

    /// Changes whenever a static body is added or removed (static bodies never move).
    #[must_use]
    pub fn static_generation(&self) -> u64 {
        self.static_generation
    }

    /// Whether any body has a controller.
    #[must_use]
    pub fn any_controller(&self) -> bool {
        self.with_controller > 0
    }

    /// Whether every body of `layer` is a single AABB (true for an empty layer).
    #[must_use]
    pub fn only_boxes(&self, layer: LayerId) -> bool {
        self.non_boxes
            .get(usize::from(layer))
            .is_none_or(|&n| n == 0)
    }

    /// Whether any body has a lifetime.
    #[must_use]
    pub fn any_lifetime(&self) -> bool {
        self.with_lifetime > 0
    }

    /// Bounds of body `i` for the broad phase: they hold the shape, and are exact for a body
    /// that has not turned since it was created (or whose bounds turning does not change).
    /// A body that has turned is bounded by the square around the disc that holds its shape
    /// at every angle, so turning never costs a rotation here.
    pub fn bounds(&mut self, i: usize) -> Bounds {
        self.local_bounds[i].at(&self.shape[i], self.angle[i], self.position[i])
    }

    /// Body `i`'s entity as one number, ordered as entities are: the broad phase's key.
    pub(crate) fn key(&self, i: usize) -> u64 {
        let e = self.entity[i];
        (u64::from(e.index) << 32) | u64::from(e.generation)
    }

    /// The broad phase's view of every moving body, in [`World::movers`] order, into `out`:
    /// [`World::bounds`], widened over the frame's motion for a body of a layer in
    /// `sweeping` (a bullet that went right through something is still paired with it), or of
    /// a layer in `separate_swept` that moved more than half its [`Shape::min_width`] (a
    /// `separate` pair that time of impact may have to stop), and
    /// a frozen body handed over as kinematic (it keeps its place in the dense order; the
    /// caller drops its pairs). `visit` sees each entry's place in `out` and its bounds as
    /// they are made (the wrap seam looks for bodies near an edge without another pass).
    pub(crate) fn mover_entries(
        &mut self,
        sweeping: &[bool],
        separate_swept: &[bool],
        out: &mut Vec<BodyEntry>,
        mut visit: impl FnMut(usize, &Bounds),
    ) {
        out.clear();
        out.reserve(self.movers.len());
        for &i in &self.movers {
            let i = i as usize;
            let p = self.position[i];
            let mut bounds = self.local_bounds[i].at(&self.shape[i], self.angle[i], p);
            let layer = self.layer[i];
            let moved = self.start_position[i] - p;
            if moved != Vec2::ZERO
                && (sweeping[usize::from(layer)]
                    || (separate_swept[usize::from(layer)]
                        && moved.length() > 0.5 * self.shape[i].min_width()))
            {
                bounds = bounds.union(bounds.translated(moved));
            }
            visit(out.len(), &bounds);
            out.push(BodyEntry {
                key: self.key(i),
                bounds,
                layer,
                kind: if self.frozen[i] {
                    BodyKind::Kinematic
                } else {
                    self.kind[i]
                },
            });
        }
    }

    /// The pose of body `i`.
    #[must_use]
    pub fn pose(&self, i: usize) -> ricochet_geom::Pose {
        ricochet_geom::Pose::new(self.position[i], self.angle[i])
    }

    /// A 64-bit FNV-1a hash of every body's raw state bits in id order (entity, position,
    /// angle, velocity, angular velocity), like Box2D's determinism test: any change of any
    /// bit anywhere changes it.
    #[must_use]
    pub fn digest(&self) -> u64 {
        const PRIME: u64 = 0x0000_0100_0000_01b3;
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        let mut eat = |bits: u64| {
            for byte in bits.to_le_bytes() {
                h ^= u64::from(byte);
                h = h.wrapping_mul(PRIME);
            }
        };
        for i in 0..self.len() {
            eat(u64::from(self.entity[i].index) << 32 | u64::from(self.entity[i].generation));
            for v in [
                self.position[i].x,
                self.position[i].y,
                self.angle[i],
                self.velocity[i].x,
                self.velocity[i].y,
                self.angular_velocity[i],
            ] {
                eat(v.to_bits());
            }
        }
        h
    }

    /// Kinetic energy of the dynamic bodies, `sum(m v² / 2)` (translation only).
    #[must_use]
    pub fn kinetic_energy(&self) -> f64 {
        self.movers
            .iter()
            .map(|&i| i as usize)
            .filter(|&i| self.kind[i] == BodyKind::Dynamic)
            .map(|i| 0.5 * self.mass[i] * self.velocity[i].length_squared())
            .sum()
    }
}
