//! A list of bodies that is one run: consecutive dense indices whose rows are consecutive
//! too. Bodies spawned one after another and never removed (an asteroid field, a rain of
//! drops) are such a run, and a pass over them reads each column as one slice, in place,
//! instead of gathering every body through the list and then through its row. The pass's
//! arithmetic, and its order, are the same either way: only how it finds the values
//! differs.

use super::{NO_ROW, World};

/// Bodies `index..index + len`, whose rows are `row..row + len` in the same order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct RowRun {
    pub(super) index: usize,
    pub(super) row: usize,
    pub(super) len: usize,
}

impl RowRun {
    /// The run's dense indices.
    pub(super) fn indices(self) -> std::ops::Range<usize> {
        self.index..self.index + self.len
    }

    /// The run's rows.
    pub(super) fn rows(self) -> std::ops::Range<usize> {
        self.row..self.row + self.len
    }
}

impl World {
    /// `list` (dense indices, ascending, without repeats: [`World::movers`] or
    /// [`World::active`]) as one [`RowRun`], if it is one and is not empty.
    pub(super) fn row_run(&self, list: &[u32]) -> Option<RowRun> {
        #[cfg(test)]
        if tests::NO_RUNS.get() {
            return None;
        }
        let (&first, &last) = (list.first()?, list.last()?);
        // Ascending without repeats: consecutive exactly when the ends are as far apart as
        // the length says.
        if (last - first) as usize + 1 != list.len() {
            return None;
        }
        let index = first as usize;
        let rows = self.row.get(index..=last as usize)?;
        let row = rows[0];
        if row == NO_ROW || row as usize + rows.len() > self.rows.entity.len() {
            return None;
        }
        // In blocks without an early exit inside, which the compiler vectorises.
        let consecutive = rows
            .chunks(64)
            .zip((row..).step_by(64))
            .all(|(block, start)| {
                block
                    .iter()
                    .zip(start..)
                    .fold(true, |all, (&r, want)| all & (r == want))
            });
        consecutive.then_some(RowRun {
            index,
            row: row as usize,
            len: rows.len(),
        })
    }

    /// [`World::row_run`] of the movers, kept while the layout stays: only a body coming or
    /// going (or a restore, which takes a new layout) moves a mover's index or row. The
    /// scan reads 40 KB at 10,000 bodies, and a step asks it several times.
    pub(super) fn movers_run(&mut self) -> Option<RowRun> {
        #[cfg(test)]
        if tests::NO_RUNS.get() {
            return None;
        }
        match self.kept_run {
            Some((layout, run)) if layout == self.layout => {
                debug_assert_eq!(
                    run,
                    self.row_run(&self.movers),
                    "kept while the layout stays"
                );
                run
            }
            _ => {
                let run = self.row_run(&self.movers);
                self.kept_run = Some((self.layout, run));
                run
            }
        }
    }

    /// [`World::row_run`] of the active bodies: the movers' kept one when every mover is
    /// active (the active bodies are movers).
    pub(super) fn active_run(&mut self) -> Option<RowRun> {
        if self.active.len() == self.movers.len() {
            debug_assert_eq!(self.active, self.movers, "the active bodies are movers");
            self.movers_run()
        } else {
            self.row_run(&self.active)
        }
    }
}

#[cfg(test)]
mod tests {
    use std::cell::Cell;

    use ricochet_geom::{Bounds, Shape, Vec2};

    use crate::broad_phase::Extent;
    use crate::def::{BodyDef, BodyKind};
    use crate::world::{MoverEntries, World};

    thread_local! {
        /// Every pass of this thread goes body by body, as if no list were a run: the
        /// reference the run paths are compared with.
        pub(super) static NO_RUNS: Cell<bool> = const { Cell::new(false) };
    }

    fn body(kind: BodyKind) -> BodyDef {
        BodyDef {
            kind,
            velocity: ricochet_geom::Vec2::new(1.0, 0.0),
            ..BodyDef::default()
        }
    }

    #[test]
    fn a_run_is_found_only_where_indices_and_rows_are_both_consecutive() {
        let mut w = World::new();
        assert_eq!(w.row_run(w.movers()), None, "no body, no run");
        for _ in 0..130 {
            w.spawn(&body(BodyKind::Dynamic));
        }
        let run = w.row_run(w.movers()).expect("spawned in order");
        assert_eq!((run.index, run.row, run.len), (0, 0, 130));
        // Removing a body in the middle moves the last row into its place: the indices
        // are still consecutive, the rows are not.
        w.despawn(60);
        assert_eq!(w.movers().len(), 129);
        assert_eq!(w.row_run(w.movers()), None);
        // The list of the first 60 bodies is still a run.
        assert_eq!(
            w.row_run(&w.movers()[..60])
                .map(|r| (r.index, r.row, r.len)),
            Some((0, 0, 60))
        );
        // Indices that skip one are no run.
        let gap: Vec<u32> = (0..10).chain(11..20).collect();
        assert_eq!(w.row_run(&gap), None);
    }

    #[test]
    fn the_movers_run_kept_follows_every_body_that_comes_or_goes() {
        let mut w = World::new();
        assert_eq!(w.movers_run(), None, "no body, no run");
        for _ in 0..100 {
            w.spawn(&body(BodyKind::Dynamic));
        }
        let fresh = |w: &World| w.row_run(w.movers());
        // Asked twice: the second answer is the kept one.
        for _ in 0..2 {
            assert_eq!(w.movers_run().map(|r| r.len), Some(100));
        }
        w.despawn(40);
        assert_eq!(
            (w.movers_run(), fresh(&w)),
            (None, None),
            "rows out of order"
        );
        // The last body, removed, leaves the rows in order again.
        let mut w = World::new();
        for _ in 0..10 {
            w.spawn(&body(BodyKind::Dynamic));
        }
        assert_eq!(w.movers_run().map(|r| r.len), Some(10));
        w.despawn(9);
        assert_eq!(w.movers_run().map(|r| r.len), Some(9));
        w.spawn(&body(BodyKind::Dynamic));
        assert_eq!(w.movers_run().map(|r| r.len), Some(10));
        // Scenery after them (a new layout, the same run).
        w.spawn(&BodyDef {
            kind: BodyKind::Static,
            ..BodyDef::default()
        });
        assert_eq!(w.movers_run(), fresh(&w));
        // Every mover active: the active run is the movers' one.
        assert_eq!(w.active_run(), fresh(&w));
    }

    #[test]
    fn scenery_before_the_movers_leaves_their_run_intact() {
        let mut w = World::new();
        w.spawn(&BodyDef {
            kind: BodyKind::Static,
            ..BodyDef::default()
        });
        for _ in 0..3 {
            w.spawn(&body(BodyKind::Dynamic));
        }
        let run = w.row_run(w.movers()).expect("scenery has no row");
        assert_eq!((run.index, run.row, run.len), (1, 0, 3));
        // The scenery alone is no run: it has no row.
        assert_eq!(w.row_run(&[0]), None);
    }

    /// A body of every sort the passes treat apart: circles (bounds kept at every angle),
    /// turning boxes and polygons, kinematic and dynamic, on three layers.
    fn varied(k: usize) -> BodyDef {
        let f = k as f64;
        let shape = match k % 3 {
            0 => Shape::circle(0.5 + f * 0.01),
            1 => Shape::obb(Vec2::new(0.7, 0.2)),
            _ => Shape::polygon(&[
                Vec2::new(-1.0, -0.5),
                Vec2::new(1.0, -0.4),
                Vec2::new(0.1, 0.9),
            ]),
        };
        BodyDef {
            layer: (k % 3) as u8,
            shape: shape.expect("a valid shape"),
            kind: if k % 7 == 3 {
                BodyKind::Kinematic
            } else {
                BodyKind::Dynamic
            },
            mass: 1.0 + f * 0.37,
            position: Vec2::new(f * 1.37 - 50.0, f * 0.71 - 20.0),
            angle: f * 0.1,
            velocity: Vec2::new((f * 0.9) % 7.0 * 9.0 - 30.0, 45.0 - (f * 1.3) % 11.0 * 8.0),
            angular_velocity: if k.is_multiple_of(2) {
                0.0
            } else {
                f * 0.05 - 2.0
            },
            ..BodyDef::default()
        }
    }

    #[test]
    fn the_passes_over_a_run_give_the_bits_of_the_passes_body_by_body() {
        // Without a force or a gravity scale (forces of -0.0 count as none), the run's
        // `forces` pass reads neither column; with some, it reads both. With masses that
        // are powers of two, gravity alone accelerates every body by `g` itself, and the
        // run's pass divides by no mass (`motion.rs`, `GravityExact`); with the varied
        // masses, six do not give `g` back, and it divides.
        for (pushed, exact) in [(false, false), (true, false), (false, true)] {
            passes_over_a_run(pushed, exact);
        }
    }

    /// Whether gravity alone is exact is found again when a body comes (a mass that does
    /// not give `g` back: 1 + 17 × 0.37) and when `g` changes, and kept otherwise.
    #[test]
    fn gravity_alone_exact_is_found_again_when_a_mass_or_g_changes() {
        let mut w = World::new();
        for k in 0..4 {
            w.spawn(&BodyDef {
                mass: f64::from(1 << k),
                ..varied(3 * k)
            });
        }
        let (g, h) = (Vec2::new(0.0, -9.81), Vec2::new(0.0, -9.80665));
        let step = |w: &mut World, g: Vec2| w.accelerate(1.0 / 60.0, g, |_, _, _| Vec2::ZERO);
        step(&mut w, g);
        assert_eq!(w.gravity_exact.found(), Some((4, true)));
        let m = 1.0 + 17.0 * 0.37;
        assert_ne!((g * m) / m, g);
        assert_eq!((h * m) / m, h, "another g, that mass gives it back");
        w.spawn(&BodyDef {
            mass: m,
            ..varied(0)
        });
        step(&mut w, g);
        assert_eq!(w.gravity_exact.found(), Some((5, false)));
        step(&mut w, h);
        assert_eq!(w.gravity_exact.found(), Some((5, true)));
    }

    /// Entries kept from call to call write their keys, layers and kinds again when a
    /// body is frozen or thawed, comes or goes: each call's are those made afresh.
    #[test]
    fn kept_entries_follow_frozen_bits_and_bodies_that_come_and_go() {
        let mut w = World::new();
        for k in 0..12 {
            w.spawn(&varied(k));
        }
        let widen = (&[false; 3][..], &[false; 3][..]);
        let mut kept = MoverEntries::default();
        let check = |w: &mut World, kept: &mut MoverEntries| {
            let mut fresh = MoverEntries::default();
            let () = w.mover_entries(widen, &mut fresh, 0..0, |_, _| false);
            let () = w.mover_entries(widen, kept, 0..0, |_, _| false);
            assert_eq!(kept.list(), fresh.list());
        };
        check(&mut w, &mut kept);
        let i = w.movers()[4] as usize;
        w.set_frozen(i, true);
        check(&mut w, &mut kept);
        assert_eq!(
            kept.list()[4].kind,
            BodyKind::Kinematic,
            "frozen, handed over"
        );
        w.set_frozen(i, false);
        check(&mut w, &mut kept);
        w.spawn(&varied(20));
        check(&mut w, &mut kept);
        w.despawn(3);
        check(&mut w, &mut kept);
        assert_eq!(kept.list().len(), 12);
    }

    fn passes_over_a_run(pushed: bool, exact: bool) {
        let mut run = World::new();
        // Scenery first: its body has no row, so each mover's index is its row plus one.
        run.spawn(&BodyDef {
            kind: BodyKind::Static,
            ..BodyDef::default()
        });
        for k in 0..150 {
            let mut def = varied(k);
            if k % 5 == 1 {
                def.force = Vec2::new(-0.0, 0.0);
            }
            if pushed && k % 11 == 5 {
                (def.force, def.gravity_scale) = (Vec2::new(0.3, -0.2), 0.5);
            }
            if exact {
                def.mass = f64::from(1 << (k % 4));
            }
            run.spawn(&def);
        }
        let g = Vec2::new(0.0, -9.81);
        let inexact = (run.rows.mass.iter())
            .filter(|&&m| (Vec2::ZERO + g * (m * 1.0)) / m != g)
            .count();
        assert_eq!(inexact, if exact { 0 } else { 6 });
        assert_eq!((run.with_force > 0, run.rows.scaled > 0), (pushed, pushed));
        let mut plain = run.clone();
        assert!(run.row_run(run.movers()).is_some());
        let dt = 1.0 / 60.0;
        // Layer 1 sweeps, layer 2 is swept when it moves more than half its width.
        let (sweeping, separate_swept) = ([false, true, false], [false, false, true]);
        let mut seen = Vec::new();
        for (w, body_by_body) in [(&mut run, false), (&mut plain, true)] {
            NO_RUNS.set(body_by_body);
            assert_eq!(w.row_run(w.movers()).is_none(), body_by_body);
            let mut frames = Vec::new();
            let mut some = MoverEntries::default();
            for _ in 0..3 {
                w.start_frame();
                w.accelerate(dt, g, |_, _, _| Vec2::ZERO);
                // The run's pass keeps the energy it summed, the same bits as summed again.
                assert_eq!(w.kept_energy.is_some(), !body_by_body);
                assert_eq!(
                    w.step_kinetic_energy().to_bits(),
                    w.kinetic_energy().to_bits()
                );
                w.integrate(dt, true, true, true);
                let widen = (&sweeping[..], &separate_swept[..]);
                let mut entries = MoverEntries::default();
                let mut visited: Vec<(usize, Bounds)> = Vec::new();
                let extent: Extent = w.mover_entries(widen, &mut entries, 0..0, |k, b| {
                    visited.push((k, *b));
                    false
                });
                let entries = entries.list().to_vec();
                // Some places made apart, into entries kept from the frame before (their
                // keys then not written again): the same entries, each visited once.
                let skipped = 40..90;
                let () = w.mover_entries(widen, &mut some, skipped.clone(), |k, _| {
                    assert!(!skipped.contains(&k));
                    true
                });
                w.some_mover_entries(
                    widen,
                    &mut some,
                    skipped.clone(),
                    |k, b| {
                        assert_eq!((k, *b), visited[k]);
                        k % 3 == 0
                    },
                    None,
                );
                assert_eq!(some.list(), entries);
                // The extent measured as the entries were made is theirs: the tallest box
                // and the largest finite coordinate, each value tested on its own.
                let (mut height, mut max_abs) = (0.0f64, 0.0f64);
                for b in entries.iter().map(|e| e.bounds) {
                    height = height.max(b.max.y - b.min.y);
                    for v in [b.min.x, b.min.y, b.max.x, b.max.y] {
                        if v.abs().is_finite() {
                            max_abs = max_abs.max(v.abs());
                        }
                    }
                }
                let (h, a) = extent.get();
                assert_eq!(
                    (h.to_bits(), a.to_bits()),
                    (height.to_bits(), max_abs.to_bits())
                );
                let state: Vec<[u64; 7]> = (w.movers().iter())
                    .map(|&i| {
                        let (i, r) = (i as usize, w.row[i as usize] as usize);
                        let (p, s) = (w.position[i], w.rows.start_position[r]);
                        let v = w.rows.velocity[r];
                        [p.x, p.y, w.angle[i], s.x, s.y, v.x, v.y].map(f64::to_bits)
                    })
                    .collect();
                frames.push((state, w.kinetic_energy().to_bits(), entries, visited));
            }
            seen.push(frames);
        }
        NO_RUNS.set(false);
        assert_eq!(seen[0], seen[1]);
        // The run's pass found whether gravity alone is exact (only without a force or a
        // scale); the body-by-body one never asks.
        let found = |w: &World| w.gravity_exact.found();
        let expect = (!pushed).then_some((150, exact));
        assert_eq!((found(&run), found(&plain)), (expect, None));
    }
}
