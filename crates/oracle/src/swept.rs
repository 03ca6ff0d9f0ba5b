//! Swept pairs: every pair Ricochet tests by time of impact, cast by parry along the same
//! straight-line motion, and each logged `swept` contact checked to be the first touch.

use std::collections::BTreeMap;

use ricochet_geom::{Pose, Vec2};
use ricochet_sim::{
    BodyKind, ContactRecord, Doomed, Entity, FrameOutput, Phase, Response, Simulation,
};

use crate::convert::depth;
use crate::convert::{first_touch, size};
use crate::referee::{Body, FrameReport, Referee, body};
use crate::seam::{moved, widened};
use crate::{OracleError, rules};

/// One swept-eligible pair, with parry's answer.
struct Pair<'a> {
    a: Body<'a>,
    b: Body<'a>,
    /// Start poses: start positions, end angles (rotation is not swept); `b`'s translated
    /// by `offset`.
    start: (Pose, Pose),
    /// The translation of `b` through the wrap seam (zero for the direct pair): the one
    /// whose first touch is earliest.
    offset: Vec2,
    /// Displacements over the frame.
    motion: (Vec2, Vec2),
    /// Parry's first touch in `[0, 1]`.
    toi: Option<f64>,
    /// The body that travelled further (`a` on a tie), as Ricochet picks it.
    mover: Entity,
}

/// The deepest the pair gets along its straight-line motion, by parry: per part pair, a
/// ternary search on `t` (with rotation fixed, the relative position moves along a line
/// through a fixed convex Minkowski difference, on which the signed depth is concave).
fn deepest_along(p: &Pair<'_>) -> Result<f64, OracleError> {
    let (sa, sb) = p.start;
    let (da, db) = p.motion;
    let at = |t: f64| {
        (
            Pose::new(sa.position + da * t, sa.angle),
            Pose::new(sb.position + db * t, sb.angle),
        )
    };
    let mut deepest = f64::NEG_INFINITY;
    for pa in p.a.shape.primitives() {
        for pb in p.b.shape.primitives() {
            // A part alone is placed as in its body: only parts that turn use the angle.
            let (ka, kb) = (
                ricochet_geom::Shape::Primitive(*pa),
                ricochet_geom::Shape::Primitive(*pb),
            );
            let f = |t: f64| -> Result<f64, OracleError> {
                let (qa, qb) = at(t);
                depth(&ka, &qa, &kb, &qb, f64::MAX)
            };
            let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
            for _ in 0..100 {
                let (m1, m2) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
                if f(m1)? < f(m2)? {
                    lo = m1;
                } else {
                    hi = m2;
                }
            }
            deepest = deepest.max(f(0.5 * (lo + hi))?);
        }
    }
    Ok(deepest)
}

/// Whether a swept record's response removed `e`.
fn dooms(c: &ContactRecord, e: Entity) -> bool {
    match c.response {
        Response::Destroy(Doomed::First) => c.a == e,
        Response::Destroy(Doomed::Second) => c.b == e,
        Response::Destroy(Doomed::Both) => c.a == e || c.b == e,
        _ => false,
    }
}

impl Referee {
    /// Where body `e` started the frame: the simulation's `start_position` if it is alive,
    /// else its position at the end of the previous checked frame, else (a body spawned and
    /// removed within this frame) its detect position minus `velocity * dt`.
    fn start_of(
        &self,
        sim: &Simulation,
        out: &FrameOutput,
        e: Entity,
        detect: &Pose,
    ) -> Option<Vec2> {
        if let Some(i) = sim.world().index_of(e) {
            return Some(sim.world().start_position(i));
        }
        let removed = out.removed.iter().find(|r| r.entity == e);
        if let Some((frame, positions)) = &self.previous
            && *frame + 1 == out.frame
            && let Some(&p) = positions.get(&e)
        {
            // A body that ended its motion far out of a wrapping world was wrapped in
            // before detect, its start moved by the same whole world sizes: the sizes that
            // bring the start nearest `detect - velocity dt`.
            return Some(match (self.seam.size(), removed) {
                (Some(size), Some(r)) => {
                    let k = (detect.position - r.velocity * sim.dt() - p) / size;
                    p + k.round() * size
                }
                _ => p,
            });
        }
        Some(detect.position - removed?.velocity * sim.dt())
    }

    /// Part 3: swept pairs. Every pair Ricochet would test by time of impact is cast by
    /// parry from the start poses along the frame's motion; Ricochet's `swept` records must
    /// be those first touches, and each hit parry finds must be logged or explained.
    pub(crate) fn check_swept(
        &self,
        sim: &Simulation,
        out: &FrameOutput,
        poses: &[(Entity, Pose)],
        end: &BTreeMap<Entity, Pose>,
        report: &mut FrameReport,
    ) {
        let frame = out.frame;
        let logged: BTreeMap<(Entity, Entity), &ContactRecord> = out
            .contacts
            .iter()
            .filter(|c| c.phase == Phase::Swept && c.response != Response::Separate)
            .map(|c| ((c.a, c.b), c))
            .collect();
        let n = self.layers.names().len();
        let any_swept = (0..n).any(|a| {
            (0..n).any(|b| match (u8::try_from(a), u8::try_from(b)) {
                (Ok(a), Ok(b)) => self.swept(a, b),
                _ => false,
            })
        });
        if !any_swept {
            for (a, b) in logged.keys() {
                report.mismatch(format!(
                    "frame {frame}: swept contact #{a} #{b}, but no layer pair is swept"
                ));
            }
            return;
        }
        let pairs = match self.swept_pairs(sim, out, poses, end) {
            Ok(p) => p,
            Err(e) => {
                report.mismatch(format!("frame {frame}: {e}"));
                return;
            }
        };
        for key in logged.keys() {
            if !pairs.contains_key(key) {
                report.mismatch(format!(
                    "frame {frame}: swept contact #{} #{} is not a swept pair of this frame",
                    key.0, key.1
                ));
            }
        }
        for (&(ea, eb), p) in &pairs {
            let who = format!(
                "frame {frame} {} #{ea} {} / {} #{eb} {}",
                p.a.name,
                p.a.shape_name(),
                p.b.name,
                p.b.shape_name()
            );
            let tol = self.depth_tol(p.a.shape, p.b.shape);
            let small = size(p.a.shape).min(size(p.b.shape));
            let gap = self.tol.toi_gap * small;
            // The time-of-impact tolerance as a fraction of the frame's motion.
            let speed = (p.motion.1 - p.motion.0).length();
            let slack = if speed > 0.0 {
                self.tol.toi * small / speed
            } else {
                0.0
            };
            match (logged.get(&(ea, eb)), p.toi) {
                (Some(c), Some(t_r)) => {
                    match self.check_first_touch(p, c, t_r, tol, gap, slack) {
                        Ok(None) => report.swept_confirmed += 1,
                        Ok(Some(Ok((rule, d)))) => report.explain(rule, d),
                        Ok(Some(Err(why))) => report.mismatch(format!("{who}: {why}")),
                        Err(e) => report.mismatch(format!("{who}: {e}")),
                    }
                    // A mover is spent by the first hit that destroys it while it is that
                    // hit's mover: no later hit it moves into may be logged.
                    let earlier_doom = logged.iter().any(|(k, other)| {
                        *k != (ea, eb)
                            && dooms(other, p.mover)
                            && pairs.get(k).is_some_and(|q| {
                                q.mover == p.mover && q.toi.is_some_and(|t| t < t_r - slack)
                            })
                    });
                    if earlier_doom {
                        report.mismatch(format!(
                            "{who}: logged at t = {t_r:.9} although #{} was destroyed by an \
                             earlier swept hit",
                            p.mover
                        ));
                    }
                }
                (Some(c), None) => {
                    // Parry finds no touch: within the stopping gap of one is `touching`.
                    match first_touch(
                        p.a.shape, &p.start.0, p.motion.0, p.b.shape, &p.start.1, p.motion.1, gap,
                    ) {
                        Ok(Some(_)) => report.explain(rules::TOUCHING, c.depth),
                        Ok(None) => report.mismatch(format!(
                            "{who}: Ricochet logged a swept hit (depth {:e}); parry's shape \
                             cast finds no touch during the frame",
                            c.depth
                        )),
                        Err(e) => report.mismatch(format!("{who}: {e}")),
                    }
                }
                (None, Some(t_r)) => {
                    // Parry finds a touch Ricochet did not log: the mover must have been
                    // stopped by an earlier hit that destroyed it (as that hit's mover too),
                    // or the path only grazes.
                    let spent = logged.iter().any(|(k, other)| {
                        dooms(other, p.mover)
                            && pairs.get(k).is_some_and(|q| {
                                q.mover == p.mover && q.toi.is_some_and(|t| t <= t_r + slack)
                            })
                    });
                    if spent {
                        let end_b = moved(&end[&eb], p.offset);
                        let d = depth(p.a.shape, &end[&ea], p.b.shape, &end_b, tol)
                            .unwrap_or(f64::NEG_INFINITY);
                        report.explain(rules::FIRST_HIT, d);
                        continue;
                    }
                    match deepest_along(p) {
                        Ok(d) if d <= tol => report.explain(rules::TOUCHING, d),
                        Ok(d) => report.mismatch(format!(
                            "{who}: parry's shape cast touches at t = {t_r:.9} of the frame \
                             and the path goes {d:e} deep; Ricochet logged no swept contact"
                        )),
                        Err(e) => report.mismatch(format!("{who}: {e}")),
                    }
                }
                (None, None) => {}
            }
        }
    }

    /// A swept `separate` record (`sweep_normal.rs` in the simulation), met in the replayed
    /// `all` pass at the poses `(pa, pb)` the pass had reached: Ricochet swept the pair from
    /// the frame's start positions to those poses. The record must be parry's first touch
    /// along that path, as for a `swept` hit (or within the stopping gap of one: `touching`);
    /// what rapier sees at those poses (the tunnelled end pose) is rule `swept-separate`.
    #[expect(clippy::too_many_arguments, reason = "the pair as the replay holds it")]
    pub(crate) fn check_swept_separate(
        &self,
        sim: &Simulation,
        out: &FrameOutput,
        (a, b): (Body<'_>, Body<'_>),
        c: &ContactRecord,
        (pa, pb): (Pose, Pose),
        who: &str,
        report: &mut FrameReport,
    ) {
        // What rapier sees at these poses is the tunnelled end pose: explained.
        let tol = self.depth_tol(a.shape, b.shape);
        let d = depth(a.shape, &pa, b.shape, &pb, tol).unwrap_or(f64::NEG_INFINITY);
        report.explain(rules::SWEPT_SEPARATE, d);
        let (Some(start_a), Some(start_b)) = (
            self.start_of(sim, out, c.a, &pa),
            self.start_of(sim, out, c.b, &pb),
        ) else {
            report.mismatch(format!("{who}: a swept separate body has no start pose"));
            return;
        };
        let start = (Pose::new(start_a, pa.angle), Pose::new(start_b, pb.angle));
        let motion = (pa.position - start_a, pb.position - start_b);
        let small = size(a.shape).min(size(b.shape));
        let gap = self.tol.toi_gap * small;
        let speed = (motion.1 - motion.0).length();
        let slack = if speed > 0.0 {
            self.tol.toi * small / speed
        } else {
            0.0
        };
        let toi = first_touch(
            a.shape, &start.0, motion.0, b.shape, &start.1, motion.1, 0.0,
        );
        // Only the first-touch check reads the pair: no seam, and the mover is not used.
        let p = Pair {
            a,
            b,
            start,
            offset: Vec2::ZERO,
            motion,
            toi: None,
            mover: c.a,
        };
        match toi {
            Ok(Some(t_r)) => match self.check_first_touch(&p, c, t_r, tol, gap, slack) {
                Ok(None) => report.swept_confirmed += 1,
                Ok(Some(Ok((rule, d)))) => report.explain(rule, d),
                Ok(Some(Err(why))) => report.mismatch(format!("{who}: {why}")),
                Err(e) => report.mismatch(format!("{who}: {e}")),
            },
            Ok(None) => match first_touch(
                p.a.shape, &start.0, motion.0, p.b.shape, &start.1, motion.1, gap,
            ) {
                Ok(Some(_)) => report.explain(rules::TOUCHING, c.depth),
                Ok(None) => report.mismatch(format!(
                    "{who}: Ricochet logged a swept separate stop; parry's shape cast finds \
                     no touch on the path"
                )),
                Err(e) => report.mismatch(format!("{who}: {e}")),
            },
            Err(e) => report.mismatch(format!("{who}: {e}")),
        }
    }

    /// Checks a logged swept contact against parry's first touch `t_r`: `Ok(None)` when it
    /// is that touch, `Ok(Some(Ok(rule)))` when a rule explains the difference,
    /// `Ok(Some(Err(why)))` when nothing does.
    #[expect(
        clippy::type_complexity,
        reason = "three outcomes plus a query error, used once"
    )]
    fn check_first_touch(
        &self,
        p: &Pair<'_>,
        c: &ContactRecord,
        t_r: f64,
        tol: f64,
        gap: f64,
        slack: f64,
    ) -> Result<Option<Result<(&'static str, f64), String>>, OracleError> {
        let (sa, sb) = p.start;
        let (da, db) = p.motion;
        // Ricochet's poses are start + t * motion at the end angles; recover its t.
        if c.pose_a.angle != sa.angle || c.pose_b.angle != sb.angle {
            return Ok(Some(Err(format!(
                "logged at angles {} and {}, the end angles are {} and {}",
                c.pose_a.angle, c.pose_b.angle, sa.angle, sb.angle
            ))));
        }
        let rel_motion = db - da;
        let rel0 = sb.position - sa.position;
        let rel = c.pose_b.position - c.pose_a.position;
        let t_s = if rel_motion.length_squared() > 0.0 {
            (rel - rel0).dot(rel_motion) / rel_motion.length_squared()
        } else {
            0.0
        };
        let off_path = (c.pose_a.position - (sa.position + da * t_s))
            .length()
            .max((c.pose_b.position - (sb.position + db * t_s)).length());
        if off_path > tol.max(1e-12 * (sa.position.length() + da.length())) {
            return Ok(Some(Err(format!(
                "logged {off_path:e} off the straight path from the start poses"
            ))));
        }
        let d = depth(p.a.shape, &c.pose_a, p.b.shape, &c.pose_b, gap + tol)?;
        if t_s > t_r + slack {
            // Later than parry's first touch: only the end-of-frame fallback of a grazing
            // approach may do that.
            let at_end = (t_s - 1.0).abs() <= slack;
            return Ok(Some(if at_end && d > 0.0 {
                Ok((rules::TOI_FALLBACK, d))
            } else {
                Err(format!(
                    "logged at t = {t_s:.9} of the frame, after parry's first touch at \
                     t = {t_r:.9}"
                ))
            }));
        }
        if d < -gap {
            return Ok(Some(Err(format!(
                "logged {:e} apart (parry), more than the stopping gap {gap:e}",
                -d
            ))));
        }
        if t_s > slack && d > tol {
            return Ok(Some(Err(format!(
                "logged {d:e} deep at t = {t_s:.9}: a first touch after the start is never deep"
            ))));
        }
        Ok(None)
    }

    /// The translation of `b` (through the wrap seam) whose first touch along the motion is
    /// earliest, the first in the seam's order on a tie, and that touch. When none touches,
    /// the earliest within the stopping gap (a graze), else the direct one.
    fn earliest_touch(
        &self,
        a: &Body<'_>,
        b: &Body<'_>,
        start: (Pose, Pose),
        motion: (Vec2, Vec2),
    ) -> Result<(Vec2, Option<f64>), OracleError> {
        let gap = self.tol.toi_gap * size(a.shape).min(size(b.shape));
        let swept = |s: &ricochet_geom::Shape, p: &Pose, d: Vec2| {
            s.bounds(p)
                .union(s.bounds(&Pose::new(p.position + d, p.angle)))
        };
        let path_a = widened(swept(a.shape, &start.0, motion.0), 2.0 * gap);
        let path_b = swept(b.shape, &start.1, motion.1);
        let offsets = self.seam.along(&path_a, &path_b)?;
        let mut touch: Option<(f64, Vec2)> = None;
        let mut graze: Option<(f64, Vec2)> = None;
        for &o in &offsets {
            let sb = moved(&start.1, o);
            if o != Vec2::ZERO && !path_a.overlaps(&swept(b.shape, &sb, motion.1)) {
                continue;
            }
            let cast =
                |target| first_touch(a.shape, &start.0, motion.0, b.shape, &sb, motion.1, target);
            if let Some(t) = cast(0.0)?
                && touch.is_none_or(|(best, _)| t < best)
            {
                touch = Some((t, o));
            }
            if touch.is_none()
                && let Some(t) = cast(gap)?
                && graze.is_none_or(|(best, _)| t < best)
            {
                graze = Some((t, o));
            }
        }
        Ok(match (touch, graze) {
            (Some((t, o)), _) => (o, Some(t)),
            (None, Some((_, o))) => (o, None),
            (None, None) => (Vec2::ZERO, None),
        })
    }

    /// Every pair Ricochet tests by time of impact this frame, with parry's first touch.
    fn swept_pairs<'a>(
        &self,
        sim: &'a Simulation,
        out: &'a FrameOutput,
        poses: &[(Entity, Pose)],
        end: &BTreeMap<Entity, Pose>,
    ) -> Result<BTreeMap<(Entity, Entity), Pair<'a>>, OracleError> {
        let mut pairs = BTreeMap::new();
        for (k, (ea, detect_a)) in poses.iter().enumerate() {
            for (eb, detect_b) in &poses[k + 1..] {
                let (Some(a), Some(b)) = (body(sim, out, *ea), body(sim, out, *eb)) else {
                    continue;
                };
                if (a.kind != BodyKind::Dynamic && b.kind != BodyKind::Dynamic)
                    || !self.swept(a.layer, b.layer)
                {
                    continue;
                }
                let (Some(start_a), Some(start_b)) = (
                    self.start_of(sim, out, *ea, detect_a),
                    self.start_of(sim, out, *eb, detect_b),
                ) else {
                    return Err(OracleError::Conversion("a swept body has no start pose"));
                };
                let (end_a, end_b) = (end[ea].position, end[eb].position);
                let start = (
                    Pose::new(start_a, detect_a.angle),
                    Pose::new(start_b, detect_b.angle),
                );
                let motion = (end_a - start_a, end_b - start_b);
                let (offset, toi) = self.earliest_touch(&a, &b, start, motion)?;
                let start = (start.0, moved(&start.1, offset));
                let mover = if motion.1.length() > motion.0.length() {
                    *eb
                } else {
                    *ea
                };
                // Detect poses are in id order, so `ea < eb`: the log's `(a, b)`.
                pairs.insert(
                    (*ea, *eb),
                    Pair {
                        a,
                        b,
                        start,
                        offset,
                        motion,
                        toi,
                        mover,
                    },
                );
            }
        }
        Ok(pairs)
    }
}
