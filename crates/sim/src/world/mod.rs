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
//!   `position`, `angle`; and, private, a *look* id into a table holding each distinct
//!   shape once for each name it goes with (the look's name an id into a table of each
//!   distinct name once: [`World::shape`], [`World::name`]), and the body's row. 42 bytes
//!   a body.
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

use ricochet_geom::{Pose, Shape, Vec2};

use crate::def::{BodyDef, BodyKind, Controller, LayerId, Split};
use crate::entity::{Entity, EntityAllocator};
use crate::interned::{NameTable, ShapeTable, shape_key};
use crate::scenario::TileRows;

mod bounds;
#[cfg(test)]
mod checksum_fields;
mod disturbed;
mod local_bounds;
mod measures;
mod motion;
mod rows;
mod runs;
mod set;
mod sleep;
mod state;

pub(crate) use bounds::{MoverEntries, placed};
pub use disturbed::Disturbed;
pub use rows::Motion;
pub(crate) use state::{Bodies, PackedWorld};

use bounds::KeptCount;
use motion::KeptOutside;
use rows::Rows;
use runs::RowRun;

/// What a controller's inputs currently are.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Inputs {
    /// Ship engine on.
    pub thrust: bool,
    /// Ship turn input, -1 to 1.
    pub turn: f64,
    /// Runner horizontal input, -1 to 1.
    pub run: f64,
    /// Dropping through one-way platforms (a `drop` input): set while the body overlaps one,
    /// cleared by the `one_way` pass once it overlaps none (`stages/one_way.rs`).
    pub drop: bool,
}

/// The row of a body that has none (scenery).
const NO_ROW: u32 = u32::MAX;

/// The body columns. The every-body columns are public for reading; change bodies through
/// the methods so the columns stay in step and the world names what it disturbed
/// ([`World::disturbed`]: inside the crate, `position_mut`, `angle_mut`, `velocity_mut`
/// and `angular_velocity_mut`, never the columns themselves, outside the integrator).
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
    /// Each body's look (shape and name) in `shapes`.
    shape_id: Vec<u32>,
    /// Each body's row in `rows`, or [`NO_ROW`] for scenery.
    row: Vec<u32>,
    /// Every shape a body has, once for each name it goes with, with its bounds at angle 0
    /// relative to the body.
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
    /// The bodies with a controller, in id order (the dense order): what the controls stage
    /// visits, instead of every active body (one ship among 10,000 asteroids).
    controlled: Vec<Entity>,
    /// How many rows have a constant force other than zero (`any_force` without a pass).
    with_force: usize,
    /// How many rows have their thrust input on (`any_thrust_input` without a pass).
    thrusting: usize,
    /// Per layer, how many bodies are not a single AABB (the per-axis stages own box pairs).
    non_boxes: Vec<u32>,
    /// Scratch for a shape's key.
    key: Vec<u64>,
    /// Whether [`World::set_shape`] ever ran: until then every body has the shape it was
    /// spawned with (a snapshot compares shapes only after it).
    reshaped: bool,
    /// A number taken anew ([`crate::interned::next_serial`], never used before in the
    /// process) whenever a body is added or removed or given another look, and by a world a
    /// restore builds or patches: while it stays, `entity`, `layer` and the look ids are the
    /// same, and kept frames share one copy of them (`history.rs`). Counting up by one
    /// instead could reach a number a restore took, and a kept answer would be taken for
    /// another order of the bodies.
    layout: u64,
    /// The bodies touched other than by the usual integration ([`World::disturbed`]).
    disturbed: Disturbed,
    /// The last answer of [`World::active_not_inside`] kept for the same step's next ask.
    kept_outside: KeptOutside,
    /// The kinetic energy summed at the end of a step or by the forces pass, until a
    /// velocity changes or a body comes or goes ([`World::step_kinetic_energy`]).
    kept_energy: Option<f64>,
    /// Whether gravity alone accelerates every row by itself (`motion.rs`).
    gravity_exact: motion::GravityExact,
    /// Counts every change of a body's frozen bit ([`World::set_frozen`]).
    frozen_changes: u64,
    /// [`World::count_movers`]' stretches, with the `layout` and `frozen_changes` they
    /// were counted at.
    kept_count: KeptCount,
    /// [`World::movers_run`]'s answer, with the `layout` it was found at.
    kept_run: Option<(u64, Option<RowRun>)>,
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
        let shapes = &self.shapes;
        self.shape_id.iter().position(|&s| shapes.name(s) == id)
    }

    /// Body `i`'s collision shape, local coordinates.
    #[must_use]
    #[inline]
    pub fn shape(&self, i: usize) -> &Shape {
        &self.shapes.get(self.shape_id[i]).0
    }

    /// Asks for body `i`'s columns the narrow phase reads, without reading them (a hint:
    /// `prefetch.rs`): its shape id, position and angle.
    #[inline]
    pub(crate) fn prefetch_columns(&self, i: usize) {
        if i < self.shape_id.len() {
            crate::prefetch::line_of(&self.shape_id[i]);
            crate::prefetch::line_of(&self.position[i]);
            crate::prefetch::line_of(&self.angle[i]);
        }
    }

    /// Asks for the first cache line of body `i`'s shape (reading its shape id, which
    /// [`World::prefetch_columns`] should have asked for a little before).
    #[inline]
    pub(crate) fn prefetch_shape(&self, i: usize) {
        self.shapes.prefetch(self.shape_id[i]);
    }

    /// Each body's look id (its shape and name) in [`World::shape_table`], by dense index:
    /// what a kept frame copies (`history.rs`).
    pub(crate) fn looks(&self) -> &[u32] {
        &self.shape_id
    }

    /// The world's layout serial (see the field): the same while `entity`, `layer` and
    /// [`World::looks`] are.
    pub(crate) fn layout(&self) -> u64 {
        self.layout
    }

    /// The table the look ids index.
    pub(crate) fn shape_table(&self) -> &ShapeTable {
        &self.shapes
    }

    /// Body `i`'s name.
    #[must_use]
    pub fn name(&self, i: usize) -> &str {
        self.names.key(self.shapes.name(self.shape_id[i]))
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

    /// Copies every moving body's position to its start position: the frame's swept tests
    /// run from there (static bodies never move; their start is their position).
    pub fn start_frame(&mut self) {
        if let Some(run) = self.movers_run() {
            // One run (`runs.rs`): one copy.
            self.rows.start_position[run.rows()].copy_from_slice(&self.position[run.indices()]);
            return;
        }
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
            && def.user_data == 0
    }

    /// Creates a body; it takes the lowest free id, and its column position follows from it.
    /// A mass or a controller value past the loader's limits is brought to the nearest one
    /// (as `restore` checks them: every snapshot of the world restores).
    pub fn spawn(&mut self, def: &BodyDef) -> Entity {
        let e = self.ids.allocate();
        match crate::limits::within_limits(def) {
            Some(within) => self.insert(e, &within),
            None => self.insert(e, def),
        }
        e
    }

    /// Creates body `e` (an id the caller took from the allocator, or a restored one) at its
    /// place in id order.
    fn insert(&mut self, e: Entity, def: &BodyDef) {
        self.layout = crate::interned::next_serial();
        self.kept_energy = None;
        let i = self.entity.partition_point(|x| *x < e);
        self.entity.insert(i, e);
        self.disturb(i);
        let name = self.names.acquire(def.name.as_str(), || ());
        self.layer.insert(i, def.layer);
        shape_key(&def.shape, &mut self.key);
        let shape = self.shapes.acquire(self.key.as_slice(), name, || {
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
            self.with_force += usize::from(def.force != Vec2::ZERO);
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
        if def.controller.is_some() {
            let at = self.controlled.partition_point(|&c| c < e);
            self.controlled.insert(at, e);
        }
        if !def.shape.is_single_aabb() {
            let l = usize::from(def.layer);
            if self.non_boxes.len() <= l {
                self.non_boxes.resize(l + 1, 0);
            }
            self.non_boxes[l] += 1;
        }
    }

    /// Spawns every tile of `tiles`, row by row, each row's tiles in order: the bodies
    /// `BodyDef { name, layer, kind: Static, shape, position, ..BodyDef::default() }` with
    /// `position = start + step * k` for the `k`-th tile of a row (see [`TileRows`]).
    /// `each` is handed every tile's id, in spawn order (which is id order).
    pub fn spawn_tiles(&mut self, tiles: &TileRows, mut each: impl FnMut(Entity)) {
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
                each(self.spawn(&def));
            }
        }
    }

    /// Removes the body at dense index `i`, keeping the order of the rest.
    pub fn despawn(&mut self, i: usize) {
        self.layout = crate::interned::next_serial();
        self.kept_energy = None;
        self.disturb(i);
        let e = self.entity.remove(i);
        self.ids.free(e);
        let layer = self.layer.remove(i);
        let shape = self.shape_id.remove(i);
        self.names.release(self.shapes.name(shape));
        if !self.shapes.get(shape).0.is_single_aabb() {
            self.non_boxes[usize::from(layer)] -= 1;
        }
        self.shapes.release(shape);
        self.position.remove(i);
        self.angle.remove(i);
        let row = self.row.remove(i);
        if row != NO_ROW {
            let r = row as usize;
            if self.rows.controller[r].is_some()
                && let Ok(at) = self.controlled.binary_search(&e)
            {
                self.controlled.remove(at);
            }
            if self.rows.asleep[r] {
                self.sleeping -= 1;
            }
            if self.rows.lifetime[r].is_some() {
                self.with_lifetime -= 1;
            }
            if self.rows.force[r] != Vec2::ZERO {
                self.with_force -= 1;
            }
            if self.rows.inputs[r].thrust {
                self.thrusting -= 1;
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

    /// Changes whenever a static body is added or removed (static bodies never move).
    #[must_use]
    pub fn static_generation(&self) -> u64 {
        self.static_generation
    }

    /// Whether any body has a controller.
    #[must_use]
    pub fn any_controller(&self) -> bool {
        !self.controlled.is_empty()
    }

    /// The dense index of the `k`-th body with a controller (in id order, which is the dense
    /// order; `k` below [`World::controlled_count`]), when it is active (a controlled body is
    /// always alive: [`World::controlled_count`] checks it in debug builds).
    pub(crate) fn active_controlled(&self, k: usize) -> Option<usize> {
        let i = self.index_of(self.controlled[k])?;
        self.active.binary_search(&(i as u32)).is_ok().then_some(i)
    }

    /// How many bodies have a controller.
    pub(crate) fn controlled_count(&self) -> usize {
        debug_assert!(
            self.controlled.windows(2).all(|w| w[0] < w[1])
                && self.controlled.len()
                    == self.rows.controller.iter().filter(|c| c.is_some()).count()
                && self.controlled.iter().all(|&e| {
                    self.index_of(e)
                        .is_some_and(|i| self.controller(i).is_some())
                }),
            "the controlled bodies are the rows with a controller, in id order"
        );
        self.controlled.len()
    }

    /// Whether every body of `layer` is a single AABB (true for an empty layer).
    #[must_use]
    pub fn only_boxes(&self, layer: LayerId) -> bool {
        self.non_boxes
            .get(usize::from(layer))
            .is_none_or(|&n| n == 0)
    }

    /// Sets body `i`'s constant force (a row it lacked given first), counted for
    /// [`World::any_force`].
    pub(crate) fn set_force(&mut self, i: usize, force: Vec2) {
        let r = self.row_of(i);
        let old = &mut self.rows.force[r];
        self.with_force -= usize::from(*old != Vec2::ZERO);
        self.with_force += usize::from(force != Vec2::ZERO);
        *old = force;
    }

    /// Sets body `i`'s thrust input (a row it lacked given first), counted for
    /// [`World::any_thrust_input`].
    pub(crate) fn set_thrust(&mut self, i: usize, on: bool) {
        let inputs = self.inputs_mut(i);
        let was = std::mem::replace(&mut inputs.thrust, on);
        self.thrusting -= usize::from(was);
        self.thrusting += usize::from(on);
    }

    /// How many rows have their thrust input on.
    pub(crate) fn thrusting(&self) -> usize {
        debug_assert_eq!(
            self.thrusting,
            self.rows.inputs.iter().filter(|x| x.thrust).count(),
            "the count of thrust inputs is the rows'"
        );
        self.thrusting
    }

    /// Whether any body has a constant force (scenery has none).
    #[must_use]
    pub fn any_force(&self) -> bool {
        debug_assert_eq!(
            self.with_force,
            self.rows.force.iter().filter(|f| **f != Vec2::ZERO).count(),
            "the count of forces is the rows'"
        );
        self.with_force > 0
    }

    /// Whether any body has a lifetime.
    #[must_use]
    pub fn any_lifetime(&self) -> bool {
        self.with_lifetime > 0
    }

    /// The pose of body `i`.
    #[must_use]
    pub fn pose(&self, i: usize) -> ricochet_geom::Pose {
        ricochet_geom::Pose::new(self.position[i], self.angle[i])
    }

    /// How many ids the shape table has handed out (some may be free).
    fn shapes_len(&self) -> u32 {
        self.shapes.len()
    }
}
