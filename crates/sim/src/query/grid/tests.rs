//! The grid's tests: its answers against a loop over every box, on random boxes and on
//! tiles lined up with its cells, and its rays against the slab test.

use super::*;

/// A seeded xorshift in `[0, 1)`.
fn uniform(s: &mut u64) -> f64 {
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    (*s >> 11) as f64 / (1u64 << 53) as f64
}

/// Every member whose box meets `q`, by a loop over all (the definition).
fn brute(boxes: &[Bounds], q: &Bounds) -> Vec<usize> {
    (0..boxes.len()).filter(|&k| boxes[k].overlaps(q)).collect()
}

fn grid_answer(grid: &Grid, q: &Bounds) -> Vec<usize> {
    let mut got = Vec::new();
    grid.query(q, &mut |k| got.push(k));
    got.sort_unstable();
    got
}

/// Whether the grid must report box `m` to query `q`: they share more than a side (the
/// intersection's lower corner is below `m`'s top and left of its right side).
fn must(m: &Bounds, q: &Bounds) -> bool {
    m.overlaps(q) && q.min.x.max(m.min.x) < m.max.x && q.min.y.max(m.min.y) < m.max.y
}

/// The grid's answer to `q`: once each, every box that must be reported, and no box
/// that does not at least touch `q` (the module docs).
fn check_answer(grid: &Grid, boxes: &[Bounds], q: &Bounds) {
    let got = grid_answer(grid, q);
    let mut once = got.clone();
    once.dedup();
    assert_eq!(once, got, "reported twice: query {q:?}");
    let must: Vec<usize> = (0..boxes.len()).filter(|&k| must(&boxes[k], q)).collect();
    assert!(
        must.iter().all(|k| got.binary_search(k).is_ok()),
        "missed: query {q:?}, got {got:?}, must {must:?}"
    );
    let touching = brute(boxes, q);
    assert!(
        got.iter().all(|k| touching.binary_search(k).is_ok()),
        "a box apart: query {q:?}"
    );
}

/// Unit tiles edge to edge (touching boxes, queries touching them at cell edges), and
/// random boxes of mixed sizes, a few much larger than the rest.
fn mixed(s: &mut u64) -> Vec<Bounds> {
    let mut boxes: Vec<Bounds> = (0..400)
        .map(|k| {
            let c = Vec2::new((k % 20) as f64, (k / 20) as f64);
            Bounds::around(c, Vec2::splat(0.5))
        })
        .collect();
    for k in 0..300 {
        let c = Vec2::new(uniform(s) * 40.0 - 10.0, uniform(s) * 40.0 - 10.0);
        let big = if k % 60 == 0 { 8.0 } else { 1.0 };
        let h = Vec2::new(uniform(s) * big, uniform(s) * big);
        boxes.push(Bounds::around(c, h));
    }
    boxes
}

#[test]
fn a_grid_reports_every_box_met_once_as_a_loop_over_all_does() {
    let mut s = 0x9e37_79b9_7f4a_7c15;
    let boxes = mixed(&mut s);
    let grid = Grid::new(&boxes).expect("a grid");
    assert!(!grid.big.is_empty(), "the large boxes are kept apart");
    for k in 0..3000 {
        let c = if k % 3 == 0 {
            // On tile corners and edges exactly.
            Vec2::new(
                (uniform(&mut s) * 44.0).floor() - 12.5,
                (uniform(&mut s) * 44.0).floor() - 12.5,
            )
        } else {
            Vec2::new(uniform(&mut s) * 60.0 - 20.0, uniform(&mut s) * 60.0 - 20.0)
        };
        let h = if k % 3 == 0 {
            Vec2::splat(0.5 * (1 + k % 4) as f64)
        } else {
            Vec2::new(uniform(&mut s) * 3.0, uniform(&mut s) * 3.0)
        };
        let q = Bounds::around(c, h);
        check_answer(&grid, &boxes, &q);
    }
}

/// Unit tiles edge to edge, as a level of tiles: the cells (two tiles wide) line up
/// with them, so every tile is listed once, not in the cells its box only touches; and
/// queries on the tiles' edges and corners, and points on them, still find every tile
/// they share more than a side with, and rays along the cells' edges every tile the
/// slab test meets.
#[test]
fn tiles_on_the_cells_edges_are_listed_once_and_still_found() {
    let boxes: Vec<Bounds> = (0..40 * 30)
        .map(|k| {
            let c = Vec2::new((k % 40) as f64 + 0.5, (k / 40) as f64 + 0.5);
            Bounds::around(c, Vec2::splat(0.5))
        })
        .collect();
    let grid = Grid::new(&boxes).expect("a grid");
    assert_eq!(
        (grid.side, grid.origin),
        (2.0, Vec2::ZERO),
        "cells on the tiles"
    );
    assert_eq!(grid.entries.len(), boxes.len(), "each tile listed once");
    let mut s = 0x51ed_2701_9a3c_44f1;
    for k in 0..4000 {
        let half = |s: &mut u64| (1.0 + (uniform(s) * 6.0).floor()) * 0.25;
        let c = Vec2::new(
            (uniform(&mut s) * 176.0).floor() * 0.25 - 2.0,
            (uniform(&mut s) * 136.0).floor() * 0.25 - 2.0,
        );
        let h = if k % 5 == 0 {
            Vec2::ZERO // a point, on an edge or a corner as often as not
        } else {
            Vec2::new(half(&mut s), half(&mut s))
        };
        check_answer(&grid, &boxes, &Bounds::around(c, h));
    }
    let hull = boxes.iter().copied().reduce(Bounds::union).expect("boxes");
    for k in 0..400 {
        // Along and across the cells' edges (even coordinates), and diagonally.
        let o = Vec2::new(f64::from(k % 20 * 2), f64::from(k / 20 % 15 * 2));
        let dir = [
            Vec2::X,
            Vec2::Y,
            -Vec2::X,
            -Vec2::Y,
            Vec2::new(1.0, 1.0).normalize(),
        ][k as usize % 5];
        let slab = Slab::new(o, dir, &hull);
        let want: Vec<usize> = (0..boxes.len())
            .filter(|&j| slab.enter(&boxes[j], 30.0).is_some())
            .collect();
        let mut got = Vec::new();
        assert!(grid.ray(o, dir, 30.0, &mut |j, m| {
            got.push(j);
            m
        }));
        got.sort_unstable();
        got.dedup();
        assert!(
            want.iter().all(|j| got.binary_search(j).is_ok()),
            "ray from {o:?} along {dir:?}"
        );
    }
}

#[test]
fn a_grid_ray_meets_every_box_the_slab_test_meets_and_finds_the_same_first() {
    let mut s = 0x2545_f491_4f6c_dd1d;
    let boxes = mixed(&mut s);
    let grid = Grid::new(&boxes).expect("a grid");
    let hull = boxes.iter().copied().reduce(Bounds::union).expect("boxes");
    for k in 0..3000 {
        let o = if k % 4 == 0 {
            // On tile edges and corners, along the axes and the diagonals.
            Vec2::new(
                (uniform(&mut s) * 44.0).floor() - 12.5,
                (uniform(&mut s) * 44.0).floor() - 12.0,
            )
        } else {
            Vec2::new(uniform(&mut s) * 60.0 - 20.0, uniform(&mut s) * 60.0 - 20.0)
        };
        let a = if k % 4 == 0 {
            std::f64::consts::FRAC_PI_4 * (k / 4 % 8) as f64
        } else {
            uniform(&mut s) * std::f64::consts::TAU
        };
        // Exactly along each axis too (`cos` of a right angle is not zero).
        let axes = [Vec2::X, Vec2::Y, -Vec2::X, -Vec2::Y];
        let dir = if k % 16 == 4 {
            axes[k / 16 % 4]
        } else {
            Vec2::new(libm::cos(a), libm::sin(a))
        };
        let max = if k % 8 == 1 {
            60.0
        } else {
            uniform(&mut s) * 20.0
        };
        let slab = Slab::new(o, dir, &hull);
        let want: Vec<usize> = (0..boxes.len())
            .filter(|&j| slab.enter(&boxes[j], max).is_some())
            .collect();
        // Every candidate, `max` kept.
        let mut got = Vec::new();
        assert!(grid.ray(o, dir, max, &mut |j, m| {
            got.push(j);
            m
        }));
        got.sort_unstable();
        got.dedup();
        assert_eq!(got, want, "ray from {o:?} along {dir:?} for {max}");
        // A first-hit search (a member hit where the segment enters its box): the
        // same first as over every box.
        let first = want
            .iter()
            .filter_map(|&j| slab.enter(&boxes[j], max).map(|t| (t, j)))
            .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut best: Option<(f64, usize)> = None;
        grid.ray(o, dir, max, &mut |j, m| {
            if let Some(t) = slab.enter(&boxes[j], m)
                && best.is_none_or(|b| (t, j) < b)
            {
                best = Some((t, j));
            }
            best.map_or(m, |b| b.0)
        });
        assert_eq!(best, first, "ray from {o:?} along {dir:?} for {max}");
    }
}

#[test]
fn no_grid_for_infinite_or_too_many_large_boxes_and_nan_boxes_meet_nothing() {
    let unit = |x: f64| Bounds::around(Vec2::new(x, 0.0), Vec2::splat(0.5));
    let mut boxes: Vec<Bounds> = (0..100).map(|k| unit(k as f64)).collect();
    let mut inf = boxes.clone();
    inf.push(Bounds {
        min: Vec2::new(f64::NEG_INFINITY, 0.0),
        max: Vec2::new(0.0, 1.0),
    });
    assert!(Grid::new(&inf).is_none());
    let mut large = boxes.clone();
    large.extend((0..=BIG).map(|_| Bounds::around(Vec2::ZERO, Vec2::splat(40.0))));
    assert!(Grid::new(&large).is_none());
    boxes.push(Bounds {
        min: Vec2::new(f64::NAN, 0.0),
        max: Vec2::new(1.0, 1.0),
    });
    let grid = Grid::new(&boxes).expect("a grid");
    let q = Bounds::around(Vec2::new(0.5, 0.0), Vec2::splat(2.0));
    assert_eq!(grid_answer(&grid, &q), vec![0, 1, 2, 3]);
    assert!(Grid::new(&[]).is_none());
}
