//! The per-frame referee: every logged contact recomputed by parry, and the `all` pass's set
//! of pairs compared with rapier's own broad and narrow phase at the same poses (swept pairs
//! are in `swept.rs`).

use std::collections::{BTreeMap, BTreeSet};

use crate::bench::threshold;
use rapier2d_f64::prelude::{ActiveCollisionTypes, ColliderBuilder, PhysicsWorld};
use ricochet_geom::{Pose, Primitive, Shape, Vec2};
use ricochet_sim::{
    BodyKind, ContactRecord, Entity, FrameOutput, LayerId, Layers, Phase, Response, Scenario,
    Simulation, Stage,
};

use crate::convert::{
    ReferenceContact, depth, overlap_along, pairing, place, reference_contact, size,
};
pub use crate::frame_report::FrameReport;
use crate::pairs::{LayerFilter, penetration};
use crate::seam::{Seam, moved};
use crate::{OracleError, Tolerances, rules};

/// What the referee needs of a body that took part in the frame.
pub(crate) struct Body<'a> {
    pub(crate) name: &'a str,
    pub(crate) shape: &'a Shape,
    pub(crate) kind: BodyKind,
    pub(crate) layer: LayerId,
}

/// The body `e` as it was this frame: alive at its end, or removed during it.
pub(crate) fn body<'a>(sim: &'a Simulation, out: &'a FrameOutput, e: Entity) -> Option<Body<'a>> {
    if let Some(i) = sim.world().index_of(e) {
        let w = sim.world();
        return Some(Body {
            name: w.name(i),
            shape: w.shape(i),
            kind: w.kind[i],
            layer: w.layer[i],
        });
    }
    out.removed.iter().find(|r| r.entity == e).map(|r| Body {
        name: &r.name,
        shape: &r.shape,
        kind: r.kind,
        layer: r.layer,
    })
}

/// The angle between two unit vectors, radians (`atan2` of cross and dot: accurate near 0).
fn angle_between(a: Vec2, b: Vec2) -> f64 {
    libm::atan2(a.perp_dot(b).abs(), a.dot(b))
}

/// Whether the shape is resolved per axis by Ricochet: a single AABB.
fn is_box(s: &Shape) -> bool {
    matches!(s, Shape::Primitive(Primitive::Aabb(_)))
}

/// A contact record recomputed by parry at the record's own poses (see [`recheck`]).
pub(crate) enum Recheck {
    /// Parry's depth is within the tolerance of the record's.
    Agrees(ReferenceContact),
    /// Parry finds the shapes overlapping to another depth.
    Differs(ReferenceContact),
    /// Parry finds the shapes apart.
    Apart,
}

/// Recomputes a contact record (of shapes `a` and `b`) at its own poses: parry's answer, and
/// whether its depth is within `tol` of the record's. Part 1 of [`Referee::check_frame`]
/// (with the pair's relative depth tolerance) and the bench's records at other poses (with
/// its absolute one) both judge a record by this.
pub(crate) fn recheck(
    a: &Shape,
    b: &Shape,
    c: &ContactRecord,
    tol: f64,
) -> Result<Recheck, OracleError> {
    let prediction = tol + (-c.depth).max(0.0);
    Ok(
        match reference_contact(a, &c.pose_a, b, &c.pose_b, prediction)? {
            Some(r) if (r.depth - c.depth).abs() <= tol => Recheck::Agrees(r),
            Some(r) => Recheck::Differs(r),
            None => Recheck::Apart,
        },
    )
}

/// Compares Ricochet's frames with rapier's answers at the same poses. See the crate docs
/// for what is compared and [`rules`] for the differences it explains.
pub struct Referee {
    pub(crate) layers: Layers,
    pub(crate) tol: Tolerances,
    /// The translations a pair is tested at (through the wrap seam).
    pub(crate) seam: Seam,
    /// Every body's position at the end of the last frame checked, and that frame: where a
    /// body removed during the next frame started it.
    pub(crate) previous: Option<(u64, BTreeMap<Entity, Vec2>)>,
}

impl Referee {
    /// A referee for frames of `scenario` (it keeps the layer matrix), judging with `tol`.
    #[must_use]
    pub fn new(scenario: &Scenario, tol: Tolerances) -> Referee {
        Referee {
            layers: scenario.world.layers.clone(),
            tol,
            seam: Seam::new(scenario),
            previous: None,
        }
    }

    /// The tolerances this referee judges with.
    #[must_use]
    pub fn tolerances(&self) -> Tolerances {
        self.tol
    }

    /// Compare one frame: `sim` is the simulation after `step()` returned `out`
    /// (`out.detect_poses` is `Some` because the caller set `sim.capture_detect_poses`).
    ///
    /// 1. Every contact record of every phase is recomputed by parry at the record's own
    ///    poses; depth and normal must agree within the tolerances.
    /// 2. The `all` pass's pairs are compared with the pairs rapier's broad and narrow phase
    ///    find penetrating at the detect poses; each difference must be explained by a
    ///    named rule ([`rules`]).
    /// 3. Every pair Ricochet tests by time of impact is cast by parry along the frame's
    ///    motion: each `swept` record must be parry's first touch, and each touch parry finds
    ///    must be logged, or explained by a rule.
    ///
    /// Call it for every frame in order: a body removed during a frame started it where the
    /// previous frame's check saw it last.
    pub fn check_frame(&mut self, sim: &Simulation, out: &FrameOutput) -> FrameReport {
        let mut report = FrameReport {
            frame: out.frame,
            ..FrameReport::default()
        };
        // One-way platforms are not compared: rapier has no one-way response, and their
        // records (a landing's push onto the platform's top) are left out, as rapier never
        // pairs those layers (docs/validation.md).
        for c in out
            .contacts
            .iter()
            .filter(|c| !matches!(c.response, Response::OneWay(_)))
        {
            self.check_contact(sim, out, c, &mut report);
        }
        match &out.detect_poses {
            Some(poses) => {
                let end = self.check_all_pass(sim, out, poses, &mut report);
                self.check_swept(sim, out, poses, &end, &mut report);
            }
            None if out.stats.stages_run.contains(Stage::Detect) => report.mismatch(format!(
                "frame {}: detect ran but no poses were captured; set \
                 Simulation::capture_detect_poses",
                out.frame
            )),
            None => {}
        }
        self.remember(sim, out.frame);
        report
    }

    /// Keeps every body's end-of-frame position for the next frame's swept checks.
    fn remember(&mut self, sim: &Simulation, frame: u64) {
        let w = sim.world();
        let positions = (0..w.len()).map(|i| (w.entity[i], w.position[i])).collect();
        self.previous = Some((frame, positions));
    }

    /// Whether a layer pair is tested by time of impact (`swept`) rather than at the
    /// detect poses: swept in the matrix, and a `report` or `destroy` response.
    pub(crate) fn swept(&self, a: LayerId, b: LayerId) -> bool {
        let r = self.layers.response(a, b);
        r != Response::Ignore && r != Response::Separate && self.layers.sweeps(a, b)
    }

    /// The absolute depth tolerance of a pair.
    pub(crate) fn depth_tol(&self, a: &Shape, b: &Shape) -> f64 {
        self.tol.depth * size(a).min(size(b))
    }

    /// Part 1: one contact record against parry at the record's poses.
    fn check_contact(
        &self,
        sim: &Simulation,
        out: &FrameOutput,
        c: &ContactRecord,
        report: &mut FrameReport,
    ) {
        let frame = out.frame;
        let (Some(a), Some(b)) = (body(sim, out, c.a), body(sim, out, c.b)) else {
            report.mismatch(format!(
                "frame {frame}: contact #{} #{} names a body that is neither alive nor removed",
                c.a, c.b
            ));
            return;
        };
        report.contacts_compared += 1;
        *report.by_phase.entry(c.phase.name()).or_default() += 1;
        *report
            .by_pairing
            .entry(pairing(a.shape, b.shape))
            .or_default() += 1;
        let who = format!(
            "frame {frame} {} #{} {} / {} #{} {}",
            a.name,
            c.a,
            a.shape_name(),
            b.name,
            c.b,
            b.shape_name()
        );
        let tol = self.depth_tol(a.shape, b.shape);
        let r = match recheck(a.shape, b.shape, c, tol) {
            Ok(Recheck::Agrees(r)) => {
                report.worst_depth_error = report.worst_depth_error.max((c.depth - r.depth).abs());
                r
            }
            Ok(Recheck::Differs(r)) => {
                let depth_err = (c.depth - r.depth).abs();
                report.worst_depth_error = report.worst_depth_error.max(depth_err);
                report.mismatch(format!(
                    "{who} (phase {}): depth {:e} vs rapier {:e} (error {depth_err:e} > {tol:e})",
                    c.phase.name(),
                    c.depth,
                    r.depth
                ));
                return;
            }
            Ok(Recheck::Apart) => {
                report.mismatch(format!(
                    "{who} (phase {}): Ricochet depth {:e}, rapier finds the shapes apart",
                    c.phase.name(),
                    c.depth
                ));
                return;
            }
            Err(e) => {
                report.mismatch(format!("{who}: {e}"));
                return;
            }
        };
        let normal_err = angle_between(c.normal, r.normal);
        if normal_err <= self.tol.normal {
            report.worst_normal_error = report.worst_normal_error.max(normal_err);
            return;
        }
        match tied_normal(
            a.shape, &c.pose_a, b.shape, &c.pose_b, c.normal, r.depth, tol,
        ) {
            Ok(true) => report.explain(rules::TIED_NORMAL, r.depth),
            Ok(false) => report.mismatch(format!(
                "{who} (phase {}): normal {} vs rapier {} ({normal_err:e} rad > {:e})",
                c.phase.name(),
                c.normal,
                r.normal,
                self.tol.normal
            )),
            Err(e) => report.mismatch(format!("{who}: {e}")),
        }
    }

    /// Part 2: the `all` pass's pairs against rapier's pipeline at the detect poses.
    ///
    /// Returns every body's pose at the end of the pass (the detect poses moved by the
    /// pass's `separate` pushes): where swept tests end.
    fn check_all_pass(
        &self,
        sim: &Simulation,
        out: &FrameOutput,
        poses: &[(Entity, Pose)],
        report: &mut FrameReport,
    ) -> BTreeMap<Entity, Pose> {
        let frame = out.frame;
        let detect: BTreeMap<Entity, Pose> = poses.iter().copied().collect();
        let found = match self.rapier_pairs(sim, out, poses) {
            Ok(f) => f,
            Err(e) => {
                report.mismatch(format!("frame {frame}: {e}"));
                return detect;
            }
        };
        // Swept pairs are not tested at the detect poses: `check_swept` owns them.
        let found: BTreeSet<(Entity, Entity)> = found
            .into_iter()
            .filter(
                |(ea, eb)| match (body(sim, out, *ea), body(sim, out, *eb)) {
                    (Some(a), Some(b)) => !self.swept(a.layer, b.layer),
                    _ => true,
                },
            )
            .collect();
        let logged: BTreeMap<(Entity, Entity), &ContactRecord> = out
            .contacts
            .iter()
            .filter(|c| c.phase == Phase::All)
            .map(|c| ((c.a, c.b), c))
            .collect();
        // Swept `separate` stops (time of impact in the pass, then the push): checked where
        // the replay meets them, and their moves replayed like pushes.
        let stops: BTreeMap<(Entity, Entity), &ContactRecord> = out
            .contacts
            .iter()
            .filter(|c| c.phase == Phase::Swept && c.response == Response::Separate)
            .map(|c| ((c.a, c.b), c))
            .collect();
        // Poses as the pass saw them: the detect poses, moved by each `separate` push in
        // pair order (replayed from the records, so the same floating-point additions).
        let mut current = detect.clone();
        let keys: BTreeSet<(Entity, Entity)> = found
            .iter()
            .chain(logged.keys())
            .chain(stops.keys())
            .copied()
            .collect();
        for (ea, eb) in keys {
            let (Some(a), Some(b)) = (body(sim, out, ea), body(sim, out, eb)) else {
                report.mismatch(format!(
                    "frame {frame}: pair #{ea} #{eb} names an unknown body"
                ));
                continue;
            };
            let (Some(&pa), Some(&pb)) = (current.get(&ea), current.get(&eb)) else {
                report.mismatch(format!(
                    "frame {frame}: pair #{ea} #{eb} has no detect pose"
                ));
                continue;
            };
            let who = format!(
                "frame {frame} {} #{ea} {} / {} #{eb} {}",
                a.name,
                a.shape_name(),
                b.name,
                b.shape_name()
            );
            if let Some(c) = stops.get(&(ea, eb)) {
                // The stop replaces the end-pose test (`swept.rs`).
                apply_push(&mut current, c, a.kind, b.kind);
                self.check_swept_separate(sim, out, (a, b), c, (pa, pb), &who, report);
                continue;
            }
            let response = self.layers.response(a.layer, b.layer);
            let tol = self.depth_tol(a.shape, b.shape);
            let thr = threshold(response);
            let moved = pa != detect[&ea] || pb != detect[&eb];
            let in_rapier = found.contains(&(ea, eb));
            let logged_here = logged.get(&(ea, eb)).copied();
            if let Some(c) = logged_here {
                match self.seam.offset_to(&pb, &c.pose_b) {
                    Some(offset) if c.pose_a == pa => {
                        self.check_seam_rule(&a, &b, (&pa, &pb), offset, tol, &who, report);
                    }
                    _ => report.mismatch(format!(
                        "{who}: logged at poses {:?} {:?}, the replayed pass says {pa:?} {pb:?}",
                        c.pose_a, c.pose_b
                    )),
                }
            }
            if in_rapier && logged_here.is_some() {
                report.pairs_confirmed += 1;
            } else {
                // A difference: parry's depth where Ricochet tested the pair decides (the
                // deepest translation through the seam).
                let d = match self.seam.deepest(a.shape, &pa, b.shape, &pb, tol) {
                    Ok((d, _)) => d,
                    Err(e) => {
                        report.mismatch(format!("{who}: {e}"));
                        continue;
                    }
                };
                let rule = if logged_here.is_some() {
                    // Ricochet logged it, rapier's narrow phase saw no penetration.
                    if moved {
                        Some(rules::MOVED_IN_PASS)
                    } else if d >= -tol && d <= thr + tol {
                        Some(rules::TOUCHING)
                    } else {
                        None
                    }
                } else if a.kind != BodyKind::Dynamic && b.kind != BodyKind::Dynamic {
                    Some(rules::STATIC_STATIC)
                } else if response == Response::Separate && is_box(a.shape) && is_box(b.shape) {
                    Some(rules::PER_AXIS_BOXES)
                } else if moved && d <= thr + tol {
                    Some(rules::MOVED_IN_PASS)
                } else if d >= -tol && d <= thr + tol {
                    Some(rules::TOUCHING)
                } else {
                    None
                };
                match (rule, logged_here) {
                    (Some(rule), _) => report.explain(rule, d),
                    (None, Some(c)) => report.mismatch(format!(
                        "{who}: Ricochet logged depth {:e}; rapier's narrow phase finds no \
                         penetration (its query: depth {d:e})",
                        c.depth
                    )),
                    (None, None) => report.mismatch(format!(
                        "{who}: rapier finds depth {d:e} ({} response, threshold {thr:e}); \
                         Ricochet logged no contact",
                        response.name()
                    )),
                }
            }
            if let Some(c) = logged_here {
                apply_push(&mut current, c, a.kind, b.kind);
            }
        }
        current
    }

    /// A logged `all` contact through the seam at `offset` (of `b`'s pose): no other
    /// translation may be deeper by parry (beyond the tolerance).
    #[expect(clippy::too_many_arguments, reason = "the pair as the caller holds it")]
    fn check_seam_rule(
        &self,
        a: &Body<'_>,
        b: &Body<'_>,
        (pa, pb): (&Pose, &Pose),
        offset: Vec2,
        tol: f64,
        who: &str,
        report: &mut FrameReport,
    ) {
        if !self.seam.wraps() {
            return;
        }
        let logged = depth(a.shape, pa, b.shape, &moved(pb, offset), tol);
        let best = self.seam.deepest(a.shape, pa, b.shape, pb, tol);
        match (logged, best) {
            (Ok(d), Ok((best, o))) if best > d + tol => report.mismatch(format!(
                "{who}: logged with b translated by {offset} (parry depth {d:e}); by {o} it \
                 is deeper ({best:e}): the seam rule takes the deepest"
            )),
            (Err(e), _) | (_, Err(e)) => report.mismatch(format!("{who}: {e}")),
            _ => {}
        }
    }

    /// The pairs rapier's broad and narrow phase find penetrating (`dist < 0`) with every
    /// body's collider at its detect pose, layers filtering as Ricochet's matrix does. In a
    /// wrapping world every pose is first wrapped into the world (what the log shows), every
    /// body also has a collider at each of its images, and a pair of a body and another's
    /// image counts as the pair.
    fn rapier_pairs(
        &self,
        sim: &Simulation,
        out: &FrameOutput,
        poses: &[(Entity, Pose)],
    ) -> Result<BTreeSet<(Entity, Entity)>, OracleError> {
        let mut world = PhysicsWorld::new();
        world.integration_parameters.normalized_prediction_distance = 0.0;
        let filter = LayerFilter::new(&self.layers);
        let offsets = self.seam.offsets();
        let n = offsets.len();
        for (k, (e, pose)) in poses.iter().enumerate() {
            let b = body(sim, out, *e).ok_or(OracleError::Conversion("unknown body"))?;
            let pose = self.seam.wrapped(pose);
            for (m, &o) in offsets.iter().enumerate() {
                let (p, shape) = place(b.shape, &moved(&pose, o), Vec2::ZERO)?;
                let builder = ColliderBuilder::new(shape)
                    .position(p)
                    .active_collision_types(ActiveCollisionTypes::all());
                world
                    .colliders
                    .insert(filter.collider(builder, b.layer, k * n + m).build());
            }
        }
        world.detect_collisions(&filter, &());
        let mut pairs = BTreeSet::new();
        for pair in world.narrow_phase.contact_pairs() {
            if penetration(pair).is_none() {
                continue;
            }
            let index = |h| world.colliders.get(h).map(crate::pairs::index);
            let (Some(i), Some(j)) = (index(pair.collider1), index(pair.collider2)) else {
                continue;
            };
            // A body and another's image (index 0 is the body itself); two images moved
            // alike are the real pair, and a body never meets its own image.
            let ((i, mi), (j, mj)) = ((i / n, i % n), (j / n, j % n));
            if (mi != 0 && mj != 0) || i == j {
                continue;
            }
            let (ea, eb) = (poses[i].0, poses[j].0);
            pairs.insert((ea.min(eb), ea.max(eb)));
        }
        Ok(pairs)
    }
}

impl Body<'_> {
    pub(crate) fn shape_name(&self) -> &'static str {
        crate::convert::shape_name(self.shape)
    }
}

/// Applies the push a logged `separate` contact made, exactly as Ricochet's `detect` did:
/// `resolved` is the push of the body that moved (`b`'s when both did, `a`'s being its
/// negation).
pub(crate) fn apply_push(
    current: &mut BTreeMap<Entity, Pose>,
    c: &ContactRecord,
    ka: BodyKind,
    kb: BodyKind,
) {
    if c.response != Response::Separate || c.resolved == Vec2::ZERO {
        return;
    }
    let (da, db) = (ka == BodyKind::Dynamic, kb == BodyKind::Dynamic);
    let push_a = if da && db { -c.resolved } else { c.resolved };
    if da && let Some(p) = current.get_mut(&c.a) {
        p.position += push_a;
    }
    if db && let Some(p) = current.get_mut(&c.b) {
        p.position += c.resolved;
    }
}

/// Whether `normal` is a minimum-translation direction too: some part pair is as deep as
/// rapier's deepest (within `tol`) and overlaps along `normal` by that depth (within `tol`).
/// Overlapping convex shapes overlap along every direction by at least their depth, and by
/// exactly their depth along a minimum translation, so this accepts exactly the directions
/// that tie with rapier's.
fn tied_normal(
    a: &Shape,
    pose_a: &Pose,
    b: &Shape,
    pose_b: &Pose,
    normal: Vec2,
    depth: f64,
    tol: f64,
) -> Result<bool, OracleError> {
    if depth <= 0.0 {
        return Ok(false);
    }
    for pa in a.primitives() {
        for pb in b.primitives() {
            let (sa, sb) = (Shape::Primitive(*pa), Shape::Primitive(*pb));
            let Some(part) = reference_contact(&sa, pose_a, &sb, pose_b, tol)? else {
                continue;
            };
            if part.depth < depth - tol {
                continue;
            }
            let along = overlap_along(pa, pose_a, pb, pose_b, normal)?;
            if (along - depth).abs() <= tol {
                return Ok(true);
            }
        }
    }
    Ok(false)
}
