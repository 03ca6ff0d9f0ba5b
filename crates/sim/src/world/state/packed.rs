//! The snapshot baseline, packed: a world as built keeps its scenery as runs, not as a copy
//! of a million bodies' columns.
//!
//! A tile map spawned row by row is runs of scenery with consecutive ids, one layer, shape,
//! name and angle, at `start + step * k` for the run's `k`-th body (as
//! [`World::spawn_tiles`] places them). A run of at least [`MIN_RUN`] such bodies is kept as
//! its first id, its length, its start and its kind (what its bodies share, once per
//! distinct kind), written as a few bytes ([`RunCoder`]): the id as its distance from the
//! end of the run before, and the start, when it is exactly the previous run's start plus
//! `m` steps (a floor's next stretch after a gap), as `m`. A floor of a tile map costs
//! about 6 bytes a run instead of 42 a body. Every other body keeps its every-body columns;
//! the rows and tables are kept whole, the allocator's generations run-length coded.
//! [`PackedWorld::unpack`] gives the world back, every column bit for bit (checked by the
//! round trip of every body when packing: a body the run's formula does not give back
//! exactly is loose; a start the previous run's does not give back exactly is written
//! whole).

use ricochet_geom::Vec2;

use super::super::{NO_ROW, World};
use super::runs_code::{Run, RunCoder, RunKind, RunReader, at, same};
use crate::entity::{Entity, EntityAllocator};

/// Scenery in a shorter run stays loose (a run costs 4 to 20 bytes, a loose body 42).
const MIN_RUN: usize = 2;

/// A world with its scenery runs packed (module docs).
#[derive(Debug, Clone)]
pub(crate) struct PackedWorld {
    /// The world, its every-body columns holding only the loose bodies.
    loose: World,
    /// The runs, in id order, as [`RunCoder`] writes them.
    runs: Vec<u8>,
    /// What the bodies of a run share, each distinct one once.
    kinds: Vec<RunKind>,
    /// The allocator's generations, run-length coded: `(generation, slots)` (a world as
    /// built has every slot at generation 0). Its free slots are every slot not alive.
    generations: Vec<(u32, u32)>,
}

impl World {
    /// The kind of body `i` as the first of a run whose bodies are `step` apart.
    fn run_kind(&self, i: usize, step: Vec2) -> RunKind {
        RunKind {
            generation: self.entity[i].generation,
            layer: self.layer[i],
            kind: self.kind[i],
            shape_id: self.shape_id[i],
            angle: self.angle[i].to_bits(),
            step: (step.x.to_bits(), step.y.to_bits()),
        }
    }

    /// How many bodies from `i` on make one run (at least 1).
    fn run_from(&self, i: usize) -> (usize, RunKind) {
        let n = self.len();
        let step = if i + 1 < n {
            self.position[i + 1] - self.position[i]
        } else {
            Vec2::ZERO
        };
        let kind = self.run_kind(i, step);
        if self.row[i] != NO_ROW {
            return (1, kind);
        }
        let (first, start) = (self.entity[i].index, self.position[i]);
        let mut k = 1;
        while i + k < n {
            let j = i + k;
            let fits = self.row[j] == NO_ROW
                && u64::from(self.entity[j].index) == u64::from(first) + k as u64
                && self.run_kind(j, step) == kind
                && same(self.position[j], at(start, step, k as u32));
            if !fits {
                break;
            }
            k += 1;
        }
        (k, kind)
    }

    /// This world, packed (module docs).
    pub(crate) fn packed(&self) -> PackedWorld {
        let mut loose = self.without_bodies();
        let (mut runs, mut kinds) = (RunCoder::default(), Vec::<RunKind>::new());
        let mut i = 0;
        while i < self.len() {
            let (count, kind) = self.run_from(i);
            if count < MIN_RUN {
                loose.push_body_columns(self, i);
                i += 1;
                continue;
            }
            // Looked for among the last few kinds only: runs of one kind come together, and
            // a world of a thousand kinds must not cost a thousand looks a run.
            let recent = kinds.len().saturating_sub(8);
            let k = match kinds[recent..].iter().position(|x| *x == kind) {
                Some(k) => recent + k,
                None => {
                    kinds.push(kind);
                    kinds.len() - 1
                }
            };
            runs.push(
                Run {
                    index: self.entity[i].index,
                    count: count as u32,
                    start: self.position[i],
                    kind: k as u32,
                },
                &kinds,
            );
            i += count;
        }
        loose.shrink_body_columns();
        let mut runs = runs.bytes;
        runs.shrink_to_fit();
        let mut generations: Vec<(u32, u32)> = Vec::new();
        for &g in self.ids.generations() {
            match generations.last_mut() {
                Some((last, n)) if *last == g => *n += 1,
                _ => generations.push((g, 1)),
            }
        }
        PackedWorld {
            loose,
            runs,
            kinds,
            generations,
        }
    }

    /// A copy of every column but the every-body ones, which are empty, and the id
    /// allocator, which is new (both callers set their own: a copy of a million generations
    /// would only raise the peak).
    fn without_bodies(&self) -> World {
        // Every field named: a new one fails to compile until it is placed here.
        let World {
            ids: _,
            entity: _,
            layer: _,
            kind: _,
            position: _,
            angle: _,
            shape_id: _,
            row: _,
            shapes,
            names,
            rows,
            movers,
            active,
            static_generation,
            with_lifetime,
            sleeping,
            controlled,
            with_force,
            thrusting,
            non_boxes,
            key,
            reshaped,
            layout: _,
            disturbed,
            kept_outside: _,
            kept_energy: _,
            gravity_exact: _,
            frozen_changes: _,
            kept_count: _,
            kept_run: _,
        } = self;
        World {
            ids: EntityAllocator::default(),
            entity: Vec::new(),
            layer: Vec::new(),
            kind: Vec::new(),
            position: Vec::new(),
            angle: Vec::new(),
            shape_id: Vec::new(),
            row: Vec::new(),
            shapes: shapes.clone(),
            names: names.clone(),
            rows: rows.clone(),
            movers: movers.clone(),
            active: active.clone(),
            static_generation: *static_generation,
            with_lifetime: *with_lifetime,
            sleeping: *sleeping,
            controlled: controlled.clone(),
            with_force: *with_force,
            thrusting: *thrusting,
            non_boxes: non_boxes.clone(),
            key: key.clone(),
            reshaped: *reshaped,
            // Another world: its own serial.
            layout: crate::interned::next_serial(),
            // Another world: its own serial, every body named.
            disturbed: disturbed.clone(),
            kept_outside: Default::default(),
            kept_energy: None,
            gravity_exact: Default::default(),
            frozen_changes: 0,
            kept_count: Default::default(),
            kept_run: None,
        }
    }

    /// Appends body `i` of `from` to the every-body columns.
    fn push_body_columns(&mut self, from: &World, i: usize) {
        self.entity.push(from.entity[i]);
        self.layer.push(from.layer[i]);
        self.kind.push(from.kind[i]);
        self.position.push(from.position[i]);
        self.angle.push(from.angle[i]);
        self.shape_id.push(from.shape_id[i]);
        self.row.push(from.row[i]);
    }

    /// Gives back what the every-body columns do not use.
    fn shrink_body_columns(&mut self) {
        self.entity.shrink_to_fit();
        self.layer.shrink_to_fit();
        self.kind.shrink_to_fit();
        self.position.shrink_to_fit();
        self.angle.shrink_to_fit();
        self.shape_id.shrink_to_fit();
        self.row.shrink_to_fit();
    }
}

impl PackedWorld {
    /// The runs, in id order.
    fn runs(&self) -> RunReader<'_> {
        RunReader {
            bytes: &self.runs,
            kinds: &self.kinds,
            last: None,
        }
    }

    /// The world as it was packed, every column bit for bit.
    pub(crate) fn unpack(&self) -> World {
        let l = &self.loose;
        let mut w = l.without_bodies();
        let n = l.len() + self.runs().map(|r| r.count as usize).sum::<usize>();
        w.reserve(n);
        let mut loose = 0;
        for r in self.runs() {
            // The loose bodies before the run (ids are in order in both).
            while loose < l.len() && l.entity[loose].index < r.index {
                w.push_body_columns(l, loose);
                loose += 1;
            }
            let kind = &self.kinds[r.kind as usize];
            let step = kind.step();
            for k in 0..r.count {
                w.entity.push(Entity {
                    index: r.index + k,
                    generation: kind.generation,
                });
                w.layer.push(kind.layer);
                w.kind.push(kind.kind);
                w.position.push(if k == 0 {
                    r.start
                } else {
                    at(r.start, step, k)
                });
                w.angle.push(f64::from_bits(kind.angle));
                w.shape_id.push(kind.shape_id);
                w.row.push(NO_ROW);
            }
        }
        while loose < l.len() {
            w.push_body_columns(l, loose);
            loose += 1;
        }
        let generations = self
            .generations
            .iter()
            .flat_map(|&(g, n)| std::iter::repeat_n(g, n as usize))
            .collect();
        w.ids = EntityAllocator::from_parts(generations, w.entity.iter().map(|e| e.index));
        w
    }

    /// The bytes the packed world holds.
    #[cfg(test)]
    fn heap_bytes(&self) -> usize {
        self.loose.heap_bytes()
            + self.runs.capacity()
            + self.kinds.capacity() * size_of::<RunKind>()
            + self.generations.capacity() * 8
    }
}

#[cfg(test)]
mod tests {
    use ricochet_geom::Shape;

    use super::*;
    use crate::def::{BodyDef, BodyKind};
    use crate::scenario::TileRows;

    /// Every column of `a` and `b` (the every-body ones bit for bit).
    fn assert_same(a: &World, b: &World) {
        assert_eq!(a.entity, b.entity);
        assert_eq!(a.layer, b.layer);
        assert_eq!(a.kind, b.kind);
        let bits = |w: &World| -> Vec<(u64, u64, u64)> {
            (0..w.len())
                .map(|i| {
                    let p = w.position[i];
                    (p.x.to_bits(), p.y.to_bits(), w.angle[i].to_bits())
                })
                .collect()
        };
        assert_eq!(bits(a), bits(b));
        assert_eq!(a.shape_id, b.shape_id);
        let names = |w: &World| {
            (0..w.len())
                .map(|i| w.name(i).to_owned())
                .collect::<Vec<_>>()
        };
        assert_eq!(names(a), names(b));
        assert_eq!(a.row, b.row);
        assert_eq!(a.movers, b.movers);
        assert_eq!(a.active, b.active);
        assert_eq!(a.ids.generations(), b.ids.generations());
        let (mut ha, mut hb) = (Vec::new(), Vec::new());
        a.encode(&World::new(), &mut ha, true);
        b.encode(&World::new(), &mut hb, true);
        assert_eq!(ha, hb);
    }

    /// Tiles in rows (one a tenth of a unit apart, inexact sums), a moving body among them,
    /// a tile removed from the middle of a row, and scenery at odd places.
    fn level() -> World {
        let mut w = World::new();
        let tile = Shape::aabb(Vec2::splat(0.5)).unwrap();
        w.spawn_tiles(
            &TileRows {
                name: "tile".to_owned(),
                layer: 0,
                shape: tile.clone(),
                step: Vec2::new(1.0, 0.0),
                rows: vec![(Vec2::new(0.5, 0.0), 40), (Vec2::new(2.5, 5.0), 7)],
            },
            |_| {},
        );
        w.spawn(&BodyDef {
            name: "actor".to_owned(),
            velocity: Vec2::new(1.0, 0.0),
            ..BodyDef::default()
        });
        w.spawn_tiles(
            &TileRows {
                name: "ledge".to_owned(),
                layer: 1,
                shape: tile.clone(),
                step: Vec2::new(0.1, 0.3),
                rows: vec![(Vec2::new(-7.3, 1.1), 30)],
            },
            |_| {},
        );
        // A floor with gaps: each stretch starts a whole number of steps after the last.
        w.spawn_tiles(
            &TileRows {
                name: "floor".to_owned(),
                layer: 0,
                shape: tile.clone(),
                step: Vec2::new(0.1, 0.0),
                rows: vec![
                    (Vec2::new(0.05, 20.0), 5),
                    (Vec2::new(0.65, 20.0), 3),
                    (Vec2::new(1.05, 20.0), 4),
                    (Vec2::new(1.05, 21.0), 4),
                ],
            },
            |_| {},
        );
        for x in [3.0, 1e6, -2.5] {
            w.spawn(&BodyDef {
                name: "rock".to_owned(),
                kind: BodyKind::Static,
                shape: tile.clone(),
                position: Vec2::new(x, 9.0),
                ..BodyDef::default()
            });
        }
        w.despawn(20);
        w
    }

    #[test]
    fn a_packed_world_unpacks_to_every_column_bit_for_bit() {
        let mut w = level();
        let packed = w.packed();
        let mut unpacked = packed.unpack();
        assert_same(&unpacked, &w);
        // The same free slots: the next ids are the same.
        for _ in 0..3 {
            assert_eq!(unpacked.ids.allocate(), w.ids.allocate());
        }
        // The rows are runs: a few loose bodies, not 80.
        assert!(packed.loose.len() < 10, "{} loose", packed.loose.len());
        assert_same(&World::new().packed().unpack(), &World::new());
    }

    /// A world of unit tiles of layer 0 in `rows` (each a start and a count, one unit apart).
    fn unit_tiles(rows: Vec<(Vec2, u32)>) -> World {
        let mut w = World::new();
        w.spawn_tiles(
            &TileRows {
                name: "tile".to_owned(),
                layer: 0,
                shape: Shape::aabb(Vec2::splat(0.5)).unwrap(),
                step: Vec2::new(1.0, 0.0),
                rows,
            },
            |_| {},
        );
        w
    }

    #[test]
    fn a_tile_map_packs_to_a_few_bytes_a_tile() {
        let rows: Vec<(Vec2, u32)> = (0..100)
            .map(|r| (Vec2::new(0.5 + f64::from(r % 8), 5.0 * f64::from(r)), 100))
            .collect();
        let w = unit_tiles(rows);
        let packed = w.packed();
        assert_same(&packed.unpack(), &w);
        let columns = 42 * w.len();
        assert!(
            packed.heap_bytes() < columns / 10,
            "{} bytes packed, {columns} in columns",
            packed.heap_bytes()
        );
    }

    #[test]
    fn a_floor_with_gaps_packs_to_a_few_bytes_a_stretch() {
        // 50 floors of 40 stretches of 7 tiles, one cell between stretches (a platformer).
        let mut rows = Vec::new();
        for f in 0..50 {
            for s in 0..40 {
                rows.push((Vec2::new(0.5 + 8.0 * f64::from(s), 5.0 * f64::from(f)), 7));
            }
        }
        let w = unit_tiles(rows);
        let packed = w.packed();
        assert_same(&packed.unpack(), &w);
        assert_eq!(packed.runs().count(), 2000);
        // A stretch after a gap: four one-byte numbers (a floor's first: 16 bytes more).
        assert!(
            packed.runs.len() <= 4 * 2000 + 16 * 50,
            "{} bytes for 2000 runs",
            packed.runs.len()
        );
    }
}
