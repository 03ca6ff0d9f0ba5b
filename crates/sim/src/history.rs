//! Lag compensation: the last frames' bodies, kept so that a query can be asked of the
//! world as it was (Valve's Source rewinds hitboxes; Unity's Netcode for Entities keeps up
//! to 32 past collision worlds).
//!
//! [`Simulation::keep_history`] turns it on: from then on the end of every step copies what
//! a query reads of each body into a ring of the last `n` frames, whose evicted frame's
//! buffers are reused: positions and angles (24 bytes a body, a copy of the two columns)
//! every frame; entities, layers and look ids (13 bytes a body) only when the world's
//! layout serial says a body was added, removed or reshaped since the last frame kept
//! (frames of one layout share them by `Arc`). Shapes are not copied per frame: a layout
//! holds an `Arc` of one table of shapes by look id, made anew only when the world's shape
//! table gave an id a new shape (a serial per id tells which), and then only that id's
//! shape is copied. [`Simulation::past`] answers with a [`Past`], which runs the same query code as
//! the world now (`query/`) over the kept columns; the frame's trees are built by its first
//! query and kept with it.
//!
//! Off (the default), a step does one branch more. A restore clears it: the frames kept
//! belong to the timeline the restore left. It is not part of a snapshot or checksum.

use std::collections::VecDeque;
use std::sync::{Arc, OnceLock};

use ricochet_geom::{Bounds, Pose, Shape, Vec2};

use crate::def::{LayerId, WorldBounds};
use crate::entity::Entity;
use crate::interned::ShapeTable;
use crate::limits::MAX_HISTORY;
use crate::pipeline::Simulation;
use crate::query::cache::Lent;
use crate::query::index::Trees;
use crate::query::{Bodies, QueryFilter, RayHit, Scene, ShapeHit};
use crate::world::World;

/// Why [`Simulation::past`] or [`Simulation::keep_history`] refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum HistoryError {
    /// History is off ([`Simulation::keep_history`] was not given a length, or was given 0).
    #[error("frame {frame} is not kept: history is off (turn it on with keep_history(n))")]
    Off {
        /// The frame asked for.
        frame: u64,
    },
    /// History is on but no frame was stepped since it was turned on or since a restore.
    #[error(
        "frame {frame} is not kept: no frame has been stepped since history was turned on \
         or the simulation was restored"
    )]
    NoneYet {
        /// The frame asked for.
        frame: u64,
    },
    /// The frame is older than the oldest kept, or has not been stepped yet.
    #[error("frame {frame} is not kept: frames {oldest} to {newest} are")]
    NotKept {
        /// The frame asked for.
        frame: u64,
        /// The oldest frame kept.
        oldest: u64,
        /// The newest frame kept: the last step's (`Simulation::frame() - 1`).
        newest: u64,
    },
    /// [`Simulation::keep_history`] was asked for more than [`MAX_HISTORY`] frames.
    #[error("cannot keep {asked} frames of history: at most {MAX_HISTORY} (MAX_HISTORY)")]
    TooLong {
        /// The length asked for.
        asked: usize,
    },
}

/// Shapes by look id, as of some frame.
type Looks = Vec<Option<Arc<Shape>>>;

/// The columns that change only when a body is added, removed or reshaped: shared by the
/// kept frames of one world layout ([`World::layout`]).
#[derive(Clone, Debug, Default)]
struct Layout {
    /// The world's layout serial they were copied at.
    serial: u64,
    entity: Vec<Entity>,
    layer: Vec<LayerId>,
    look: Vec<u32>,
    looks: Arc<Looks>,
}

/// One kept frame: the columns a query reads, as the end of its step left them.
#[derive(Clone, Debug, Default)]
pub(crate) struct Kept {
    frame: u64,
    layout: Arc<Layout>,
    position: Vec<Vec2>,
    angle: Vec<f64>,
    /// One tree over every body (static or not: a past frame never changes), and an empty
    /// set; built by the frame's first query.
    trees: OnceLock<[Arc<Trees>; 2]>,
}

/// Copies `from` into `to`, keeping `to`'s memory.
fn copy<T: Copy>(to: &mut Vec<T>, from: &[T]) {
    to.clear();
    to.extend_from_slice(from);
}

impl Bodies for &Kept {
    fn entity(&self) -> &[Entity] {
        &self.layout.entity
    }

    fn layer(&self) -> &[LayerId] {
        &self.layout.layer
    }

    #[inline]
    fn shape(&self, i: usize) -> &Shape {
        let l = &self.layout;
        l.looks[l.look[i] as usize]
            .as_deref()
            .expect("a kept body's look is kept")
    }

    #[inline]
    fn pose(&self, i: usize) -> Pose {
        Pose::new(self.position[i], self.angle[i])
    }

    fn trees(&self) -> [Lent<'_>; 2] {
        let [all, none] = self.trees.get_or_init(|| {
            let l = &self.layout;
            let all = Trees::over(
                0,
                &l.entity,
                &l.layer,
                (0..l.entity.len()).map(|i| (i, self.shape(i), self.pose(i))),
            );
            [Arc::new(all), Arc::new(Trees::default())]
        });
        [Lent::Kept(all), Lent::Kept(none)]
    }
}

/// The kept frames (see the module docs).
#[derive(Clone, Debug, Default)]
pub(crate) struct History {
    /// How many frames to keep (0: off).
    keep: usize,
    /// The kept frames, oldest first, consecutive; shared with the simulation's clones (a
    /// clone costs an `Arc` a frame, not a copy).
    frames: VecDeque<Arc<Kept>>,
    /// The shapes by look id as of the last kept frame (shared with the frames that hold
    /// the same ones).
    looks: Arc<Looks>,
    /// The world shape table's serial of each look id in `looks`.
    serials: Vec<u64>,
    /// The layout of the last kept frame (`None`: none since the last clear).
    layout: Option<Arc<Layout>>,
    /// The table's [`ShapeTable::last_serial`] when `looks` was brought up to date.
    synced: u64,
}

impl History {
    /// Whether steps are kept.
    #[inline]
    pub(crate) fn on(&self) -> bool {
        self.keep > 0
    }

    /// Forgets every frame (keeping the length).
    pub(crate) fn clear(&mut self) {
        let keep = self.keep;
        *self = History {
            keep,
            ..History::default()
        };
    }

    /// Brings `looks` up to date with `table`: the ids given a new shape since are copied.
    fn sync(&mut self, table: &ShapeTable) {
        if table.last_serial() == self.synced {
            return;
        }
        self.synced = table.last_serial();
        let n = table.len() as usize;
        // Copied only if a kept frame holds it.
        let looks = Arc::make_mut(&mut self.looks);
        looks.resize(n, None);
        self.serials.resize(n, 0);
        for (id, (look, seen)) in looks.iter_mut().zip(&mut self.serials).enumerate() {
            let id = id as u32;
            let Some((shape, _)) = table.try_get(id) else {
                // No body has it now: no frame kept from now on names it.
                continue;
            };
            let serial = table.serial(id);
            if *seen != serial {
                *seen = serial;
                *look = Some(Arc::new(shape.clone()));
            }
        }
    }

    /// Keeps `world` as the end of `frame` (the next after the newest kept).
    pub(crate) fn record(&mut self, world: &World, frame: u64) {
        self.sync(world.shape_table());
        // The evicted frame's buffers, unless a clone of the simulation still shares it.
        let mut k = if self.frames.len() >= self.keep {
            self.frames
                .pop_front()
                .and_then(|k| Arc::try_unwrap(k).ok())
                .unwrap_or_default()
        } else {
            Kept::default()
        };
        let same = self.layout.as_ref().is_some_and(|l| {
            l.serial == world.layout()
                && l.entity.len() == world.len()
                && Arc::ptr_eq(&l.looks, &self.looks)
        });
        if !same {
            // The evicted frame's, unless another frame still shares them.
            let mut l = Arc::try_unwrap(std::mem::take(&mut k.layout)).unwrap_or_default();
            l.serial = world.layout();
            copy(&mut l.entity, &world.entity);
            copy(&mut l.layer, &world.layer);
            copy(&mut l.look, world.looks());
            l.looks = Arc::clone(&self.looks);
            self.layout = Some(Arc::new(l));
        }
        let layout = self.layout.as_ref().expect("set above");
        debug_assert!(
            layout.entity == world.entity
                && layout.layer == world.layer
                && layout.look == world.looks(),
            "the world's layout serial changes with its bodies"
        );
        k.frame = frame;
        k.layout = Arc::clone(layout);
        copy(&mut k.position, &world.position);
        copy(&mut k.angle, &world.angle);
        k.trees = OnceLock::new();
        self.frames.push_back(Arc::new(k));
    }

    /// The oldest and newest frames kept.
    fn window(&self) -> Option<(u64, u64)> {
        Some((self.frames.front()?.frame, self.frames.back()?.frame))
    }
}

/// The world as it was at the end of a kept frame ([`Simulation::past`]): the same queries
/// as [`Simulation`]'s, with the same arguments and answers, asked of the bodies as a
/// [`Simulation::snapshot`] taken right after that frame's step holds them.
#[derive(Clone, Copy, Debug)]
pub struct Past<'a> {
    kept: &'a Kept,
    wrap: Option<&'a WorldBounds>,
}

impl<'a> Past<'a> {
    fn scene(&self) -> Scene<'a, &'a Kept> {
        Scene {
            bodies: self.kept,
            wrap: self.wrap,
        }
    }

    /// The frame it is the end of.
    #[must_use]
    pub fn frame(&self) -> u64 {
        self.kept.frame
    }

    /// How many bodies there were.
    #[must_use]
    pub fn len(&self) -> usize {
        self.kept.layout.entity.len()
    }

    /// Whether there were no bodies.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.kept.layout.entity.is_empty()
    }

    /// [`Simulation::cast_ray`] then.
    #[must_use]
    pub fn cast_ray(
        &self,
        origin: Vec2,
        direction: Vec2,
        max_distance: f64,
        filter: &QueryFilter,
    ) -> Option<RayHit> {
        self.scene()
            .cast_ray(origin, direction, max_distance, filter)
    }

    /// [`Simulation::cast_ray_all`] then.
    #[must_use]
    pub fn cast_ray_all(
        &self,
        origin: Vec2,
        direction: Vec2,
        max_distance: f64,
        filter: &QueryFilter,
    ) -> Vec<RayHit> {
        self.scene()
            .cast_ray_all(origin, direction, max_distance, filter)
    }

    /// [`Simulation::cast_shape`] then.
    #[must_use]
    pub fn cast_shape(
        &self,
        shape: &Shape,
        pose: Pose,
        translation: Vec2,
        filter: &QueryFilter,
    ) -> Option<ShapeHit> {
        self.scene().cast_shape(shape, pose, translation, filter)
    }

    /// [`Simulation::overlap_point`] then.
    #[must_use]
    pub fn overlap_point(&self, point: Vec2, filter: &QueryFilter) -> Vec<Entity> {
        self.scene().overlap_point(point, filter)
    }

    /// [`Simulation::overlap_aabb`] then.
    #[must_use]
    pub fn overlap_aabb(&self, bounds: Bounds, filter: &QueryFilter) -> Vec<Entity> {
        self.scene().overlap_aabb(bounds, filter)
    }

    /// [`Simulation::overlap_shape`] then.
    #[must_use]
    pub fn overlap_shape(&self, shape: &Shape, pose: Pose, filter: &QueryFilter) -> Vec<Entity> {
        self.scene().overlap_shape(shape, pose, filter)
    }
}

impl Simulation {
    /// Keeps the last `n` frames from the next step on, for [`Simulation::past`] (lag
    /// compensation: a shot checked against the world as the shooter saw it). 0 turns it
    /// off and frees what was kept (the default: a step then does one branch more). A
    /// shorter length than before drops the oldest frames. A frame kept costs 24 to 37
    /// bytes a body, and about 60 more once queried ([`MAX_HISTORY`]'s docs); a step about
    /// 6% more on `asteroids-10000` at `n = 32` (BENCHMARKS.md, "Lag compensation"). [`Simulation::restore`] clears the frames kept (the length
    /// stays); the history is in no snapshot or checksum.
    ///
    /// # Errors
    /// [`HistoryError::TooLong`] for more than [`MAX_HISTORY`] frames (nothing changes).
    pub fn keep_history(&mut self, n: usize) -> Result<(), HistoryError> {
        if n > MAX_HISTORY {
            return Err(HistoryError::TooLong { asked: n });
        }
        let h = &mut self.history;
        if n == 0 {
            *h = History::default();
            return Ok(());
        }
        h.keep = n;
        while h.frames.len() > n {
            h.frames.pop_front();
        }
        Ok(())
    }

    /// The frames kept, oldest to newest (the newest is the last step's,
    /// `frame() - 1`); `None` when none is.
    #[must_use]
    pub fn kept_frames(&self) -> Option<std::ops::RangeInclusive<u64>> {
        self.history.window().map(|(a, b)| a..=b)
    }

    /// The world as it was at the end of `frame`: what a [`Simulation::snapshot`] taken
    /// right after that frame's step holds (a body removed since is there, one spawned
    /// since is not), to query with the same methods. The end of the last step is
    /// `past(frame() - 1)`.
    ///
    /// # Errors
    /// A frame not kept: [`HistoryError::Off`] when history is off,
    /// [`HistoryError::NoneYet`] before the first step since it was turned on (or since a
    /// restore), [`HistoryError::NotKept`] (naming the frames kept) for a frame too old or
    /// not stepped yet. Never an answer from another frame.
    pub fn past(&self, frame: u64) -> Result<Past<'_>, HistoryError> {
        let h = &self.history;
        if !h.on() {
            return Err(HistoryError::Off { frame });
        }
        let Some((oldest, newest)) = h.window() else {
            return Err(HistoryError::NoneYet { frame });
        };
        if frame < oldest || frame > newest {
            return Err(HistoryError::NotKept {
                frame,
                oldest,
                newest,
            });
        }
        // Kept frames are consecutive.
        let kept = &h.frames[(frame - oldest) as usize];
        debug_assert_eq!(kept.frame, frame);
        Ok(Past {
            kept,
            wrap: crate::query::wrapping(self.scenario.world.bounds.as_ref()),
        })
    }
}
