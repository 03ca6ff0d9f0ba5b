//! The query referee (issue #22): Ricochet's scene queries against rapier's `QueryPipeline`
//! on random seeded scenes of every shape kind (static and moving, at the origin and at
//! 1e6), and a wrap world against the union of its nine images in a non-wrapping copy.
//!
//! Every difference is either within [`QueryTolerance`] or counted under a named rule whose
//! condition is checked with parry's exact pair query; anything else fails the test.
//! `docs/validation.md` ("Scene queries") states the rules and why each is legitimate.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use ricochet_geom::{Bounds, Pose, Primitive, Shape, Vec2};
use ricochet_oracle::{QueryReferee, QueryTolerance, ReferenceRayHit};
use ricochet_scenes::Rng;
use ricochet_sim::{
    BodyDef, BodyKind, Entity, LayerId, Layers, QueryFilter, RayHit, Simulation, WorldBounds,
    WorldDef,
};

/// Rule: one engine reports a ray hit the other does not, and the ray (as the segment it
/// sweeps) only touches the body: parry's depth of the segment is within the band of 0
/// (tangent to a curve, along a face, through a vertex, or ending on the boundary).
const GRAZING: &str = "grazing";
/// Rule: the first hits name different bodies at the same distance (within the band).
const TIE: &str = "tie";
/// Rule: one engine has the point inside a body, the other not, and the point is within the
/// band of the body's boundary (Ricochet: strictly inside; parry: boundary included).
const BOUNDARY: &str = "boundary";
/// Rule: one engine has a box or shape overlapping a body, the other not, and parry's exact
/// depth of the pair is within the band of 0 (Ricochet: `depth > 0`; parry: touching
/// counts).
const TOUCHING: &str = "touching";
/// Rule: a ray starting inside a body: both engines hit it at distance 0, and parry's
/// normal there depends on the shape (a ball's points from the origin to its centre, a
/// cuboid's is zero, a support-map shape's is GJK's last direction), where Ricochet's is
/// always zero. Only the distance is compared; parry's projection must put the origin inside.
const INSIDE_NORMAL: &str = "inside-normal";
/// Rule: one engine's cast touches a body the other's does not, and the deepest the swept
/// shape gets into it along the whole path is within the band of 0 (a grazing cast).
const GRAZING_CAST: &str = "grazing-cast";

/// Counts per query kind and per rule, and every unexplained difference word for word.
#[derive(Default)]
struct Tally {
    asked: BTreeMap<&'static str, usize>,
    rules: BTreeMap<&'static str, usize>,
    unexplained: Vec<String>,
    /// Worst ray distance difference, world units.
    worst_ray: f64,
    /// Worst cast difference along the path, world units.
    worst_cast: f64,
    worst_normal: f64,
}

impl Tally {
    fn ask(&mut self, kind: &'static str) {
        *self.asked.entry(kind).or_default() += 1;
    }

    fn rule(&mut self, name: &'static str) {
        *self.rules.entry(name).or_default() += 1;
    }

    fn fail(&mut self, what: String) {
        self.unexplained.push(what);
    }

    fn add(&mut self, o: Tally) {
        for (k, v) in o.asked {
            *self.asked.entry(k).or_default() += v;
        }
        for (k, v) in o.rules {
            *self.rules.entry(k).or_default() += v;
        }
        self.unexplained.extend(o.unexplained);
        self.worst_ray = self.worst_ray.max(o.worst_ray);
        self.worst_cast = self.worst_cast.max(o.worst_cast);
        self.worst_normal = self.worst_normal.max(o.worst_normal);
    }

    #[track_caller]
    fn assert_clean(&self, name: &str) {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "{name}: asked {:?}, rules {:?}, worst ray distance {:e}, worst cast {:e}, worst \
             normal {:e} rad",
            self.asked, self.rules, self.worst_ray, self.worst_cast, self.worst_normal
        );
        for u in self.unexplained.iter().take(20) {
            let _ = writeln!(s, "  {u}");
        }
        println!("{s}");
        assert!(
            self.unexplained.is_empty(),
            "{} unexplained differences\n{s}",
            self.unexplained.len()
        );
    }
}

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

/// Half the diagonal of the shape's local bounds (the validation's size of a shape).
fn size(s: &Shape) -> f64 {
    s.bounds(&Pose::default()).half_extents().length()
}

fn angle_between(a: Vec2, b: Vec2) -> f64 {
    libm::atan2(a.perp_dot(b).abs(), a.dot(b))
}

/// The band for body `e` at this scene's magnitude.
fn band(r: &QueryReferee, tol: &QueryTolerance, e: Entity) -> f64 {
    r.body(e).map_or(tol.absolute, |(s, _)| tol.band(s))
}

/// One ray: the first hit and every hit, compared.
#[allow(
    clippy::too_many_arguments,
    reason = "one ray's inputs and the scene's context"
)]
fn compare_ray(
    t: &mut Tally,
    sim: &Simulation,
    r: &QueryReferee,
    tol: &QueryTolerance,
    (o, d, max): (Vec2, Vec2, f64),
    f: &QueryFilter,
) {
    t.ask("cast_ray_all");
    let ours = sim.cast_ray_all(o, d, max, f);
    let theirs = r.cast_ray_all(o, d, max, f);
    let end = o + d * max;
    // Bodies only one engine hits: each must be a graze.
    let only_ours = ours.iter().map(|h| h.entity);
    let only_theirs = theirs.iter().map(|h| h.entity);
    for (e, who) in only_ours
        .filter(|e| !theirs.iter().any(|h| h.entity == *e))
        .map(|e| (e, "ricochet"))
        .chain(
            only_theirs
                .filter(|e| !ours.iter().any(|h| h.entity == *e))
                .map(|e| (e, "rapier")),
        )
    {
        let depth = r.segment_depth(o, end, e).unwrap();
        if depth.abs() <= band(r, tol, e) {
            t.rule(GRAZING);
        } else {
            t.fail(format!(
                "ray {o:?} along {d:?} max {max}: only {who} hits {e:?} (segment depth {depth:e})"
            ));
        }
    }
    // Bodies both hit: the same distance and normal.
    for h in &ours {
        if let Some(p) = theirs.iter().find(|p| p.entity == h.entity) {
            compare_hit(t, r, tol, (o, d, max), h, p);
        }
    }
    // The first hit.
    t.ask("cast_ray");
    let first = sim.cast_ray(o, d, max, f);
    let rfirst = r.cast_ray(o, d, max, f);
    match (first, rfirst) {
        (None, None) => {}
        (Some(a), Some(b)) if a.entity == b.entity => compare_hit(t, r, tol, (o, d, max), &a, &b),
        (Some(a), Some(b)) if (a.distance - b.distance).abs() <= band(r, tol, a.entity) => {
            t.rule(TIE);
        }
        (a, b) => {
            // Explained when the earlier of the two first hits only grazes its body (or the
            // ray ends on its boundary): the other engine then reports what lies beyond.
            let early = match (a, b) {
                (Some(x), Some(y)) if y.distance < x.distance => y.entity,
                (Some(x), _) => x.entity,
                (None, Some(y)) => y.entity,
                (None, None) => unreachable!("matched above"),
            };
            let depth = r.segment_depth(o, end, early).unwrap();
            if depth.abs() <= band(r, tol, early) {
                t.rule(GRAZING);
            } else {
                t.fail(format!(
                    "ray {o:?} along {d:?} max {max}: first hit ricochet {a:?}, rapier {b:?}"
                ));
            }
        }
    }
}

/// One body hit by both engines: distances within the band, normals within the angle the
/// band allows (a zero normal only for a ray starting inside, in both).
fn compare_hit(
    t: &mut Tally,
    r: &QueryReferee,
    tol: &QueryTolerance,
    (o, d, max): (Vec2, Vec2, f64),
    ours: &RayHit,
    theirs: &ReferenceRayHit,
) {
    let b = band(r, tol, ours.entity);
    let dd = (ours.distance - theirs.distance).abs();
    let size = r
        .body(ours.entity)
        .map_or(1.0, |(s, _)| s.min_width().max(1e-3));
    t.worst_ray = t.worst_ray.max(dd);
    if dd > b {
        t.fail(format!(
            "ray {o:?} along {d:?} max {max}: {:?} at {} (ricochet) vs {} (rapier), band {b:e}",
            ours.entity, ours.distance, theirs.distance
        ));
        return;
    }
    if ours.distance == 0.0 && theirs.distance == 0.0 {
        // Both start inside: Ricochet's normal is zero, parry's depends on the shape.
        let dist = r.point_distance(o, ours.entity).unwrap();
        let parry_zero = theirs.normal.length() < 1e-12;
        if ours.normal == Vec2::ZERO && !parry_zero && dist <= b {
            t.rule(INSIDE_NORMAL);
        } else if ours.normal != Vec2::ZERO || !parry_zero {
            t.fail(format!(
                "ray {o:?}: {:?} hit at 0 with normals {:?} (ricochet) and {:?} (rapier), \
                 the origin {dist:e} from the boundary",
                ours.entity, ours.normal, theirs.normal
            ));
        }
        return;
    }
    let a = angle_between(ours.normal, theirs.normal);
    t.worst_normal = t.worst_normal.max(a);
    if a > 1e-9 + 10.0 * b / size {
        t.fail(format!(
            "ray {o:?} along {d:?}: {:?} normal {:?} (ricochet) vs {:?} (rapier)",
            ours.entity, ours.normal, theirs.normal
        ));
    }
}

/// Two sets of bodies: each body in one set only must pass `explain` (the rule's check).
fn compare_sets(
    t: &mut Tally,
    what: &str,
    ours: &[Entity],
    theirs: &[Entity],
    rule: &'static str,
    mut explain: impl FnMut(Entity) -> (bool, f64),
) {
    for (e, who) in ours
        .iter()
        .filter(|e| !theirs.contains(e))
        .map(|e| (*e, "ricochet"))
        .chain(
            theirs
                .iter()
                .filter(|e| !ours.contains(e))
                .map(|e| (*e, "rapier")),
        )
    {
        let (ok, measure) = explain(e);
        if ok {
            t.rule(rule);
        } else {
            t.fail(format!("{what}: only {who} has {e:?} ({measure:e})"));
        }
    }
}

/// The deepest `shape` gets into body `e` on its path from `pose` along `translation`:
/// parry's depth sampled at 65 points, then refined by a ternary search around the best.
fn deepest_on_path(r: &QueryReferee, shape: &Shape, pose: Pose, tr: Vec2, e: Entity) -> f64 {
    let at = |s: f64| {
        r.depth(shape, Pose::new(pose.position + tr * s, pose.angle), e)
            .unwrap()
    };
    let n = 64;
    let (mut best, mut best_s) = (f64::NEG_INFINITY, 0.0);
    for j in 0..=n {
        let s = f64::from(j) / f64::from(n);
        let d = at(s);
        if d > best {
            (best, best_s) = (d, s);
        }
    }
    let (mut lo, mut hi) = (
        (best_s - 1.0 / 64.0).max(0.0),
        (best_s + 1.0 / 64.0).min(1.0),
    );
    for _ in 0..60 {
        let (m1, m2) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
        if at(m1) < at(m2) {
            lo = m1;
        } else {
            hi = m2;
        }
    }
    best.max(at((lo + hi) * 0.5))
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

/// One shape cast: the same body at the same fraction (within the band over the path's
/// length, plus Ricochet's stopping gap), or a tie, or a grazing cast.
fn compare_cast(
    t: &mut Tally,
    sim: &Simulation,
    r: &QueryReferee,
    tol: &QueryTolerance,
    (qs, pose, tr): (&Shape, Pose, Vec2),
    f: &QueryFilter,
) {
    let ours = sim
        .cast_shape(qs, pose, tr, f)
        .map(|h| (h.entity, h.fraction));
    let theirs = r.cast_shape(qs, pose, tr, f).unwrap();
    let len = tr.length();
    // The validation tolerances of a swept contact (`Tolerances`): within `toi` (1e-8 of
    // the pair's smaller size) of parry's fraction along the path, or else Ricochet's pose
    // touches by parry's exact depth (at most its stopping gap `toi_gap`, 2e-9 of the
    // pair's size, short of it, and not overlapping) while neither parry's pose nor any
    // point between the two overlaps (so it is the same first touch, not a later one:
    // parry's own cast stops short of the touch by its own margin). The band covers the
    // rounding of world coordinates.
    let agrees = |e: Entity, fa: f64, fb: f64| {
        let pair = r.body(e).map_or(1.0, |(s, _)| size(s)).min(size(qs));
        let b = band(r, tol, e);
        if (fa - fb).abs() * len <= 1e-8 * pair + b {
            return true;
        }
        let depth = |f: f64| {
            r.depth(qs, Pose::new(pose.position + tr * f, pose.angle), e)
                .unwrap()
        };
        let ours = depth(fa);
        ours >= -(2e-9 * pair + b) && ours <= b && depth(fb) <= b && depth((fa + fb) * 0.5) <= b
    };
    let what = || format!("cast {qs:?} from {pose:?} by {tr:?}");
    match (ours, theirs) {
        (None, None) => {}
        (Some((a, fa)), Some((b, fb))) if a == b => {
            t.worst_cast = t.worst_cast.max((fa - fb).abs() * len);
            if !agrees(a, fa, fb) {
                let at = |f: f64| Pose::new(pose.position + tr * f, pose.angle);
                t.fail(format!(
                    "{}: {a:?} at {fa} (ricochet) vs {fb} (rapier); parry's depth there {:e} \
                     and {:e}",
                    what(),
                    r.depth(qs, at(fa), a).unwrap(),
                    r.depth(qs, at(fb), a).unwrap()
                ));
            }
        }
        (Some((a, fa)), Some((b, fb))) if agrees(a, fa, fb) && agrees(b, fb, fa) => t.rule(TIE),
        (a, b) => {
            // The earlier answer's body must be one the later engine never touches: a graze.
            let early = match (a, b) {
                (Some(x), Some(y)) => {
                    if x.1 < y.1 {
                        x
                    } else {
                        y
                    }
                }
                (Some(x), None) | (None, Some(x)) => x,
                (None, None) => unreachable!("matched above"),
            };
            let deepest = deepest_on_path(r, qs, pose, tr, early.0);
            if deepest.abs() <= band(r, tol, early.0) {
                t.rule(GRAZING_CAST);
            } else {
                t.fail(format!(
                    "{}: ricochet {a:?}, rapier {b:?} (deepest into {:?}: {deepest:e})",
                    what(),
                    early.0
                ));
            }
        }
    }
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
