//! The query referee's comparisons (`queries.rs`): one query's answers from Ricochet and
//! from rapier compared, every difference either within [`QueryTolerance`] or counted under
//! a named rule whose condition is checked with parry's exact pair query, and the tally.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use ricochet_geom::{Pose, Shape, Vec2};
use ricochet_oracle::{QueryReferee, QueryTolerance, ReferenceRayHit};
use ricochet_sim::{Entity, QueryFilter, RayHit, Simulation};

/// Rule: one engine reports a ray hit the other does not, and the ray (as the segment it
/// sweeps) only touches the body: parry's depth of the segment is within the band of 0
/// (tangent to a curve, along a face, through a vertex, or ending on the boundary).
pub(super) const GRAZING: &str = "grazing";
/// Rule: the first hits name different bodies at the same distance (within the band).
pub(super) const TIE: &str = "tie";
/// Rule: one engine has the point inside a body, the other not, and the point is within the
/// band of the body's boundary (Ricochet: strictly inside; parry: boundary included).
pub(super) const BOUNDARY: &str = "boundary";
/// Rule: one engine has a box or shape overlapping a body, the other not, and parry's exact
/// depth of the pair is within the band of 0 (Ricochet: `depth > 0`; parry: touching
/// counts).
pub(super) const TOUCHING: &str = "touching";
/// Rule: a ray starting inside a body: both engines hit it at distance 0, and parry's
/// normal there depends on the shape (a ball's points from the origin to its centre, a
/// cuboid's is zero, a support-map shape's is GJK's last direction), where Ricochet's is
/// always zero. Only the distance is compared; parry's projection must put the origin inside.
pub(super) const INSIDE_NORMAL: &str = "inside-normal";
/// Rule: one engine's cast touches a body the other's does not, and the deepest the swept
/// shape gets into it along the whole path is within the band of 0 (a grazing cast).
pub(super) const GRAZING_CAST: &str = "grazing-cast";

/// Counts per query kind and per rule, and every unexplained difference word for word.
#[derive(Default)]
pub(super) struct Tally {
    pub(super) asked: BTreeMap<&'static str, usize>,
    pub(super) rules: BTreeMap<&'static str, usize>,
    pub(super) unexplained: Vec<String>,
    /// Worst ray distance difference, world units.
    pub(super) worst_ray: f64,
    /// Worst cast difference along the path, world units.
    pub(super) worst_cast: f64,
    pub(super) worst_normal: f64,
}

impl Tally {
    pub(super) fn ask(&mut self, kind: &'static str) {
        *self.asked.entry(kind).or_default() += 1;
    }

    pub(super) fn rule(&mut self, name: &'static str) {
        *self.rules.entry(name).or_default() += 1;
    }

    pub(super) fn fail(&mut self, what: String) {
        self.unexplained.push(what);
    }

    pub(super) fn add(&mut self, o: Tally) {
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
    pub(super) fn assert_clean(&self, name: &str) {
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

/// Half the diagonal of the shape's local bounds (the validation's size of a shape).
pub(super) fn size(s: &Shape) -> f64 {
    s.bounds(&Pose::default()).half_extents().length()
}

pub(super) fn angle_between(a: Vec2, b: Vec2) -> f64 {
    libm::atan2(a.perp_dot(b).abs(), a.dot(b))
}

/// The band for body `e` at this scene's magnitude.
pub(super) fn band(r: &QueryReferee, tol: &QueryTolerance, e: Entity) -> f64 {
    r.body(e).map_or(tol.absolute, |(s, _)| tol.band(s))
}

/// One ray: the first hit and every hit, compared.
#[allow(
    clippy::too_many_arguments,
    reason = "one ray's inputs and the scene's context"
)]
pub(super) fn compare_ray(
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
pub(super) fn compare_hit(
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
pub(super) fn compare_sets(
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
pub(super) fn deepest_on_path(
    r: &QueryReferee,
    shape: &Shape,
    pose: Pose,
    tr: Vec2,
    e: Entity,
) -> f64 {
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

/// One shape cast: the same body at the same fraction (within the band over the path's
/// length, plus Ricochet's stopping gap), or a tie, or a grazing cast.
pub(super) fn compare_cast(
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
