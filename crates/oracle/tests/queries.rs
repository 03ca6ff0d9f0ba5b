//! The query referee (issue #22): Ricochet's scene queries against rapier's `QueryPipeline`
//! on random seeded scenes of every shape kind (static and moving, at the origin and at
//! 1e6), and a wrap world against the union of its nine images in a non-wrapping copy.
//!
//! Every difference is either within [`QueryTolerance`] or counted under a named rule whose
//! condition is checked with parry's exact pair query; anything else fails the test.
//! `docs/validation.md` ("Scene queries") states the rules and why each is legitimate.

use std::collections::BTreeMap;

use ricochet_geom::{Bounds, Pose, Primitive, Shape, Vec2};
use ricochet_oracle::{QueryReferee, QueryTolerance};
use ricochet_scenes::Rng;
use ricochet_sim::{
    BodyDef, BodyKind, Entity, LayerId, Layers, QueryFilter, Simulation, WorldBounds, WorldDef,
};

#[path = "queries/compare.rs"]
mod compare;

use compare::*;

fn v(x: f64, y: f64) -> Vec2 {
    Vec2::new(x, y)
}

/// A random shape of kind `k` (0 circle, 1 aabb, 2 obb, 3 capsule, 4 polygon, 5 compound),
/// about `s` across, with offsets and own angles.
fn shape(rng: &mut Rng, k: usize, s: f64) -> Shape {
    let off = |rng: &mut Rng| v(rng.range(-0.3, 0.3) * s, rng.range(-0.3, 0.3) * s);
    let half = |rng: &mut Rng| v(rng.range(0.2, 1.0) * s, rng.range(0.2, 1.0) * s);
    let prim = |rng: &mut Rng, k: usize| -> Primitive {
        match k {
            0 => Primitive::circle(off(rng), rng.range(0.2, 1.0) * s).unwrap(),
            1 => Primitive::aabb(off(rng), half(rng)).unwrap(),
            2 => Primitive::obb(off(rng), half(rng), rng.range(-3.0, 3.0)).unwrap(),
            3 => {
                let a = v(rng.range(-1.0, 0.0) * s, rng.range(-0.5, 0.5) * s);
                let b = v(rng.range(0.2, 1.0) * s, rng.range(-0.5, 0.5) * s);
                Primitive::capsule(a, b, rng.range(0.1, 0.6) * s).unwrap()
            }
            _ => {
                // A convex polygon: 3 to 8 vertices on an ellipse, in angle order.
                let n = 3 + rng.below(6);
                let (rx, ry) = (rng.range(0.3, 1.0) * s, rng.range(0.3, 1.0) * s);
                let turn = rng.range(0.0, 6.0);
                let vs: Vec<Vec2> = (0..n)
                    .map(|j| {
                        let a = turn + std::f64::consts::TAU * (j as f64) / (n as f64);
                        v(rx * libm::cos(a), ry * libm::sin(a))
                    })
                    .collect();
                Primitive::polygon(&vs).unwrap()
            }
        }
    };
    if k < 5 {
        return Shape::Primitive(prim(rng, k));
    }
    let n = 2 + rng.below(3);
    let parts = (0..n)
        .map(|_| {
            let k = rng.below(5);
            prim(rng, k)
        })
        .collect();
    Shape::compound(parts).unwrap()
}

fn layers() -> Layers {
    Layers::new(vec!["a".into(), "b".into()])
}

/// A random scene of `n` bodies (every kind, static, kinematic and dynamic) around
/// `center`, stepped 3 frames so the moving ones have moved (layers ignore each other:
/// nothing collides).
fn scene(rng: &mut Rng, center: Vec2, n: usize) -> Simulation {
    let mut sim = Simulation::from_def(WorldDef {
        layers: layers(),
        gravity: Vec2::ZERO,
        ..WorldDef::default()
    })
    .unwrap();
    for j in 0..n {
        let kind = [BodyKind::Static, BodyKind::Kinematic, BodyKind::Dynamic][rng.below(3)];
        let s = rng.range(0.4, 2.0);
        let body = BodyDef {
            layer: LayerId::try_from(rng.below(2)).unwrap(),
            kind,
            shape: shape(rng, j % 6, s),
            position: center + v(rng.range(-15.0, 15.0), rng.range(-15.0, 15.0)),
            angle: rng.range(-3.2, 3.2),
            velocity: if kind == BodyKind::Static {
                Vec2::ZERO
            } else {
                v(rng.range(-5.0, 5.0), rng.range(-5.0, 5.0))
            },
            angular_velocity: if kind == BodyKind::Static {
                0.0
            } else {
                rng.range(-2.0, 2.0)
            },
            ..BodyDef::default()
        };
        sim.spawn(&body);
    }
    for _ in 0..3 {
        drop(sim.step());
    }
    sim
}

/// A random filter: every body half the time, one layer, or every body but one.
fn filter(rng: &mut Rng, sim: &Simulation) -> QueryFilter {
    match rng.below(4) {
        0 => QueryFilter::layers(&[LayerId::try_from(rng.below(2)).unwrap()]),
        1 => {
            let w = sim.world();
            QueryFilter::all().exclude(w.entity[rng.below(w.len())])
        }
        _ => QueryFilter::all(),
    }
}

/// Every query kind, `queries` times each, on one scene.
fn referee_scene(sim: &Simulation, rng: &mut Rng, center: Vec2, queries: usize) -> Tally {
    let r = QueryReferee::new(sim).unwrap();
    let tol = QueryTolerance::at(center.length() + 60.0);
    let mut t = Tally::default();
    let point = |rng: &mut Rng| center + v(rng.range(-20.0, 20.0), rng.range(-20.0, 20.0));
    for _ in 0..queries {
        // Rays: some start inside bodies (solid), lengths from short to across the scene.
        let f = filter(rng, sim);
        let o = point(rng);
        let a = rng.range(0.0, std::f64::consts::TAU);
        let d = v(libm::cos(a), libm::sin(a));
        let max = rng.range(0.5, 45.0);
        compare_ray(&mut t, sim, &r, &tol, (o, d, max), &f);

        t.ask("overlap_point");
        let p = point(rng);
        let ours = sim.overlap_point(p, &f);
        let theirs = r.overlap_point(p, &f);
        compare_sets(
            &mut t,
            &format!("point {p:?}"),
            &ours,
            &theirs,
            BOUNDARY,
            |e| {
                let dist = r.point_distance(p, e).unwrap();
                (dist.abs() <= band(&r, &tol, e), dist)
            },
        );

        t.ask("overlap_aabb");
        let c = point(rng);
        let h = v(rng.range(0.05, 4.0), rng.range(0.05, 4.0));
        let b = Bounds::around(c, h);
        let ours = sim.overlap_aabb(b, &f);
        let theirs = r.overlap_aabb(b, &f);
        let boxed = Shape::aabb(h).unwrap();
        compare_sets(
            &mut t,
            &format!("box {b:?}"),
            &ours,
            &theirs,
            TOUCHING,
            |e| {
                let depth = r.depth(&boxed, Pose::new(c, 0.0), e).unwrap();
                (depth.abs() <= band(&r, &tol, e), depth)
            },
        );

        t.ask("overlap_shape");
        let k = rng.below(6);
        let size = rng.range(0.3, 3.0);
        let qs = shape(rng, k, size);
        let pose = Pose::new(point(rng), rng.range(-3.2, 3.2));
        let ours = sim.overlap_shape(&qs, pose, &f);
        let theirs = r.overlap_shape(&qs, pose, &f).unwrap();
        compare_sets(
            &mut t,
            &format!("shape {qs:?} at {pose:?}"),
            &ours,
            &theirs,
            TOUCHING,
            |e| {
                let depth = r.depth(&qs, pose, e).unwrap();
                (depth.abs() <= band(&r, &tol, e), depth)
            },
        );

        t.ask("cast_shape");
        let tr = v(rng.range(-25.0, 25.0), rng.range(-25.0, 25.0));
        compare_cast(&mut t, sim, &r, &tol, (&qs, pose, tr), &f);
    }
    t
}

/// Random scenes of every shape kind, static and moving, at the origin and at 1e6: every
/// answer agrees with rapier's `QueryPipeline` or is explained by a named rule.
#[test]
fn scene_queries_agree_with_rapier_at_the_origin_and_at_1e6() {
    let mut all = Tally::default();
    for center in [Vec2::ZERO, v(1e6, -1e6)] {
        let mut t = Tally::default();
        for seed in 0..4u64 {
            let mut rng = Rng::new(0x2200 + seed);
            let sim = scene(&mut rng, center, 36);
            t.add(referee_scene(&sim, &mut rng, center, 400));
        }
        t.assert_clean(&format!("centre {center:?}"));
        assert!(t.asked.values().all(|n| *n >= 1600), "{:?}", t.asked);
        all.add(t);
    }
    all.assert_clean("all");
}

/// A query in a wrap world equals the same query in a non-wrapping copy holding every
/// body at its nine images (the world's size times -1, 0, 1 per axis), the copy's answers
/// named by the original body: rays (first hit and every hit, each body once at its
/// first image), points, boxes, shapes and casts, the paths short enough (at most half the
/// world's smaller side) that the nine images hold every body they can meet.
#[test]
fn a_wrap_world_answers_as_its_nine_images() {
    let size = v(100.0, 60.0);
    let mut rng = Rng::new(0x22_3a9);
    let mut wrap = Simulation::from_def(WorldDef {
        layers: layers(),
        gravity: Vec2::ZERO,
        bounds: Some(WorldBounds {
            min: Vec2::ZERO,
            max: size,
            wrap: true,
        }),
        ..WorldDef::default()
    })
    .unwrap();
    for j in 0..48 {
        let kind = [BodyKind::Static, BodyKind::Kinematic][rng.below(2)];
        // Half the bodies on or near an edge, so that their images straddle the seam.
        let near = |rng: &mut Rng, side: f64| {
            if rng.below(2) == 0 {
                rng.range(0.0, side)
            } else {
                [rng.range(0.0, 2.0), rng.range(side - 2.0, side)][rng.below(2)]
            }
        };
        let s = rng.range(0.5, 3.0);
        wrap.spawn(&BodyDef {
            layer: LayerId::try_from(rng.below(2)).unwrap(),
            kind,
            shape: shape(&mut rng, j % 6, s),
            position: v(near(&mut rng, size.x), near(&mut rng, size.y)),
            angle: rng.range(-3.2, 3.2),
            velocity: if kind == BodyKind::Static {
                Vec2::ZERO
            } else {
                v(rng.range(-5.0, 5.0), rng.range(-5.0, 5.0))
            },
            ..BodyDef::default()
        });
    }
    for _ in 0..2 {
        drop(wrap.step());
    }
    let mut copy = Simulation::from_def(WorldDef {
        layers: layers(),
        gravity: Vec2::ZERO,
        ..WorldDef::default()
    })
    .unwrap();
    let mut original: BTreeMap<Entity, Entity> = BTreeMap::new();
    let w = wrap.world();
    for i in 0..w.len() {
        for ox in [-1.0, 0.0, 1.0] {
            for oy in [-1.0, 0.0, 1.0] {
                let e = copy.spawn(&BodyDef {
                    layer: w.layer[i],
                    kind: BodyKind::Static,
                    shape: w.shape(i).clone(),
                    position: w.position[i] + v(ox * size.x, oy * size.y),
                    angle: w.angle[i],
                    ..BodyDef::default()
                });
                original.insert(e, w.entity[i]);
            }
        }
    }
    let named = |es: Vec<Entity>| {
        let mut out: Vec<Entity> = es.iter().map(|e| original[e]).collect();
        out.sort_unstable();
        out.dedup();
        out
    };
    let mut t = Tally::default();
    let eps = 1e-9;
    for _ in 0..400 {
        // Filters name the wrap world's entities: the copy's excluded images are all nine.
        let layer = match rng.below(3) {
            0 => Some(LayerId::try_from(rng.below(2)).unwrap()),
            _ => None,
        };
        let f = layer.map_or_else(QueryFilter::all, |l| QueryFilter::layers(&[l]));
        let o = v(rng.range(0.0, size.x), rng.range(0.0, size.y));
        let a = rng.range(0.0, std::f64::consts::TAU);
        let d = v(libm::cos(a), libm::sin(a));
        let max = rng.range(0.5, 30.0);

        t.ask("cast_ray");
        let ours = wrap.cast_ray(o, d, max, &f);
        let theirs = copy.cast_ray(o, d, max, &f);
        match (ours, theirs) {
            (None, None) => {}
            (Some(a), Some(b)) if a.entity == original[&b.entity] => {
                t.worst_ray = t.worst_ray.max((a.distance - b.distance).abs());
                if (a.distance - b.distance).abs() > eps || (a.normal - b.normal).length() > eps {
                    t.fail(format!("wrap ray {o:?} along {d:?}: {a:?} vs images {b:?}"));
                }
            }
            (Some(a), Some(b)) if (a.distance - b.distance).abs() <= eps => t.rule(TIE),
            (a, b) => t.fail(format!("wrap ray {o:?} along {d:?}: {a:?} vs images {b:?}")),
        }

        t.ask("cast_ray_all");
        let ours: Vec<(Entity, f64)> = wrap
            .cast_ray_all(o, d, max, &f)
            .iter()
            .map(|h| (h.entity, h.distance))
            .collect();
        let mut theirs: Vec<(Entity, f64)> = Vec::new();
        for h in copy.cast_ray_all(o, d, max, &f) {
            // Each body once, at its first image along the ray (the list is by distance).
            if !theirs.iter().any(|(e, _)| *e == original[&h.entity]) {
                theirs.push((original[&h.entity], h.distance));
            }
        }
        let mut sorted = theirs.clone();
        sorted.sort_by_key(|a| a.0);
        let mut mine = ours.clone();
        mine.sort_by_key(|a| a.0);
        let same = mine.len() == sorted.len()
            && mine
                .iter()
                .zip(&sorted)
                .all(|(a, b)| a.0 == b.0 && (a.1 - b.1).abs() <= eps);
        if !same {
            t.fail(format!(
                "wrap ray {o:?} along {d:?} all: {ours:?} vs images {theirs:?}"
            ));
        }

        t.ask("overlap_point");
        let p = v(rng.range(0.0, size.x), rng.range(0.0, size.y));
        let (ours, theirs) = (wrap.overlap_point(p, &f), named(copy.overlap_point(p, &f)));
        if ours != theirs {
            t.fail(format!("wrap point {p:?}: {ours:?} vs images {theirs:?}"));
        }

        t.ask("overlap_aabb");
        let c = v(rng.range(0.0, size.x), rng.range(0.0, size.y));
        let b = Bounds::around(c, v(rng.range(0.1, 8.0), rng.range(0.1, 8.0)));
        let (ours, theirs) = (wrap.overlap_aabb(b, &f), named(copy.overlap_aabb(b, &f)));
        if ours != theirs {
            t.fail(format!("wrap box {b:?}: {ours:?} vs images {theirs:?}"));
        }

        t.ask("overlap_shape");
        let k = rng.below(6);
        let s = rng.range(0.5, 4.0);
        let qs = shape(&mut rng, k, s);
        let pose = Pose::new(
            v(rng.range(0.0, size.x), rng.range(0.0, size.y)),
            rng.range(-3.2, 3.2),
        );
        let (ours, theirs) = (
            wrap.overlap_shape(&qs, pose, &f),
            named(copy.overlap_shape(&qs, pose, &f)),
        );
        if ours != theirs {
            t.fail(format!(
                "wrap shape at {pose:?}: {ours:?} vs images {theirs:?}"
            ));
        }

        t.ask("cast_shape");
        let tr = d * max;
        let ours = wrap.cast_shape(&qs, pose, tr, &f);
        let theirs = copy.cast_shape(&qs, pose, tr, &f);
        match (ours, theirs) {
            (None, None) => {}
            (Some(a), Some(b)) if a.entity == original[&b.entity] => {
                if (a.fraction - b.fraction).abs() * max > eps {
                    t.fail(format!(
                        "wrap cast at {pose:?} by {tr:?}: {a:?} vs images {b:?}"
                    ));
                }
            }
            (Some(a), Some(b)) if (a.fraction - b.fraction).abs() * max <= eps => t.rule(TIE),
            (a, b) => t.fail(format!(
                "wrap cast at {pose:?} by {tr:?}: {a:?} vs images {b:?}"
            )),
        }
    }
    t.assert_clean("wrap world against its nine images");
}

/// Queries placed on purpose where the conventions differ (a point on a face, a box and a
/// shape touching a face, rays along a face, tangent to a disc or ending on a face, a cast
/// sliding along a face), at the origin and at 1e6: the rules explain every difference,
/// and the `boundary` and `touching` rules are met (Ricochet does not count touching, parry
/// does).
#[test]
fn touching_and_grazing_queries_follow_the_rules() {
    let mut t = Tally::default();
    for center in [Vec2::ZERO, v(1e6, -1e6)] {
        let mut sim = Simulation::from_def(WorldDef {
            layers: layers(),
            gravity: Vec2::ZERO,
            ..WorldDef::default()
        })
        .unwrap();
        let place = |x: f64, y: f64| center + v(x, y);
        for (shape, at) in [
            (Shape::aabb(v(1.0, 0.5)).unwrap(), place(3.0, 4.0)),
            (Shape::circle(1.5).unwrap(), place(-5.0, 2.0)),
        ] {
            sim.spawn(&BodyDef {
                shape,
                position: at,
                kind: BodyKind::Static,
                ..BodyDef::default()
            });
        }
        let r = QueryReferee::new(&sim).unwrap();
        let tol = QueryTolerance::at(center.length() + 10.0);
        let all = QueryFilter::all();
        // The box's faces: x = 2 and 4, y = 3.5 and 4.5; the disc's rightmost point (-3.5, 2).
        for (o, d, max) in [
            (place(0.0, 4.5), Vec2::X, 10.0),
            (place(0.0, 3.5), Vec2::X, 10.0),
            (place(-3.5, -3.0), Vec2::Y, 10.0),
            (place(0.0, 4.0), Vec2::X, 2.0),
            (place(4.0, 0.0), Vec2::Y, 10.0),
        ] {
            compare_ray(&mut t, &sim, &r, &tol, (o, d, max), &all);
        }
        for p in [
            place(4.0, 4.2),
            place(3.0, 4.5),
            place(-3.5, 2.0),
            place(4.0, 4.5),
        ] {
            t.ask("overlap_point");
            let (ours, theirs) = (sim.overlap_point(p, &all), r.overlap_point(p, &all));
            compare_sets(
                &mut t,
                &format!("point {p:?}"),
                &ours,
                &theirs,
                BOUNDARY,
                |e| {
                    let dist = r.point_distance(p, e).unwrap();
                    (dist.abs() <= band(&r, &tol, e), dist)
                },
            );
        }
        for b in [
            Bounds {
                min: place(4.0, 3.8),
                max: place(5.0, 4.2),
            },
            Bounds {
                min: place(2.5, 4.5),
                max: place(3.5, 6.0),
            },
        ] {
            t.ask("overlap_aabb");
            let (ours, theirs) = (sim.overlap_aabb(b, &all), r.overlap_aabb(b, &all));
            let boxed = Shape::aabb(b.half_extents()).unwrap();
            compare_sets(
                &mut t,
                &format!("box {b:?}"),
                &ours,
                &theirs,
                TOUCHING,
                |e| {
                    let depth = r.depth(&boxed, Pose::new(b.center(), 0.0), e).unwrap();
                    (depth.abs() <= band(&r, &tol, e), depth)
                },
            );
        }
        // A disc of 0.5 resting on the box's top face, then slid along it.
        let disc = Shape::circle(0.5).unwrap();
        let pose = Pose::new(place(3.0, 5.0), 0.0);
        t.ask("overlap_shape");
        let (ours, theirs) = (
            sim.overlap_shape(&disc, pose, &all),
            r.overlap_shape(&disc, pose, &all).unwrap(),
        );
        compare_sets(&mut t, "disc on the box", &ours, &theirs, TOUCHING, |e| {
            let depth = r.depth(&disc, pose, e).unwrap();
            (depth.abs() <= band(&r, &tol, e), depth)
        });
        t.ask("cast_shape");
        compare_cast(
            &mut t,
            &sim,
            &r,
            &tol,
            (&disc, Pose::new(place(0.0, 5.0), 0.0), v(6.0, 0.0)),
            &all,
        );
    }
    t.assert_clean("touching and grazing");
    assert!(
        t.rules.get(BOUNDARY).is_some_and(|n| *n > 0)
            && t.rules.get(TOUCHING).is_some_and(|n| *n > 0),
        "{:?}",
        t.rules
    );
}
