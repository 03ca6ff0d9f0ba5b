//! The world: hand-written struct-of-arrays body columns, like Box2D's and rapier's body sets.
//!
//! Every column is indexed by the same dense index, and the columns are kept sorted by
//! [`Entity`], so iterating `0..len()` visits bodies in id order. Removing a body shifts the
//! rest down (`Vec::remove`): slower than a swap-remove, but the order, and so every log,
//! never depends on what was removed before.
//!
//! # Layout: a tile map is data, not a million full bodies
//!
//! A level's tiles are most of its bodies and need almost nothing, so the columns come in
//! two sets:
//! - **Every body** (public `Vec`s, indexed by the dense index): `entity`, `layer`, `kind`,
//!   `position`, `angle`; and, private, a shape id and a name id into tables holding each
//!   distinct shape and name once ([`World::shape`], [`World::name`]), and the body's row.
//!   46 bytes a body.
//! - **Rows**, for every body that is not *scenery*: the state only moving bodies, or static
//!   ones with a lifetime, a controller, children, or a mass, force or gravity scale other
//!   than the defaults, have (velocity, force, lifetime, controller, inputs, carrier,
//!   sleep state, cached bounds, ...). Read through accessors by dense index
//!   ([`World::velocity`], [`World::carrier`], ...): scenery reads the defaults (zero
//!   velocity, no lifetime, not frozen, `start_position` is `position`). Rows are appended
//!   and swap-removed: their order is private and never visited, so it never reaches an
//!   output.
//!
//! Scenery is a static body whose definition has nothing but a name, layer, shape, position
//! and angle ([`World::is_scenery`]). [`World::heap_bytes`] counts what the columns hold.

use ricochet_geom::{Bounds, Pose, Shape, Vec2};

use crate::broad_phase::BodyEntry;
use crate::def::{BodyDef, BodyKind, Controller, LayerId, Split};
use crate::entity::{Entity, EntityAllocator};
use crate::interned::{NameTable, ShapeTable, shape_key};
use crate::scenario::TileRows;

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

/// The row of a body that has none (scenery).
const NO_ROW: u32 = u32::MAX;

/// The body columns. The every-body columns are public for reading; change bodies through
/// the methods so the columns stay in step.
#[derive(Clone, Debug, Default)]
pub struct World {
    ids: EntityAllocator,
    /// Entity of each body, ascending.
    pub entity: Vec<Entity>,
    /// Layer.
    pub layer: Vec<LayerId>,
    /// Dynamic, static or kinematic.
    pub kind: Vec<BodyKind>,
    /// Position.
    pub position: Vec<Vec2>,
    /// Angle, radians.
    pub angle: Vec<f64>,
    /// Each body's shape in `shapes`.
    shape_id: Vec<u32>,
    /// Each body's name in `names`.
    name_id: Vec<u32>,
    /// Each body's row in `rows`, or [`NO_ROW`] for scenery.
    row: Vec<u32>,
    /// Every shape a body has, once, with its bounds at angle 0 relative to the body.
    shapes: ShapeTable,
    /// Every name a body has, once.
    names: NameTable,
    /// The columns of the bodies that are not scenery.
    rows: Rows,
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
    /// Scratch for a shape's key.
    key: Vec<u64>,
}

/// The columns of the bodies that have a row, indexed by row.
#[derive(Clone, Debug, Default)]
struct Rows {
    /// The body of each row.
    entity: Vec<Entity>,
    mass: Vec<f64>,
    start_position: Vec<Vec2>,
    velocity: Vec<Vec2>,
    angular_velocity: Vec<f64>,
    force: Vec<Vec2>,
    gravity_scale: Vec<f64>,
    lifetime: Vec<Option<u32>>,
    controller: Vec<Option<Controller>>,
    inputs: Vec<Inputs>,
    grounded: Vec<bool>,
    on_static: Vec<bool>,
    carrier: Vec<Option<Entity>>,
    still: Vec<bool>,
    split: Vec<Vec<Split>>,
    frozen: Vec<bool>,
    asleep: Vec<bool>,
    rest_frames: Vec<u32>,
    local_bounds: Vec<LocalBounds>,
}

/// The row columns every body reads (a copy), with what scenery reads: each gets a reader
/// `name(i)` by dense index.
macro_rules! row_readers {
    ($($(#[$doc:meta])* $get:ident: $ty:ty = $scenery:expr;)*) => {
        impl World {
            $(
                $(#[$doc])*
                #[must_use]
                #[inline]
                pub fn $get(&self, i: usize) -> $ty {
                    match self.row[i] {
                        NO_ROW => $scenery,
                        r => self.rows.$get[r as usize],
                    }
                }
            )*
        }
    };
}

/// The row columns the stages write: each gets, inside the crate, a writer `name_mut(i)`
/// by dense index (scenery written to, a script's force or input sent to a tile, gets a row
/// first).
macro_rules! row_writers {
    ($($get:ident, $get_mut:ident: $ty:ty;)*) => {
        impl World {
            $(
                #[doc = concat!("[`World::", stringify!($get), "`] of body `i`, to change.")]
                #[inline]
                pub(crate) fn $get_mut(&mut self, i: usize) -> &mut $ty {
                    let r = self.row_of(i);
                    &mut self.rows.$get[r]
                }
            )*
        }
    };
}

row_readers! {
    /// Mass (dynamic bodies).
    mass: f64 = 1.0;
    /// Velocity.
    velocity: Vec2 = Vec2::ZERO;
    /// Angular velocity.
    angular_velocity: f64 = 0.0;
    /// Constant force.
    force: Vec2 = Vec2::ZERO;
    /// Gravity multiplier.
    gravity_scale: f64 = 1.0;
    /// Frames left to live.
    lifetime: Option<u32> = None;
    /// Current inputs.
    inputs: Inputs = Inputs::default();
    /// Standing on something: pushed up by a `separate` response this frame.
    grounded: bool = false;
    /// Standing on a static body: pushed up by one this frame (what sleeping needs).
    on_static: bool = false;
    /// What a box stands on and rides (`stages/carry.rs`): the kinematic or dynamic box that
    /// last pushed it up in the last `resolve_y` (or that it still rests on, flush), `None`
    /// on a static body or in the air. `move_x` and `move_y` move it by that carrier's
    /// displacement before its own motion.
    carrier: Option<Entity> = None;
    /// Ended the last frame where it started it, with zero velocity (a box resting on a
    /// sleeper does not wake it).
    still: bool = false;
    /// Frozen outside the active region: not moved, not tested, lifetime paused.
    frozen: bool = false;
    /// Asleep: at rest on static geometry, not integrated until something touches it.
    asleep: bool = false;
    /// Consecutive frames a dynamic body has ended exactly where it started, grounded.
    rest_frames: u32 = 0;
}

row_writers! {
    velocity, velocity_mut: Vec2;
    angular_velocity, angular_velocity_mut: f64;
    force, force_mut: Vec2;
    inputs, inputs_mut: Inputs;
    grounded, grounded_mut: bool;
    on_static, on_static_mut: bool;
    carrier, carrier_mut: Option<Entity>;
    still, still_mut: bool;
    frozen, frozen_mut: bool;
    rest_frames, rest_frames_mut: u32;
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
        self.at_with(|| shape, angle, p)
    }

    /// [`LocalBounds::at`], looking the shape up only when the bounds must be recomputed
    /// (once per body: a body that turned keeps its any-angle bounds).
    #[inline]
    fn at_with<'s>(&mut self, shape: impl FnOnce() -> &'s Shape, angle: f64, p: Vec2) -> Bounds {
        if !self.any_angle && self.angle.to_bits() != angle.to_bits() {
            // The farthest corner of the angle-0 box is as far as any point of the shape.
            let b = shape().bounds(&Pose::default());
            let r = b.min.abs().max(b.max.abs()).length();
            // A rotated point may round one ulp past the exact radius.
            let r = r + r * 1e-12;
            self.bounds = Bounds {
                min: Vec2::splat(-r),
                max: Vec2::splat(r),
            };
            self.any_angle = true;
        }
        placed(self.bounds, p)
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

impl Rows {
    /// Appends a row for `def`'s body `e`.
    fn push(&mut self, e: Entity, def: &BodyDef) {
        let moves = def.kind != BodyKind::Static;
        self.entity.push(e);
        self.mass.push(def.mass);
        self.start_position.push(def.position);
        self.velocity
            .push(if moves { def.velocity } else { Vec2::ZERO });
        self.angular_velocity
            .push(if moves { def.angular_velocity } else { 0.0 });
        self.force.push(def.force);
        self.gravity_scale.push(def.gravity_scale);
        self.lifetime.push(def.lifetime);
        self.controller.push(def.controller.clone());
        self.inputs.push(Inputs::default());
        self.grounded.push(false);
        self.on_static.push(false);
        self.carrier.push(None);
        self.still.push(false);
        self.split.push(def.split.clone());
        self.frozen.push(false);
        self.asleep.push(false);
        self.rest_frames.push(0);
        self.local_bounds
            .push(LocalBounds::new(&def.shape, def.angle));
    }

    /// Removes row `r`, moving the last row into its place.
    fn swap_remove(&mut self, r: usize) {
        self.entity.swap_remove(r);
        self.mass.swap_remove(r);
        self.start_position.swap_remove(r);
        self.velocity.swap_remove(r);
        self.angular_velocity.swap_remove(r);
        self.force.swap_remove(r);
        self.gravity_scale.swap_remove(r);
        self.lifetime.swap_remove(r);
        self.controller.swap_remove(r);
        self.inputs.swap_remove(r);
        self.grounded.swap_remove(r);
        self.on_static.swap_remove(r);
        self.carrier.swap_remove(r);
        self.still.swap_remove(r);
        self.split.swap_remove(r);
        self.frozen.swap_remove(r);
        self.asleep.swap_remove(r);
        self.rest_frames.swap_remove(r);
        self.local_bounds.swap_remove(r);
    }

    /// Heap bytes of the columns (capacities).
    fn heap_bytes(&self) -> usize {
        fn cap<T>(v: &Vec<T>) -> usize {
            v.capacity() * size_of::<T>()
        }
        let children: usize = self.split.iter().map(cap).sum();
        cap(&self.entity)
            + cap(&self.mass)
            + cap(&self.start_position)
            + cap(&self.velocity)
            + cap(&self.angular_velocity)
            + cap(&self.force)
            + cap(&self.gravity_scale)
            + cap(&self.lifetime)
            + cap(&self.controller)
            + cap(&self.inputs)
            + cap(&self.grounded)
            + cap(&self.on_static)
            + cap(&self.carrier)
            + cap(&self.still)
            + cap(&self.split)
            + children
            + cap(&self.frozen)
            + cap(&self.asleep)
            + cap(&self.rest_frames)
            + cap(&self.local_bounds)
    }
}

impl World {
    /// An empty world.
    #[must_use]
    pub fn new() -> World {
        World::default()
    }

    /// Makes room for `additional` more bodies in every every-body column at once (instead
    /// of each column doubling on its own). Rows grow as bodies that need them come.
    pub fn reserve(&mut self, additional: usize) {
        self.entity.reserve_exact(additional);
        self.layer.reserve_exact(additional);
        self.kind.reserve_exact(additional);
        self.position.reserve_exact(additional);
        self.angle.reserve_exact(additional);
        self.shape_id.reserve_exact(additional);
        self.name_id.reserve_exact(additional);
        self.row.reserve_exact(additional);
        self.ids.reserve(additional);
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
        let id = self.names.id(name)?;
        self.name_id.iter().position(|&n| n == id)
    }

    /// Body `i`'s collision shape, local coordinates.
    #[must_use]
    #[inline]
    pub fn shape(&self, i: usize) -> &Shape {
        &self.shapes.get(self.shape_id[i]).0
    }

    /// Body `i`'s name.
    #[must_use]
    pub fn name(&self, i: usize) -> &str {
        self.names.key(self.name_id[i])
    }

    /// Body `i`'s position at the start of the current frame (where a swept test starts).
    #[must_use]
    #[inline]
    pub fn start_position(&self, i: usize) -> Vec2 {
        match self.row[i] {
            NO_ROW => self.position[i],
            r => self.rows.start_position[r as usize],
        }
    }

    /// Body `i`'s input handling.
    #[must_use]
    #[inline]
    pub fn controller(&self, i: usize) -> Option<&Controller> {
        match self.row[i] {
            NO_ROW => None,
            r => self.rows.controller[r as usize].as_ref(),
        }
    }

    /// Takes the children body `i` spawns when destroyed (it is about to be).
    pub(crate) fn take_split(&mut self, i: usize) -> Vec<Split> {
        match self.row[i] {
            NO_ROW => Vec::new(),
            r => std::mem::take(&mut self.rows.split[r as usize]),
        }
    }

    /// Body `i`'s controller, to change (a walker turning round).
    pub(crate) fn controller_mut(&mut self, i: usize) -> Option<&mut Controller> {
        match self.row[i] {
            NO_ROW => None,
            r => self.rows.controller[r as usize].as_mut(),
        }
    }

    /// The children body `i` spawns when destroyed.
    #[must_use]
    pub fn split(&self, i: usize) -> &[Split] {
        match self.row[i] {
            NO_ROW => &[],
            r => &self.rows.split[r as usize],
        }
    }

    /// Whether body `i` is scenery: static, with no row (see the module docs).
    #[must_use]
    pub fn is_scenery(&self, i: usize) -> bool {
        self.row[i] == NO_ROW
    }

    /// Body `i`'s row, made for scenery first (with what scenery reads: nothing changes
    /// but where the body's state is kept).
    #[inline]
    fn row_of(&mut self, i: usize) -> usize {
        match self.row[i] {
            NO_ROW => self.give_row(i),
            r => r as usize,
        }
    }

    #[cold]
    fn give_row(&mut self, i: usize) -> usize {
        let def = BodyDef {
            layer: self.layer[i],
            shape: self.shape(i).clone(),
            kind: self.kind[i],
            position: self.position[i],
            angle: self.angle[i],
            ..BodyDef::default()
        };
        let r = self.rows.entity.len();
        self.rows.push(self.entity[i], &def);
        self.row[i] = r as u32;
        r
    }

    /// Copies every moving body's position to its start position: the frame's swept tests
    /// run from there (static bodies never move; their start is their position).
    pub fn start_frame(&mut self) {
        for &i in &self.movers {
            let r = self.row[i as usize] as usize;
            self.rows.start_position[r] = self.position[i as usize];
        }
    }

    /// Whether a definition makes scenery: a static body with no more than a name, layer,
    /// shape, position and angle (every other field at its default, bit for bit).
    fn makes_scenery(def: &BodyDef) -> bool {
        def.kind == BodyKind::Static
            && def.lifetime.is_none()
            && def.controller.is_none()
            && def.split.is_empty()
            && def.mass.to_bits() == 1f64.to_bits()
            && def.gravity_scale.to_bits() == 1f64.to_bits()
            && def.force.x.to_bits() == 0
            && def.force.y.to_bits() == 0
    }

    /// Creates a body; it takes the lowest free id, and its column position follows from it.
    pub fn spawn(&mut self, def: &BodyDef) -> Entity {
        let e = self.ids.allocate();
        let i = self.entity.partition_point(|x| *x < e);
        self.entity.insert(i, e);
        let name = self.names.acquire(def.name.as_str(), || ());
        self.name_id.insert(i, name);
        self.layer.insert(i, def.layer);
        shape_key(&def.shape, &mut self.key);
        let shape = self.shapes.acquire(self.key.as_slice(), || {
            let zero = def.shape.bounds(&Pose::new(Vec2::ZERO, 0.0));
            (def.shape.clone(), zero)
        });
        self.shape_id.insert(i, shape);
        self.kind.insert(i, def.kind);
        self.position.insert(i, def.position);
        self.angle.insert(i, def.angle);
        if World::makes_scenery(def) {
            self.row.insert(i, NO_ROW);
        } else {
            self.row.insert(i, self.rows.entity.len() as u32);
            self.rows.push(e, def);
        }
        let moves = def.kind != BodyKind::Static;
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

    /// Spawns every tile of `tiles`, row by row, each row's tiles in order: the bodies
    /// `BodyDef { name, layer, kind: Static, shape, position, ..BodyDef::default() }` with
    /// `position = start + step * k` for the `k`-th tile of a row (see [`TileRows`]).
    pub fn spawn_tiles(&mut self, tiles: &TileRows) {
        let mut def = BodyDef {
            name: tiles.name.clone(),
            layer: tiles.layer,
            kind: BodyKind::Static,
            shape: tiles.shape.clone(),
            ..BodyDef::default()
        };
        self.reserve(tiles.len());
        for &(start, count) in &tiles.rows {
            for k in 0..count {
                def.position = start + tiles.step * f64::from(k);
                self.spawn(&def);
            }
        }
    }

    /// Removes the body at dense index `i`, keeping the order of the rest.
    pub fn despawn(&mut self, i: usize) {
        let e = self.entity.remove(i);
        self.ids.free(e);
        self.names.release(self.name_id.remove(i));
        let layer = self.layer.remove(i);
        let shape = self.shape_id.remove(i);
        if !self.shapes.get(shape).0.is_single_aabb() {
            self.non_boxes[usize::from(layer)] -= 1;
        }
        self.shapes.release(shape);
        self.position.remove(i);
        self.angle.remove(i);
        let row = self.row.remove(i);
        if row != NO_ROW {
            let r = row as usize;
            if self.rows.controller[r].is_some() {
                self.with_controller -= 1;
            }
            if self.rows.asleep[r] {
                self.sleeping -= 1;
            }
            if self.rows.lifetime[r].is_some() {
                self.with_lifetime -= 1;
            }
            self.rows.swap_remove(r);
            // The last row moved into `r`: its body points there now.
            if let Some(&moved) = self.rows.entity.get(r) {
                let k = self.index_of(moved).expect("a row's body is alive");
                self.row[k] = row;
            }
        }
        if self.kind.remove(i) == BodyKind::Static {
            self.static_generation += 1;
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
        self.angle[i] = angle;
        let r = self.row[i];
        if r != NO_ROW {
            let r = r as usize;
            self.rows.start_position[r] = position;
            self.rows.carrier[r] = None;
            if self.kind[i] == BodyKind::Static {
                self.rows.local_bounds[r] = LocalBounds::new(self.shape(i), angle);
            }
        }
        if self.kind[i] == BodyKind::Static {
            self.static_generation += 1;
            self.wake_all();
        } else {
            // A turned body's bounds follow from the cache (it widens to the any-angle disc).
            self.wake(i);
            self.refresh_active();
        }
    }

    /// Sets body `i`'s velocity and wakes it; a static body's velocity stays zero.
    pub fn set_velocity(&mut self, i: usize, velocity: Vec2) {
        if self.kind[i] != BodyKind::Static {
            *self.velocity_mut(i) = velocity;
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
        let (row, rows) = (&self.row, &self.rows);
        self.active.extend(self.movers.iter().filter(|&&i| {
            let r = row[i as usize] as usize;
            !rows.frozen[r] && !rows.asleep[r]
        }));
    }

    /// Wakes body `i` if it sleeps: it is integrated again from the next frame (or the
    /// next [`World::refresh_active`]). Scenery never sleeps.
    pub fn wake(&mut self, i: usize) {
        let r = self.row[i];
        if r == NO_ROW {
            return;
        }
        let r = r as usize;
        if self.rows.asleep[r] {
            self.sleeping -= 1;
        }
        self.rows.asleep[r] = false;
        self.rows.rest_frames[r] = 0;
    }

    /// Puts body `i` to sleep (from the next [`World::refresh_active`] on). A sleeper rides
    /// nothing: when it wakes, the next `resolve_y` finds what it stands on.
    pub fn put_to_sleep(&mut self, i: usize) {
        let r = self.row_of(i);
        if !self.rows.asleep[r] {
            self.sleeping += 1;
        }
        self.rows.asleep[r] = true;
        self.rows.carrier[r] = None;
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
            self.rows.asleep.fill(false);
            self.rows.rest_frames.fill(0);
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

    /// Whether any body has a constant force (scenery has none).
    #[must_use]
    pub fn any_force(&self) -> bool {
        self.rows.force.iter().any(|f| *f != Vec2::ZERO)
    }

    /// Counts down every lifetime of a body not frozen, and lists the bodies whose lifetime
    /// ran out, in id order.
    pub(crate) fn count_down_lifetimes(&mut self, expired: &mut Vec<Entity>) {
        for i in 0..self.len() {
            let r = self.row[i];
            if r == NO_ROW || self.rows.frozen[r as usize] {
                continue;
            }
            if let Some(l) = &mut self.rows.lifetime[r as usize] {
                *l = l.saturating_sub(1);
                if *l == 0 {
                    expired.push(self.entity[i]);
                }
            }
        }
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
        let p = self.position[i];
        match self.row[i] {
            NO_ROW => {
                // Scenery never turns: its bounds at its angle, translated.
                let (shape, zero) = self.shapes.get(self.shape_id[i]);
                let angle = self.angle[i];
                let local = if angle.to_bits() == 0 {
                    *zero
                } else {
                    shape.bounds(&Pose::new(Vec2::ZERO, angle))
                };
                placed(local, p)
            }
            r => {
                let shape = &self.shapes.get(self.shape_id[i]).0;
                self.rows.local_bounds[r as usize].at(shape, self.angle[i], p)
            }
        }
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
            let r = self.row[i] as usize;
            let p = self.position[i];
            // The shape table is read only when needed (a scene's shapes may all differ).
            let (shapes, id) = (&self.shapes, self.shape_id[i]);
            let shape = || &shapes.get(id).0;
            let mut bounds = self.rows.local_bounds[r].at_with(shape, self.angle[i], p);
            let layer = self.layer[i];
            let moved = self.rows.start_position[r] - p;
            if moved != Vec2::ZERO
                && (sweeping[usize::from(layer)]
                    || (separate_swept[usize::from(layer)]
                        && moved.length() > 0.5 * shape().min_width()))
            {
                bounds = bounds.union(bounds.translated(moved));
            }
            visit(out.len(), &bounds);
            out.push(BodyEntry {
                key: self.key(i),
                bounds,
                layer,
                kind: if self.rows.frozen[r] {
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
            let (v, w) = (self.velocity(i), self.angular_velocity(i));
            for x in [
                self.position[i].x,
                self.position[i].y,
                self.angle[i],
                v.x,
                v.y,
                w,
            ] {
                eat(x.to_bits());
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
            .map(|i| {
                let r = self.row[i] as usize;
                0.5 * self.rows.mass[r] * self.rows.velocity[r].length_squared()
            })
            .sum()
    }

    /// The heap bytes the world holds: every column's capacity, the shape and name tables,
    /// the rows and the id allocator. An honest count of what it keeps, not of what the
    /// allocator adds around it.
    #[must_use]
    pub fn heap_bytes(&self) -> usize {
        fn cap<T>(v: &Vec<T>) -> usize {
            v.capacity() * size_of::<T>()
        }
        let compound_parts: usize = (0..self.shapes_len())
            .filter_map(|id| self.shapes.try_get(id))
            .map(|(s, _)| match s {
                Shape::Compound(c) => size_of_val(c.parts()),
                Shape::Primitive(_) => 0,
            })
            .sum();
        cap(&self.entity)
            + cap(&self.layer)
            + cap(&self.kind)
            + cap(&self.position)
            + cap(&self.angle)
            + cap(&self.shape_id)
            + cap(&self.name_id)
            + cap(&self.row)
            + self.shapes.heap_bytes()
            + compound_parts
            + self.names.heap_bytes(|k| k.len())
            + self.rows.heap_bytes()
            + cap(&self.movers)
            + cap(&self.active)
            + cap(&self.non_boxes)
            + cap(&self.key)
            + self.ids.heap_bytes()
    }

    /// How many ids the shape table has handed out (some may be free).
    fn shapes_len(&self) -> u32 {
        self.shapes.len()
    }
}

/// Bounds `b`, relative to a body, placed at `p`.
#[inline]
fn placed(b: Bounds, p: Vec2) -> Bounds {
    // Translating rounds differently from placing the shape at `p` (a rounding or two,
    // each at most half an ulp of these magnitudes): pad by more than that.
    let pad = (p.abs() + b.min.abs().max(b.max.abs())) * 1e-15;
    Bounds {
        min: b.min + p - pad,
        max: b.max + p + pad,
    }
}
