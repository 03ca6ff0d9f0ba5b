//! Snapshots: the state a step reads, as bytes, and a checksum of it.
//!
//! [`Simulation::snapshot`] is taken between two steps, at [`Simulation::frame`]: the frame
//! the next step runs. [`Simulation::restore`] puts a simulation of the same scene back in
//! that state, and it then steps exactly as the original did (byte-identical
//! [`crate::FrameOutput`]s). [`Simulation::checksum`] hashes the same encoding without the
//! game's data: two simulations with equal checksums step identically.
//!
//! # What is saved
//!
//! The scene's definition (world settings, layers, templates and script) is never copied:
//! a snapshot holds its hash, and restoring onto a simulation of another scene is
//! [`SnapshotError::OtherScene`]. Every field of the simulation is one of:
//!
//! | field | is | saved | in `checksum` |
//! |---|---|---|---|
//! | `Simulation::frame`, `cursor` (next script event) | state | yes | yes |
//! | `pending` (inputs the game sent for the next step) | state | yes | yes |
//! | `targets`, `targeted` (kinematic target poses) | state | yes | yes |
//! | `focus` (the body the active region follows) | state | yes | yes |
//! | `touch.touching` (pairs touching at the end of the last frame) | state | yes | yes |
//! | `touch.static_generation` | state, as one bit: did a static body change since the last `touch` | yes | yes |
//! | `scenario` (world def, templates, script) | definition | its hash | no (equal by the scene check) |
//! | `capture_detect_poses`, `workers` | settings of the output and the threads, not of the result | no | no |
//! | `detect` (broad phase, static entries, buffers), `separate` (static and mover grids) | caches rebuilt from the world | no: restore builds them new | no |
//! | `touch` buffers (`recorded`, `next`, `ends`, ...) | scratch | no | no |
//! | World: `entity`, `layer`, `kind`, `position`, `angle`, `shape`, `name` | state (a script finds bodies by name) | as they differ from the baseline | yes |
//! | World: the allocator's `generations` (its free list: every slot not alive) | state | as they differ from the baseline | yes |
//! | World: `shapes`, `names` tables, `row`, `movers`, `active`, counters, `non_boxes`, `key` | caches of the above | no: rebuilt or patched | no |
//! | World: `static_generation`, `layout` | counters the caches (and kept frames) compare | no: the caches are built new | no |
//! | World: `reshaped` | whether a body may no longer have the baseline's shape and name: only what is compared | no | no |
//! | Rows: `mass`, `velocity`, `angular_velocity`, `force`, `gravity_scale`, `lifetime`, `controller`, `inputs`, `grounded`, `on_static`, `carrier`, `still`, `split`, `frozen`, `asleep`, `rest_frames` | state | as they differ from the baseline | yes |
//! | Rows: whether a static body has a row (`has_row`: scenery given one) | state of the layout | yes | yes |
//! | Rows: `local_bounds` | a cache, but its history shows in the broad phase's candidates: one bit (turned: the any-angle square) | yes | yes |
//! | Rows: `start_position` | a cache: `start_frame` sets it from `position` each step | no | no |
//! | Rows: `entity` (row to body) | the layout | no | no |
//! | Rows: `user_data` | game data: no stage reads it | yes | **no** |
//! | `baseline` (the world before the first step) | definition | its hash, in the scene's | no |
//! | `history` (the frames kept for `Simulation::past`) | past states for queries; no step reads them | no: `restore` clears them | no |
//!
//! `world/checksum_fields.rs` changes every field marked "in `checksum`" in turn and checks
//! that the checksum changes (its list is checked against this table, and it destructures
//! `Rows`); `world/state/` destructures `Rows` too: a new column fails to compile until it
//! is placed in both.
//!
//! # The baseline
//!
//! A simulation keeps its world as it was built, before the first step (shared by its
//! clones), packed: scenery in runs of ids at regular places (a tile map's rows) costs a
//! few bytes a run, not 42 a body (`world/state/packed.rs`). The first snapshot, restore or
//! checksum unpacks it and keeps the copy. A snapshot writes the bodies as
//! they differ from it (`world/state/`): runs of bodies kept or dropped, a mask of the
//! field groups that changed, and whole records for bodies spawned later or redefined. A
//! drifting asteroid costs 25 bytes (its position and angle), a tile that did not move
//! nothing. The encoding is a function of the state alone (never of interned ids or row
//! order), so [`Simulation::checksum`] hashes it too. The baseline's hash is part of the
//! scene's: a snapshot restores only onto a simulation built the same way.
//!
//! [`Simulation::restore`] onto a simulation whose world has the same bodies as the
//! snapshot, each with the baseline's definition (a rollback: the common case), patches the
//! columns in place; otherwise it builds the world anew. The broad phase, grids and query
//! trees are built new either way.
//!
//! # Bytes
//!
//! `RCSN`, [`SNAPSHOT_VERSION`] (u32), the total length (u64), the frame, the scene hash
//! (u64 each), the state's length (u32) and the state, then an XXH3-64 (fixed seed) of
//! every byte before it. Little-endian, every float as its bits. Every truncation or
//! flipped bit is an error, never a panic; the state is checked against the baseline by
//! `restore`, which leaves the simulation unchanged when it fails.
//!
//! ```
//! use ricochet_sim::prelude::*;
//!
//! let mut sim = Simulation::from_def(WorldDef::default())?;
//! let ball = sim.spawn(&BodyDef { velocity: Vec2::new(60.0, 0.0), ..BodyDef::default() });
//! for _ in 0..10 {
//!     sim.step();
//! }
//! let bytes = sim.snapshot().to_bytes(); // at frame 10: the next step runs frame 10
//! let sum = sim.checksum();
//! let later: Vec<_> = (0..5).map(|_| sim.step()).collect();
//! sim.restore(&Snapshot::from_bytes(&bytes)?)?;
//! assert_eq!((sim.frame(), sim.checksum()), (10, sum));
//! let again: Vec<_> = (0..5).map(|_| sim.step()).collect();
//! assert_eq!(later, again);
//! assert_eq!(sim.position(ball), Some(Vec2::new(14.0, 0.0)));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub(crate) mod codec;
mod error;

pub use error::SnapshotError;

use std::sync::{Arc, OnceLock};

use codec::{Hasher, Reader, Sink, hash};

use crate::pipeline::Simulation;
use crate::stages::detect::DetectState;
use crate::stages::separate::SeparateState;
use crate::stages::touch::TouchState;
use crate::world::{PackedWorld, World};

/// The version of the snapshot format [`Snapshot::to_bytes`] writes and
/// [`Snapshot::from_bytes`] reads.
pub const SNAPSHOT_VERSION: u32 = 2;

/// The first bytes of a snapshot.
const MAGIC: &[u8; 4] = b"RCSN";

/// Magic, version, total length, frame, scene, state length.
const HEADER: usize = 4 + 4 + 8 + 8 + 8 + 4;

/// A simulation's state between two steps ([`Simulation::snapshot`]), restored with
/// [`Simulation::restore`] onto a simulation of the same scene.
#[derive(Clone, Debug)]
pub struct Snapshot {
    /// [`Simulation::frame`] when it was taken.
    frame: u64,
    /// The hash of the scene definition (world, templates, script).
    scene: u64,
    /// The encoded state (the module docs' table).
    payload: Vec<u8>,
}

impl Snapshot {
    /// The frame the next step of a simulation restored from it runs: [`Simulation::frame`]
    /// when it was taken.
    #[must_use]
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// The snapshot as bytes: versioned, with a checksum of the bytes (module docs).
    #[must_use]
    pub fn to_bytes(&self) -> Vec<u8> {
        let total = HEADER + self.payload.len() + 8;
        let mut b = Vec::with_capacity(total);
        b.put(MAGIC);
        b.u32(SNAPSHOT_VERSION);
        b.u64(total as u64);
        b.u64(self.frame);
        b.u64(self.scene);
        Sink::len(&mut b, self.payload.len());
        b.put(&self.payload);
        let sum = hash(&b);
        b.u64(sum);
        b
    }

    /// A snapshot from [`Snapshot::to_bytes`]'s bytes.
    ///
    /// # Errors
    /// Any damage: another magic, version, a truncation, a checksum mismatch, a state that
    /// does not hold together. Never a panic.
    pub fn from_bytes(bytes: &[u8]) -> Result<Snapshot, SnapshotError> {
        if bytes.len() < 4 || &bytes[..4] != MAGIC {
            return Err(SnapshotError::BadMagic);
        }
        let mut r = Reader::new(&bytes[4..]);
        let version = r.u32()?;
        if version != SNAPSHOT_VERSION {
            return Err(SnapshotError::Version {
                found: version,
                expected: SNAPSHOT_VERSION,
            });
        }
        let total = r.u64()?;
        if total != bytes.len() as u64 {
            return Err(SnapshotError::Truncated {
                needed: total,
                found: bytes.len() as u64,
            });
        }
        let (body, sum) = bytes.split_at(bytes.len().saturating_sub(8));
        if sum.len() != 8 || hash(body) != Reader::new(sum).u64()? {
            return Err(SnapshotError::Checksum);
        }
        let mut r = Reader::new(&body[16..]);
        let frame = r.u64()?;
        let scene = r.u64()?;
        let n = r.len(1)?;
        if HEADER + n != body.len() {
            return Err(SnapshotError::malformed("the state's length"));
        }
        let payload = body[HEADER..].to_vec();
        // The bodies are checked by `restore`, against the baseline they are written from.
        Ok(Snapshot {
            frame,
            scene,
            payload,
        })
    }

    /// The state in the payload, for a scene of `layers` layers starting as `base`.
    fn decode(&self, base: &World, layers: usize) -> Result<State, SnapshotError> {
        let mut r = Reader::new(&self.payload);
        let frame = r.u64()?;
        if frame != self.frame {
            return Err(SnapshotError::malformed("the frame"));
        }
        let cursor = usize::try_from(r.u64()?).map_err(|_| SnapshotError::malformed("cursor"))?;
        let n = r.len(9)?;
        let pending = (0..n)
            .map(|_| Ok((r.entity()?, r.action()?)))
            .collect::<Result<Vec<_>, SnapshotError>>()?;
        let n = r.len(32)?;
        let targets = (0..n)
            .map(|_| Ok((r.entity()?, r.pose()?)))
            .collect::<Result<Vec<_>, SnapshotError>>()?;
        let n = r.len(8)?;
        let targeted = (0..n).map(|_| r.entity()).collect::<Result<Vec<_>, _>>()?;
        let focus = r.opt_entity()?;
        let n = r.len(16)?;
        let touching = (0..n)
            .map(|_| Ok((r.entity()?, r.entity()?)))
            .collect::<Result<Vec<_>, SnapshotError>>()?;
        if touching.windows(2).any(|p| p[0] >= p[1]) || touching.iter().any(|(a, b)| a >= b) {
            return Err(SnapshotError::malformed("touching pairs out of order"));
        }
        let statics_moved = r.bool()?;
        let bodies = World::decode(&mut r, base, layers)?;
        if !r.is_done() {
            return Err(SnapshotError::malformed("bytes after the state"));
        }
        Ok(State {
            cursor,
            pending,
            targets,
            targeted,
            focus,
            touching,
            statics_moved,
            bodies,
        })
    }
}

/// A decoded snapshot, ready to move into a simulation.
struct State {
    cursor: usize,
    pending: Vec<(crate::Entity, crate::Action)>,
    targets: Vec<(crate::Entity, ricochet_geom::Pose)>,
    targeted: Vec<crate::Entity>,
    focus: Option<crate::Entity>,
    touching: Vec<(crate::Entity, crate::Entity)>,
    statics_moved: bool,
    bodies: crate::world::Bodies,
}

/// The world as the simulation was built, before its first step: what a snapshot's bodies
/// are written against (`world/state/`). Shared by the simulation's clones.
///
/// Kept packed (`world/state/packed.rs`: a tile map's rows as runs, a few bytes a tile), and
/// unpacked by the first snapshot, restore or checksum, which keeps the world it unpacks:
/// a simulation that never takes one never holds a second copy of its world.
#[derive(Debug)]
pub(crate) struct Baseline {
    packed: PackedWorld,
    /// The world unpacked, once a snapshot needs it.
    world: OnceLock<World>,
    /// The scene's hash: its definition and this world (computed at the first snapshot).
    scene: OnceLock<u64>,
}

impl Baseline {
    /// The baseline of a simulation whose world is `world` before its first step.
    pub(crate) fn new(world: &World) -> Arc<Baseline> {
        Arc::new(Baseline {
            packed: world.packed(),
            world: OnceLock::new(),
            scene: OnceLock::new(),
        })
    }

    /// The world before the first step.
    fn world(&self) -> &World {
        self.world.get_or_init(|| self.packed.unpack())
    }
}

impl Simulation {
    /// The hash of what a snapshot references instead of copying: the world settings,
    /// layers, templates and script (their `Debug` text, which writes every float exactly),
    /// and the baseline's bodies, every field.
    fn scene_hash(&self) -> u64 {
        *self.baseline.scene.get_or_init(|| {
            let s = &self.scenario;
            let mut h = Hasher::default();
            h.str(&format!("{:?}|{:?}|{:?}", s.world, s.templates, s.script));
            self.baseline.world().encode(&World::new(), &mut h, true);
            h.finish()
        })
    }

    /// Writes the state a step reads (module docs), and with `game_data` the user data.
    fn encode_state(&self, s: &mut impl Sink, game_data: bool) {
        s.u64(self.frame);
        s.u64(self.cursor as u64);
        s.len(self.pending.len());
        for (e, a) in &self.pending {
            s.entity(*e);
            s.action(a);
        }
        s.len(self.targets.len());
        for (e, p) in &self.targets {
            s.entity(*e);
            s.pose(*p);
        }
        s.len(self.targeted.len());
        for e in &self.targeted {
            s.entity(*e);
        }
        s.opt_entity(self.focus);
        let touching = self.touch.touching();
        s.len(touching.len());
        for (a, b) in touching {
            s.entity(*a);
            s.entity(*b);
        }
        s.bool(self.touch.static_generation() != self.world.static_generation());
        self.world.encode(self.baseline.world(), s, game_data);
    }

    /// The state the next step reads, and the game's user data: every body's state (the
    /// module docs' table), the scene by its hash.
    #[must_use]
    pub fn snapshot(&self) -> Snapshot {
        let mut payload = Vec::with_capacity(64 + 26 * self.world.movers().len());
        self.encode_state(&mut payload, true);
        Snapshot {
            frame: self.frame,
            scene: self.scene_hash(),
            payload,
        }
    }

    /// Puts the simulation back in the state of `s`: it then steps exactly as the one `s`
    /// was taken of did from there. The broad phase and the grids are built anew. The
    /// thread count and `capture_detect_poses` stay this simulation's, and so does the
    /// length of its history, whose frames are cleared ([`Simulation::past`]: they belong
    /// to the timeline left).
    ///
    /// # Errors
    /// [`SnapshotError::OtherScene`] for a snapshot of another scene,
    /// [`SnapshotError::Malformed`] for a state this scene cannot hold (a layer it lacks, a
    /// script cursor past its script). The simulation is unchanged then.
    pub fn restore(&mut self, s: &Snapshot) -> Result<(), SnapshotError> {
        let scene = self.scene_hash();
        if s.scene != scene {
            return Err(SnapshotError::OtherScene {
                snapshot_scene: s.scene,
                scene,
            });
        }
        let layers = &self.scenario.world.layers;
        let st = s.decode(self.baseline.world(), layers.names().len())?;
        if st.cursor > self.scenario.script.len() {
            return Err(SnapshotError::malformed("a script cursor past the script"));
        }
        self.detect = DetectState::new(layers, self.scenario.world.broad_phase);
        self.separate = SeparateState::new(layers);
        self.world.restore_bodies(self.baseline.world(), &st.bodies);
        let g = self.world.static_generation();
        let seen = if st.statics_moved {
            g.wrapping_sub(1)
        } else {
            g
        };
        self.touch = TouchState::restored(layers, st.touching, seen);
        // Another world: neither tree set of the scene queries may be kept (a static
        // generation can repeat with other static bodies).
        self.queries = crate::query::cache::QueryCache::default();
        // The frames kept belong to the timeline left (`history.rs`); the length stays.
        self.history.clear();
        self.frame = s.frame;
        self.cursor = st.cursor;
        self.pending = st.pending;
        self.targets = st.targets;
        self.targeted = st.targeted;
        self.focus = st.focus;
        Ok(())
    }

    /// A checksum of exactly the state a step reads: the module docs' table, every column
    /// marked "in `checksum`" (frame, script cursor, pending inputs, kinematic targets,
    /// focus, touching pairs, every body's state and shape and name, the id generations),
    /// each float by its bits. Not the user data (no stage reads it), not the caches, not
    /// the scene's definition. Two simulations of one scene with equal checksums step
    /// identically; a change of any one of those fields changes it.
    #[must_use]
    pub fn checksum(&self) -> u64 {
        let mut b = Vec::with_capacity(64 + 26 * self.world.movers().len());
        self.encode_state(&mut b, false);
        hash(&b)
    }
}
