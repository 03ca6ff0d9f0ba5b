//! Fast bodies in a wrapping world (issue 20): the contacts of any scene, at any speed, are
//! those of the same scene with every body wrapped into the world first. A body may end its
//! motion (or be placed) any number of world sizes out; `detect` must still meet what its
//! logged, wrapped pose overlaps.

use proptest::prelude::*;
use ricochet_geom::{Pose, Shape, Vec2, contact};
use ricochet_scenes::{layers, scenario};
use ricochet_sim::{BodyDef, BodyKind, Response, Simulation, WorldBounds, WorldDef};

/// A wrapping world `min .. min + size` with one layer of bodies that `report` each other.
fn world(min: Vec2, size: Vec2) -> WorldDef {
    WorldDef {
        layers: layers(&["disc"], &[(0, 0, Response::Report)]),
        bounds: Some(WorldBounds {
            min,
            max: min + size,
            wrap: true,
        }),
        ..WorldDef::default()
    }
}

fn disc(name: &str, r: f64, at: Vec2, v: Vec2) -> BodyDef {
    ricochet_scenes::moving_body(name, 0, Shape::circle(r).unwrap(), at, v)
}

/// The scene: a disc of radius 5 at `[5, 50]` moving `vx` units a second, and a
/// still one at `[8, 50]`, in a 100 x 100 wrapping world at 60 Hz.
fn fast_and_still(vx: f64, frames: u64) -> Simulation {
    let bodies = vec![
        disc("fast", 5.0, Vec2::new(5.0, 50.0), Vec2::new(vx, 0.0)),
        disc("still", 5.0, Vec2::new(8.0, 50.0), Vec2::ZERO),
    ];
    let w = world(Vec2::ZERO, Vec2::splat(100.0));
    Simulation::new(&scenario("wrap-fast", w, bodies, frames))
}

/// The depth of each frame's contact, one entry per contact.
fn depths(mut sim: Simulation, frames: u64) -> Vec<f64> {
    let mut out = Vec::new();
    for _ in 0..=frames {
        out.extend(sim.step().contacts.iter().map(|c| c.depth));
    }
    out
}

#[test]
fn a_disc_two_world_widths_a_frame_meets_the_still_disc_in_every_frame() {
    // 12000 / 60 = 200 units a frame: back at x = 5 (wrapped) every frame, centres 3 apart.
    assert_eq!(depths(fast_and_still(12000.0, 60), 60), vec![7.0; 61]);
}

#[test]
fn a_disc_110_units_a_frame_meets_the_still_disc_where_its_wrapped_pose_overlaps() {
    // 6600 / 60 = 110 units a frame: at x = 5 + 10 f (mod 100) in frame f, so at 5 in
    // frames 0, 10, ..., 60 (centres 3 apart: 7 deep) and at 15 in frames 1, 11, ..., 51
    // (7 apart: 3 deep); elsewhere at least 13 apart, through the seam or not. 13 contacts.
    let d = depths(fast_and_still(6600.0, 60), 60);
    let mut expected = [7.0, 3.0].repeat(6);
    expected.push(7.0);
    assert_eq!(d.len(), expected.len(), "{d:?}");
    for (got, want) in d.iter().zip(expected) {
        assert!((got - want).abs() < 1e-9, "{d:?}");
    }
}

#[test]
fn speeds_near_the_limits_keep_every_body_finite_and_inside_the_world() {
    // Placed 1e15 out and moving up to 1e15 units a second (the loader's limits): each
    // is wrapped in one step, every frame, with no NaN, and the contacts stay finite.
    let bodies = vec![
        disc("a", 5.0, Vec2::new(1e15, -1e15), Vec2::new(1e15, -1e15)),
        disc("b", 5.0, Vec2::new(-1e15, 3.0), Vec2::new(-1e15, 7e14)),
        disc("c", 40.0, Vec2::new(50.0, 50.0), Vec2::new(1e15, 0.0)),
    ];
    let size = Vec2::new(100.0, 100.0);
    let mut sim = Simulation::new(&scenario("limits", world(Vec2::ZERO, size), bodies, 30));
    for _ in 0..=30 {
        let out = sim.step();
        assert!(out.contacts.iter().all(|c| c.depth.is_finite()));
        assert!(out.contacts.iter().all(|c| c.normal.is_finite()));
        let w = sim.world();
        for i in 0..w.len() {
            let p = w.position[i];
            assert!(p.is_finite(), "{p}");
            // Frame 0 too: `a` and `b` are placed far out, and `detect` brings them in.
            assert!(
                p.cmpge(Vec2::ZERO).all() && p.cmplt(size).all(),
                "frame {}: {p}",
                out.frame
            );
        }
    }
}

/// `p` wrapped into `[min, min + size)` on each axis (written here, not borrowed from
/// the simulation).
fn wrapped(p: Vec2, min: Vec2, size: Vec2) -> Vec2 {
    let one = |p: f64, lo: f64, s: f64| {
        let q = lo + (p - lo).rem_euclid(s);
        if q < lo + s { q } else { lo }
    };
    Vec2::new(one(p.x, min.x, size.x), one(p.y, min.y, size.y))
}

/// One random body: dynamic (placed up to 5 world sizes out, moving up to 100 world sizes
/// a frame on each axis) or static (inside the world), a circle or a pentagon up to 0.45
/// of the world's smaller side across.
fn body_strategy() -> impl Strategy<Value = (bool, bool, f64, (f64, f64), (f64, f64), f64)> {
    (
        prop::bool::weighted(0.8),
        prop::bool::ANY,
        0.02..0.45f64,
        (-5.0..6.0f64, -5.0..6.0f64),
        (-100.0..100.0f64, -100.0..100.0f64),
        0.0..6.0f64,
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    #[test]
    fn contacts_at_any_speed_are_those_of_the_scene_wrapped_into_the_world(
        min in (-300.0..300.0f64, -300.0..300.0f64),
        size in (10.0..150.0f64, 10.0..150.0f64),
        specs in prop::collection::vec(body_strategy(), 2..9),
    ) {
        let (min, size) = (Vec2::new(min.0, min.1), Vec2::new(size.0, size.1));
        let hz = 60.0;
        let bodies: Vec<BodyDef> = specs
            .iter()
            .enumerate()
            .map(|(k, &(dynamic, round, r, at, v, angle))| {
                let r = r * size.min_element();
                let shape = if round {
                    Shape::circle(r).unwrap()
                } else {
                    let v = [(1.0, 0.1), (0.3, 0.95), (-0.8, 0.6), (-0.9, -0.5), (0.2, -1.0)];
                    Shape::polygon(&v.map(|(x, y)| Vec2::new(x * r, y * r))).unwrap()
                };
                let place = |f: (f64, f64)| min + Vec2::new(f.0, f.1) * size;
                let mut b = if dynamic {
                    let v = Vec2::new(v.0, v.1) * size * hz;
                    ricochet_scenes::moving_body(&format!("b{k}"), 0, shape, place(at), v)
                } else {
                    let inside = (at.0.rem_euclid(1.0), at.1.rem_euclid(1.0));
                    let mut b = ricochet_scenes::moving_body(&format!("b{k}"), 0, shape, place(inside), Vec2::ZERO);
                    b.kind = BodyKind::Static;
                    b
                };
                b.angle = angle;
                b
            })
            .collect();
        let frames = 6;
        let mut sim = Simulation::new(&scenario("crowd", world(min, size), bodies, frames));
        let tol = 1e-9;
        for _ in 0..=frames {
            let out = sim.step();
            let w = sim.world();
            // Every pair at its logged pose wrapped into the world, `b` at each of its nine
            // translations by whole world sizes next to `a`: the deepest.
            let pose = |i: usize| Pose::new(wrapped(w.position[i], min, size), w.angle[i]);
            let logged: Vec<(usize, usize, f64)> = out
                .contacts
                .iter()
                .map(|c| (w.index_of(c.a).unwrap(), w.index_of(c.b).unwrap(), c.depth))
                .collect();
            for i in 0..w.len() {
                for j in i + 1..w.len() {
                    if w.kind[i] != BodyKind::Dynamic && w.kind[j] != BodyKind::Dynamic {
                        continue;
                    }
                    let mut deepest = f64::NEG_INFINITY;
                    for sx in [-1.0, 0.0, 1.0] {
                        for sy in [-1.0, 0.0, 1.0] {
                            let pb = pose(j);
                            let image = Pose::new(pb.position + Vec2::new(sx, sy) * size, pb.angle);
                            deepest = deepest.max(contact(w.shape(i), &pose(i), w.shape(j), &image).depth);
                        }
                    }
                    let found = logged.iter().find(|c| (c.0, c.1) == (i, j));
                    let scale = 1.0 + size.max_element();
                    match found {
                        Some(c) => prop_assert!(
                            (c.2 - deepest).abs() <= tol * scale,
                            "frame {}: pair {i} {j} logged {} deep, wrapped {deepest}", out.frame, c.2
                        ),
                        None => prop_assert!(
                            deepest <= tol * scale,
                            "frame {}: pair {i} {j} not logged, wrapped {deepest} deep", out.frame
                        ),
                    }
                }
            }
        }
    }
}

#[test]
fn a_bullet_two_and_a_half_world_widths_a_frame_hits_the_first_rock_on_its_path() {
    // 250 units a frame from x = 5: the bullet (radius 0.2) meets the rock (radius 1) at
    // x = 60 when its centre reaches 58.8, at t = (58.8 - 5) / 250 of frame 1, on its
    // first lap; its path passes the rock twice more.
    let mut l = layers(
        &["bullet", "rock"],
        &[(0, 1, Response::Destroy(ricochet_sim::Doomed::Both))],
    );
    l.set_fast(0);
    let w = WorldDef {
        layers: l,
        ..world(Vec2::ZERO, Vec2::splat(100.0))
    };
    let bodies = vec![
        ricochet_scenes::moving_body(
            "bullet",
            0,
            Shape::circle(0.2).unwrap(),
            Vec2::new(5.0, 50.0),
            Vec2::new(15000.0, 0.0),
        ),
        ricochet_scenes::moving_body(
            "rock",
            1,
            Shape::circle(1.0).unwrap(),
            Vec2::new(60.0, 50.0),
            Vec2::ZERO,
        ),
    ];
    let mut sim = Simulation::new(&scenario("bullet", w, bodies, 2));
    assert!(sim.step().contacts.is_empty());
    let out = sim.step();
    assert_eq!(out.contacts.len(), 1, "{:?}", out.contacts);
    let c = &out.contacts[0];
    let end = out
        .removed
        .iter()
        .find(|r| r.name == "bullet")
        .unwrap()
        .pose;
    // Where the bullet was at the touch, as a fraction of its 250-unit motion.
    let start = end.position.x - 250.0;
    let t = (c.pose_a.position.x - start) / 250.0;
    assert!((t - (58.8 - 5.0) / 250.0).abs() < 1e-9, "t = {t}, {c:?}");
    assert!((c.pose_b.position.x - c.pose_a.position.x - 1.2).abs() < 1e-9);
    assert_eq!(out.removed.len(), 2);
}

/// The earliest touch of `a` moving `da` from `pa` and `b` moving `db` from `pb` (both
/// inside the world), over every translation of `b` by whole world sizes whose centre
/// passes within the two bounding radii of `a`'s along the relative path.
fn earliest_touch(
    (a, ra, pa, da): (&Shape, f64, Vec2, Vec2),
    (b, rb, pb, db): (&Shape, f64, Vec2, Vec2),
    angles: (f64, f64),
    size: Vec2,
) -> Option<f64> {
    let d = db - da;
    let reach = ra + rb + 1e-6 * size.max_element();
    // Relative centre of the image at `o`: `pb + o - pa + t d`, t in [0, 1].
    let span = |axis: usize| {
        let (lo, hi) = (
            (pa[axis] - pb[axis] - d[axis].max(0.0) - reach) / size[axis],
            (pa[axis] - pb[axis] - d[axis].min(0.0) + reach) / size[axis],
        );
        (lo.floor() as i64, hi.ceil() as i64)
    };
    let (xs, ys) = (span(0), span(1));
    let mut best: Option<f64> = None;
    for kx in xs.0..=xs.1 {
        for ky in ys.0..=ys.1 {
            let o = Vec2::new(kx as f64 * size.x, ky as f64 * size.y);
            let c = pb + o - pa;
            let t = if d == Vec2::ZERO {
                0.0
            } else {
                (-c.dot(d) / d.dot(d)).clamp(0.0, 1.0)
            };
            if (c + d * t).length() > reach {
                continue;
            }
            let sweep = |p: Vec2, m: Vec2, angle: f64| ricochet_geom::Sweep {
                start: p,
                end: p + m,
                angle,
            };
            let hit = ricochet_geom::time_of_impact(
                a,
                &sweep(pa, da, angles.0),
                b,
                &sweep(pb + o, db, angles.1),
            );
            if let Some(h) = hit
                && best.is_none_or(|t| h.t < t)
            {
                best = Some(h.t);
            }
        }
    }
    best
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn swept_hits_at_any_speed_are_those_of_the_scene_wrapped_into_the_world(
        min in (-300.0..300.0f64, -300.0..300.0f64),
        size in (10.0..150.0f64, 10.0..150.0f64),
        bullets in prop::collection::vec(
            (0.005..0.05f64, (-5.0..6.0f64, -5.0..6.0f64), (-100.0..100.0f64, -100.0..100.0f64)),
            1..4,
        ),
        rocks in prop::collection::vec(
            (0.02..0.3f64, (0.0..1.0f64, 0.0..1.0f64), (-0.5..0.5f64, -0.5..0.5f64), prop::bool::ANY),
            1..4,
        ),
    ) {
        let (min, size) = (Vec2::new(min.0, min.1), Vec2::new(size.0, size.1));
        let hz = 60.0;
        let mut l = layers(&["bullet", "rock"], &[(0, 1, Response::Report)]);
        l.set_fast(0);
        let w = WorldDef { layers: l, ..world(min, size) };
        let place = |f: (f64, f64)| min + Vec2::new(f.0, f.1) * size;
        let speed = |v: (f64, f64)| Vec2::new(v.0, v.1) * size * hz;
        let mut bodies = Vec::new();
        // Bullets first: each swept pair's `a` is the bullet, the body that moves.
        for (k, &(r, at, v)) in bullets.iter().enumerate() {
            let r = r * size.min_element();
            let v = speed(v).max(Vec2::splat(1e-3));
            bodies.push(ricochet_scenes::moving_body(&format!("bullet{k}"), 0, Shape::circle(r).unwrap(), place(at), v));
        }
        for (k, &(r, at, v, round)) in rocks.iter().enumerate() {
            let r = r * size.min_element();
            let shape = if round {
                Shape::circle(r).unwrap()
            } else {
                let v = [(1.0, 0.1), (0.3, 0.95), (-0.8, 0.6), (-0.9, -0.5), (0.2, -1.0)];
                Shape::polygon(&v.map(|(x, y)| Vec2::new(x * r, y * r))).unwrap()
            };
            bodies.push(ricochet_scenes::moving_body(&format!("rock{k}"), 1, shape, place(at), speed(v)));
        }
        let frames = 4;
        let mut sim = Simulation::new(&scenario("bullets", w, bodies, frames));
        let dt = sim.dt();
        sim.step();
        for _ in 1..=frames {
            let out = sim.step();
            let w = sim.world();
            let radius = |k: usize| {
                let b = w.shape(k).bounds(&Pose::new(Vec2::ZERO, w.angle[k]));
                b.min.abs().max(b.max.abs()).length()
            };
            for i in 0..bullets.len() {
                for j in bullets.len()..w.len() {
                    let (ma, mb) = (w.velocity(i) * dt, w.velocity(j) * dt);
                    let start = |k: usize| wrapped(w.start_position(k), min, size);
                    let expected = earliest_touch(
                        (w.shape(i), radius(i), start(i), ma),
                        (w.shape(j), radius(j), start(j), mb),
                        (w.angle[i], w.angle[j]),
                        size,
                    );
                    let logged = out.contacts.iter().find(|c| {
                        (w.index_of(c.a), w.index_of(c.b)) == (Some(i), Some(j))
                    });
                    // The logged touch's moment along the bullet's own motion.
                    let t = logged.map(|c| {
                        (c.pose_a.position - w.start_position(i)).dot(ma) / ma.dot(ma)
                    });
                    match (t, expected) {
                        (Some(t), Some(e)) => prop_assert!(
                            (t - e).abs() <= 1e-6,
                            "frame {}: pair {i} {j} touched at t = {t}, wrapped at {e}", out.frame
                        ),
                        (t, e) => prop_assert!(
                            t.is_none() && e.is_none(),
                            "frame {}: pair {i} {j} logged at {t:?}, wrapped at {e:?}", out.frame
                        ),
                    }
                }
            }
        }
    }
}
