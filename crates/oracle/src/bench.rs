//! The rapier side of `ricochet bench`: rapier's collision-only pipeline on the same shapes
//! at the same poses as a running [`Simulation`], and the comparison of the two contact sets.
//!
//! [`RapierScene`] holds what a good rapier user would build for a game that moves its own
//! bodies and asks rapier only for contacts:
//!
//! - one collider per body, without a rigid body: a collider without a parent is *fixed* to
//!   rapier. Moving bodies' colliders are moved with `Collider::set_position` (only those
//!   whose pose changed: rapier then revisits only them); static bodies' colliders never
//!   change, so rapier's broad phase never revisits their leaves. Measured against the
//!   alternative (dynamic or kinematic rigid bodies moved with `RigidBody::set_position`),
//!   this is 25–30% faster for rapier on `asteroids-10000` and `rain-10000` and the same on
//!   platformers, so it is the configuration the bench times;
//! - [`ActiveCollisionTypes`]: every pair is fixed–fixed to rapier, so the colliders of
//!   dynamic bodies enable `FIXED_FIXED` (a pair is active when either collider enables
//!   it) and the others keep the default: a pair is tested only when one body is dynamic,
//!   Ricochet's rule exactly (static and kinematic bodies never collide with each other);
//! - [`InteractionGroups`]: membership = the layer's bit, filter = every layer whose response
//!   with it is not `ignore` (so layers Ricochet ignores are never tested by rapier either);
//! - no sensors (a `report` pair still wants its penetration depth), prediction distance 0;
//! - a [`CollisionPipeline`] (BVH broad phase, narrow phase) stepped once per frame, after
//!   [`RapierScene::sync`] has copied every moving body's pose from the simulation.
//!
//! Shapes are converted and placed exactly as the referee does (`convert.rs`): a collider's
//! pose is the pose `place` gives the body's primitive, so an AABB stays unrotated whatever
//! the body's angle. Compound shapes are not supported here (the bench scenes have
//! none): placing their parts would mean rebuilding the collider every frame.
//!
//! [`compare_contacts`] then compares one frame's [`FrameOutput`] with rapier's penetrating
//! pairs at the end-of-frame poses; the rule is documented on it.

use std::collections::{BTreeMap, BTreeSet};

use rapier2d_f64::math::{Pose as PPose, Rot2};
use rapier2d_f64::prelude::{
    ActiveCollisionTypes, BroadPhaseBvh, ColliderBuilder, ColliderHandle, ColliderSet,
    CollisionPipeline, Group, InteractionGroups, InteractionTestMode, IslandManager, NarrowPhase,
    PairContacts, RigidBodySet,
};
use ricochet_geom::{Pose, Primitive, Rot, Shape};
use ricochet_sim::{
    BodyKind, ContactRecord, Entity, FrameOutput, LayerId, Layers, Phase, Response, SLOP,
    Simulation,
};

use crate::OracleError;
use crate::convert::{place, reference_contact, to_vector};
use crate::referee::body;

/// The tolerance of the contact-set comparison, world units, on both sides of touching:
/// Ricochet's depth `<= CONTACT_TOLERANCE` or rapier's `dist >= -CONTACT_TOLERANCE` is a
/// touch either engine may call either way. Parry's GJK/EPA on capsule colliders (what
/// rapier's pipeline runs for them) stops within about `3e-7` of the exact depth
/// (`docs/validation.md`); every other pairing agrees to rounding.
pub const CONTACT_TOLERANCE: f64 = 1e-6;

/// How many disagreements a [`ContactAgreement`] keeps word for word (all are counted).
pub const MAX_AGREEMENT_DETAILS: usize = 20;

/// The pose of the rapier collider of `shape` at `pose`: the pose `convert::place` gives the
/// primitive, in world coordinates.
fn collider_pose(shape: &Shape, pose: &Pose) -> Result<PPose, OracleError> {
    let Shape::Primitive(p) = shape else {
        return Err(OracleError::Conversion(
            "compound shapes are not supported by the benchmark's rapier scene",
        ));
    };
    let rot = shape.rotation(pose.angle);
    let to_rot = |r: Rot| Rot2::from_cos_sin_unchecked(r.c, r.s);
    let p0 = pose.position;
    Ok(match p {
        Primitive::Circle(c) => PPose::from_translation(to_vector(p0 + rot.apply(c.center))),
        Primitive::Aabb(b) => PPose::from_translation(to_vector(p0 + rot.apply(b.center))),
        Primitive::Obb(b) => {
            let own = if b.angle == 0.0 {
                rot
            } else {
                Rot::from_angle(pose.angle + b.angle)
            };
            PPose::from_parts(to_vector(p0 + rot.apply(b.center)), to_rot(own))
        }
        Primitive::Capsule(_) | Primitive::Polygon(_) => {
            PPose::from_parts(to_vector(p0), to_rot(rot))
        }
    })
}

/// The collision groups of a layer: its bit, filtered by every layer it does not ignore.
fn groups(layers: &Layers, layer: LayerId) -> Result<InteractionGroups, OracleError> {
    let n = layers.names().len();
    if n > 32 {
        return Err(OracleError::Conversion(
            "more than 32 layers: rapier has 32 collision groups",
        ));
    }
    let mut filter = 0u32;
    for other in 0..n {
        let other = LayerId::try_from(other).unwrap_or(LayerId::MAX);
        if layers.response(layer, other) != Response::Ignore {
            filter |= 1 << other;
        }
    }
    Ok(InteractionGroups::new(
        Group::from_bits_retain(1 << layer),
        Group::from_bits_retain(filter),
        InteractionTestMode::And,
    ))
}

/// Rapier's collision-only pipeline holding one collider per body of a [`Simulation`]. See
/// the module docs for how it is configured.
pub struct RapierScene {
    pipeline: CollisionPipeline,
    islands: IslandManager,
    broad_phase: BroadPhaseBvh,
    narrow_phase: NarrowPhase,
    /// Always empty: every collider is parentless.
    bodies: RigidBodySet,
    colliders: ColliderSet,
    /// Every non-static body: its dense index and its collider.
    moving: Vec<(usize, ColliderHandle)>,
    /// Every body's entity, by dense index (the collider's `user_data`).
    entities: Vec<Entity>,
}

impl RapierScene {
    /// Rapier colliders for every body of `sim`, at their current poses. Call [`step`] once
    /// before timing anything: the first step builds the broad phase's tree from scratch.
    ///
    /// [`step`]: RapierScene::step
    pub fn new(sim: &Simulation) -> Result<RapierScene, OracleError> {
        let w = &sim.world;
        let layers = &sim.scenario.world.layers;
        let mut scene = RapierScene {
            pipeline: CollisionPipeline::new(),
            islands: IslandManager::new(),
            broad_phase: BroadPhaseBvh::new(),
            narrow_phase: NarrowPhase::new(),
            bodies: RigidBodySet::new(),
            colliders: ColliderSet::new(),
            moving: Vec::new(),
            entities: w.entity.clone(),
        };
        for i in 0..w.len() {
            let pose = collider_pose(&w.shape[i], &w.pose(i))?;
            // The shape in its own frame: the collider's pose carries the whole placement.
            let (_, shape) = place(&w.shape[i], &Pose::default(), ricochet_geom::Vec2::ZERO)?;
            let types = if w.kind[i] == BodyKind::Dynamic {
                ActiveCollisionTypes::default() | ActiveCollisionTypes::FIXED_FIXED
            } else {
                ActiveCollisionTypes::default()
            };
            let collider = ColliderBuilder::new(shape)
                .position(pose)
                .collision_groups(groups(layers, w.layer[i])?)
                .active_collision_types(types)
                .user_data(i as u128)
                .build();
            let handle = scene.colliders.insert(collider);
            if w.kind[i] != BodyKind::Static {
                scene.moving.push((i, handle));
            }
        }
        Ok(scene)
    }

    /// Copies every moving body's pose from `sim` into its collider (not part of the timed
    /// step). Colliders whose pose did not change are left untouched, so rapier skips them.
    ///
    /// Fails when the simulation gained or lost bodies: the bench scenes keep their count.
    pub fn sync(&mut self, sim: &Simulation) -> Result<(), OracleError> {
        let w = &sim.world;
        if w.entity != self.entities {
            return Err(OracleError::Conversion(
                "the simulation spawned or removed bodies; the bench needs a stable body set",
            ));
        }
        for &(i, handle) in &self.moving {
            let pose = collider_pose(&w.shape[i], &w.pose(i))?;
            // `get_mut` marks the collider modified: touch only the ones that moved.
            if self
                .colliders
                .get(handle)
                .is_some_and(|c| *c.position() != pose)
                && let Some(c) = self.colliders.get_mut(handle)
            {
                c.set_position(pose);
            }
        }
        Ok(())
    }

    /// One step of rapier's collision-only pipeline: broad phase and narrow phase for
    /// everything that moved since the last step. This is the part `ricochet bench` times.
    pub fn step(&mut self) {
        self.pipeline.step(
            0.0,
            &mut self.islands,
            &mut self.broad_phase,
            &mut self.narrow_phase,
            &mut self.bodies,
            &mut self.colliders,
            &(),
            &(),
        );
    }

    /// How many colliders rapier holds.
    #[must_use]
    pub fn len(&self) -> usize {
        self.entities.len()
    }

    /// Whether rapier holds no collider.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.entities.is_empty()
    }

    /// Every pair rapier's narrow phase finds penetrating after the last [`step`]: some
    /// contact point with `dist < 0`. Keyed `(a, b)` with `a < b`, the value is the pair's
    /// smallest `dist` (minus its depth). Every such pair has a dynamic body (see the module
    /// docs on collision types), so only the moving colliders' pairs are visited.
    ///
    /// [`step`]: RapierScene::step
    #[must_use]
    pub fn penetrating(&self) -> BTreeMap<(Entity, Entity), f64> {
        let mut pairs = BTreeMap::new();
        let entity = |h: ColliderHandle| {
            self.colliders
                .get(h)
                .and_then(|c| self.entities.get(c.user_data as usize).copied())
        };
        for &(_, co) in &self.moving {
            for pair in self.narrow_phase.contact_pairs_with(co) {
                let PairContacts::Rigid(rigid) = &pair.contacts else {
                    continue;
                };
                let dist = rigid
                    .manifolds
                    .iter()
                    .flat_map(|m| m.points.iter())
                    .map(|p| p.dist)
                    .fold(f64::INFINITY, f64::min);
                if dist >= 0.0 {
                    continue;
                }
                let (Some(ea), Some(eb)) = (entity(pair.collider1), entity(pair.collider2)) else {
                    continue;
                };
                pairs.insert((ea.min(eb), ea.max(eb)), dist);
            }
        }
        pairs
    }
}

/// How one frame's (or a whole run's) contact sets compare. Every compared item either
/// agrees or is counted as a disagreement with a sentence in `details`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ContactAgreement {
    /// Items compared: end-of-frame pairs (from either engine) plus contact records checked
    /// at their own poses.
    pub compared: u64,
    /// Items on which the engines agree (`both + touching + rapier_cached +
    /// at_record_poses`).
    pub agreed: u64,
    /// Pairs penetrating in both engines at the end of the frame (or penetrating in rapier and
    /// touched by a Ricochet swept test during the frame).
    pub both: u64,
    /// Pairs in one engine only, within the tolerance of touching (see [`compare_contacts`]).
    pub touching: u64,
    /// Pairs in one engine only where rapier's pipeline kept contact points from an earlier
    /// frame and a fresh parry query at the end-of-frame poses agrees with Ricochet (see
    /// [`compare_contacts`], step 4).
    pub rapier_cached: u64,
    /// Contact records at poses other than the end of the frame (`x`, `y`, most `swept`),
    /// whose depth parry confirms at the record's own poses.
    pub at_record_poses: u64,
    /// Pairs and records left out because a body of the pair wrapped round the world after
    /// `detect` (rapier sees it on the other side).
    pub excluded: u64,
    /// Disagreements where Ricochet found a contact rapier does not confirm.
    pub ricochet_only: u64,
    /// Disagreements where rapier found a penetration Ricochet did not log.
    pub rapier_only: u64,
    /// The first [`MAX_AGREEMENT_DETAILS`] disagreements, one sentence each.
    pub details: Vec<String>,
}

impl ContactAgreement {
    /// Whether every compared item agreed.
    #[must_use]
    pub fn all_agree(&self) -> bool {
        self.agreed == self.compared
    }

    /// Adds another frame's counts (and details, up to the limit).
    pub fn add(&mut self, other: &ContactAgreement) {
        self.compared += other.compared;
        self.agreed += other.agreed;
        self.both += other.both;
        self.touching += other.touching;
        self.rapier_cached += other.rapier_cached;
        self.at_record_poses += other.at_record_poses;
        self.excluded += other.excluded;
        self.ricochet_only += other.ricochet_only;
        self.rapier_only += other.rapier_only;
        for d in &other.details {
            if self.details.len() < MAX_AGREEMENT_DETAILS {
                self.details.push(d.clone());
            }
        }
    }

    fn agree(&mut self) {
        self.compared += 1;
        self.agreed += 1;
    }

    fn disagree(&mut self, ricochet_side: bool, detail: impl FnOnce() -> String) {
        self.compared += 1;
        if ricochet_side {
            self.ricochet_only += 1;
        } else {
            self.rapier_only += 1;
        }
        if self.details.len() < MAX_AGREEMENT_DETAILS {
            self.details.push(detail());
        }
    }
}

/// Compares one frame's contacts with rapier's penetrating pairs at the end-of-frame poses
/// (`rapier` from [`RapierScene::penetrating`], after [`RapierScene::sync`] and
/// [`RapierScene::step`] on the same `sim`). `tol` is normally [`CONTACT_TOLERANCE`].
///
/// The rule:
/// 1. **Excluded:** pairs (and records) with a body that the `bounds` stage wrapped round
///    the world this frame (it moved by more than half the world on an axis): Ricochet
///    detected it before the wrap, rapier sees it on the other side.
/// 2. **Records at other poses** (`x` and `y`, whose bodies the per-axis passes moved before
///    `detect`; `swept`, logged at the time of impact; any record whose poses are not both
///    bodies' end-of-frame poses): parry recomputes the depth at the record's own poses and
///    must agree within `tol`. Such a pair takes no other part in step 3, except that a
///    `swept` record covers a penetration at the end of the frame (a pair that penetrates at
///    the end touched at some moment of the frame).
/// 3. **End-of-frame sets:** Ricochet's pairs with a record at the end-of-frame poses against
///    rapier's pairs with `dist < 0`. A pair in both agrees. A pair only Ricochet has agrees
///    when its depth is at most `tol`; a pair only rapier has agrees when its `dist` is at
///    least `-(threshold + tol)`, the threshold being `SLOP` for a `separate` pair (Ricochet
///    leaves such pairs up to `SLOP` deep, and the per-axis passes leave box pairs flush, so
///    this is where a box left inside a tile would show) and 0 otherwise.
/// 4. **Rapier's cached contact points:** parry updates a pair's contact points from the
///    previous frame's when the shapes moved little relative to each other along the old
///    normal (`ContactManifold::try_update_contacts`), and only recomputes them when the sign
///    of a distance flips. Two `report` boxes that slide right through each other therefore
///    stay "penetrating" in rapier, ever deeper along the stale normal, after they have
///    separated (measured: depth 1.65 for two 0.8-wide boxes 0.05 apart). A pair left over
///    after step 3 is queried afresh by parry (`query::contact` at the end-of-frame poses,
///    no cache); when that answer agrees with Ricochet's it is counted as `rapier_cached`,
///    not as a disagreement.
#[must_use]
pub fn compare_contacts(
    sim: &Simulation,
    out: &FrameOutput,
    rapier: &BTreeMap<(Entity, Entity), f64>,
    tol: f64,
) -> ContactAgreement {
    let mut report = ContactAgreement::default();
    let w = &sim.world;
    let layers = &sim.scenario.world.layers;
    let frame = out.frame;
    let wrapped = |e: Entity| -> bool {
        let (Some(b), Some(i)) = (sim.scenario.world.bounds, w.index_of(e)) else {
            return false;
        };
        let size = b.max - b.min;
        let moved = (w.position[i] - w.start_position[i]).abs();
        b.wrap && (moved.x > 0.5 * size.x || moved.y > 0.5 * size.y)
    };
    let end_pose = |e: Entity| w.index_of(e).map(|i| w.pose(i));
    let at_end =
        |c: &ContactRecord| end_pose(c.a) == Some(c.pose_a) && end_pose(c.b) == Some(c.pose_b);

    let mut ricochet: BTreeMap<(Entity, Entity), f64> = BTreeMap::new();
    let mut covered: BTreeSet<(Entity, Entity)> = BTreeSet::new();
    let mut elsewhere: BTreeSet<(Entity, Entity)> = BTreeSet::new();
    for c in &out.contacts {
        let key = (c.a, c.b);
        if wrapped(c.a) || wrapped(c.b) {
            report.excluded += 1;
            continue;
        }
        if c.phase == Phase::Swept {
            covered.insert(key);
        }
        if at_end(c) {
            let depth = ricochet.entry(key).or_insert(f64::NEG_INFINITY);
            *depth = depth.max(c.depth);
            continue;
        }
        elsewhere.insert(key);
        check_at_record_poses(sim, out, c, tol, &mut report);
    }

    let keys: BTreeSet<(Entity, Entity)> = ricochet.keys().chain(rapier.keys()).copied().collect();
    for key in keys {
        let (ea, eb) = key;
        if wrapped(ea) || wrapped(eb) {
            report.excluded += 1;
            continue;
        }
        let name = |e: Entity| {
            body(sim, out, e).map_or_else(|| format!("#{e}"), |b| format!("{} #{e}", b.name))
        };
        match (ricochet.get(&key), rapier.get(&key)) {
            (Some(_), Some(_)) => {
                report.both += 1;
                report.agree();
            }
            (None, Some(_)) if covered.contains(&key) => {
                report.both += 1;
                report.agree();
            }
            (Some(&depth), None) => {
                if depth <= tol {
                    report.touching += 1;
                    report.agree();
                    continue;
                }
                match fresh_depth(sim, out, key, tol) {
                    Ok(fresh) if fresh > tol => {
                        report.rapier_cached += 1;
                        report.agree();
                    }
                    fresh => report.disagree(true, || {
                        format!(
                            "frame {frame}: {} / {}: Ricochet depth {depth:e} at the end of \
                             the frame; rapier finds no penetration (a fresh parry query: {})",
                            name(ea),
                            name(eb),
                            describe(&fresh)
                        )
                    }),
                }
            }
            (None, Some(&dist)) => {
                let response = match (body(sim, out, ea), body(sim, out, eb)) {
                    (Some(a), Some(b)) => layers.response(a.layer, b.layer),
                    _ => Response::Ignore,
                };
                let threshold = if response == Response::Separate {
                    SLOP
                } else {
                    0.0
                };
                if dist >= -(threshold + tol) {
                    report.touching += 1;
                    report.agree();
                    continue;
                }
                let fresh = fresh_depth(sim, out, key, tol);
                if matches!(fresh, Ok(d) if d <= threshold + tol) {
                    report.rapier_cached += 1;
                    report.agree();
                } else {
                    let logged = if elsewhere.contains(&key) {
                        "Ricochet logged it only at other poses"
                    } else {
                        "Ricochet logged no contact"
                    };
                    report.disagree(false, || {
                        format!(
                            "frame {frame}: {} / {}: rapier depth {:e} ({} response) at the \
                             end of the frame (a fresh parry query: {}); {logged}",
                            name(ea),
                            name(eb),
                            -dist,
                            response.name(),
                            describe(&fresh)
                        )
                    });
                }
            }
            (None, None) => {}
        }
    }
    report
}

/// Parry's exact depth of a pair at the end-of-frame poses, queried afresh (`-inf` when the
/// shapes are further apart than `tol`): what rapier's narrow phase would say without the
/// contact points it keeps from earlier frames.
fn fresh_depth(
    sim: &Simulation,
    out: &FrameOutput,
    (ea, eb): (Entity, Entity),
    tol: f64,
) -> Result<f64, OracleError> {
    let w = &sim.world;
    let (Some(a), Some(b), Some(ia), Some(ib)) = (
        body(sim, out, ea),
        body(sim, out, eb),
        w.index_of(ea),
        w.index_of(eb),
    ) else {
        return Err(OracleError::Conversion("a body of the pair is gone"));
    };
    Ok(
        reference_contact(a.shape, &w.pose(ia), b.shape, &w.pose(ib), tol)?
            .map_or(f64::NEG_INFINITY, |r| r.depth),
    )
}

fn describe(fresh: &Result<f64, OracleError>) -> String {
    match fresh {
        Ok(d) if *d == f64::NEG_INFINITY => "apart".to_owned(),
        Ok(d) => format!("depth {d:e}"),
        Err(e) => e.to_string(),
    }
}

/// Step 2 of [`compare_contacts`]: a record at poses other than the end of the frame,
/// recomputed by parry at those poses.
fn check_at_record_poses(
    sim: &Simulation,
    out: &FrameOutput,
    c: &ContactRecord,
    tol: f64,
    report: &mut ContactAgreement,
) {
    let frame = out.frame;
    let (Some(a), Some(b)) = (body(sim, out, c.a), body(sim, out, c.b)) else {
        report.disagree(true, || {
            format!(
                "frame {frame}: contact #{} #{} names an unknown body",
                c.a, c.b
            )
        });
        return;
    };
    let prediction = tol + (-c.depth).max(0.0);
    let who = || {
        format!(
            "frame {frame}: {} #{} / {} #{} (phase {})",
            a.name,
            c.a,
            b.name,
            c.b,
            c.phase.name()
        )
    };
    match reference_contact(a.shape, &c.pose_a, b.shape, &c.pose_b, prediction) {
        Ok(Some(r)) if (r.depth - c.depth).abs() <= tol => {
            report.at_record_poses += 1;
            report.agree();
        }
        Ok(Some(r)) => report.disagree(true, || {
            format!(
                "{}: depth {:e} at the record's poses, parry {:e}",
                who(),
                c.depth,
                r.depth
            )
        }),
        Ok(None) => report.disagree(true, || {
            format!(
                "{}: depth {:e} at the record's poses, parry finds the shapes apart",
                who(),
                c.depth
            )
        }),
        Err(e) => report.disagree(true, || format!("{}: {e}", who())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ricochet_geom::Vec2;

    fn shapes() -> Vec<Shape> {
        vec![
            Shape::circle(0.5).unwrap(),
            Shape::Primitive(Primitive::circle(Vec2::new(0.3, -0.2), 0.5).unwrap()),
            Shape::aabb(Vec2::new(0.5, 0.25)).unwrap(),
            Shape::Primitive(Primitive::aabb(Vec2::new(0.1, 0.4), Vec2::new(0.5, 0.25)).unwrap()),
            Shape::obb(Vec2::new(0.5, 0.25)).unwrap(),
            Shape::Primitive(
                Primitive::obb(Vec2::new(0.2, 0.1), Vec2::new(0.5, 0.25), 0.3).unwrap(),
            ),
            Shape::capsule(Vec2::new(-0.5, 0.0), Vec2::new(0.5, 0.1), 0.2).unwrap(),
            Shape::polygon(&[
                Vec2::new(0.0, 0.0),
                Vec2::new(1.0, 0.1),
                Vec2::new(0.4, 0.9),
            ])
            .unwrap(),
        ]
    }

    #[test]
    fn collider_poses_are_the_referees_placement() {
        let pose = Pose::new(Vec2::new(3.25, -7.5), 0.7);
        for s in shapes() {
            let (expected, _) = place(&s, &pose, Vec2::ZERO).unwrap();
            assert_eq!(collider_pose(&s, &pose).unwrap(), expected, "{s:?}");
        }
    }

    const SMALL_SCENE: &str = r#"
layers = ["a", "b"]
collide = [{ a = "a", b = "b", response = "report" }]
[[bodies]]
layer = "a"
shape = { kind = "circle", radius = 0.5 }
velocity = [1, 0]
[[bodies]]
layer = "b"
kind = "static"
shape = { kind = "aabb", half_extents = [0.5, 0.5] }
position = [0.8, 0]
[[bodies]]
layer = "b"
shape = { kind = "polygon", vertices = [[0, 0], [1, 0], [0, 1]] }
position = [10, 0]
"#;

    /// Two bodies overlapping by 0.2 along x and a third far away: rapier finds exactly the
    /// overlapping pair, and the comparison agrees with Ricochet's frame.
    #[test]
    fn rapier_and_ricochet_agree_on_a_small_scene() {
        let scenario = ricochet_sim::load_scenario(SMALL_SCENE, "t.toml").unwrap();
        let mut sim = Simulation::new(&scenario);
        let mut rapier = RapierScene::new(&sim).unwrap();
        for _ in 0..3 {
            let out = sim.step();
            rapier.sync(&sim).unwrap();
            rapier.step();
            let pairs = rapier.penetrating();
            assert_eq!(pairs.len(), 1, "{pairs:?}");
            let agreement = compare_contacts(&sim, &out, &pairs, CONTACT_TOLERANCE);
            assert!(agreement.all_agree(), "{agreement:?}");
            assert_eq!(agreement.both, 1);
        }
    }

    /// The comparison catches a Ricochet that misses a contact, invents one, or logs a wrong
    /// depth at other poses.
    #[test]
    fn a_missing_invented_or_wrong_contact_is_a_disagreement() {
        let scenario = ricochet_sim::load_scenario(SMALL_SCENE, "t.toml").unwrap();
        let mut sim = Simulation::new(&scenario);
        let mut rapier = RapierScene::new(&sim).unwrap();
        let out = sim.step();
        rapier.sync(&sim).unwrap();
        rapier.step();
        let pairs = rapier.penetrating();
        assert_eq!(out.contacts.len(), 1);

        let mut missing = out.clone();
        missing.contacts.clear();
        let a = compare_contacts(&sim, &missing, &pairs, CONTACT_TOLERANCE);
        assert_eq!((a.compared, a.rapier_only), (1, 1), "{a:?}");
        assert!(a.details[0].contains("Ricochet logged no contact"), "{a:?}");

        let mut invented = out.clone();
        let mut fake = invented.contacts[0].clone();
        fake.b = sim.world.entity[2];
        fake.pose_b = sim.world.pose(2);
        invented.contacts.push(fake);
        let a = compare_contacts(&sim, &invented, &pairs, CONTACT_TOLERANCE);
        assert_eq!((a.compared, a.ricochet_only, a.agreed), (2, 1, 1), "{a:?}");

        let mut wrong = out.clone();
        wrong.contacts[0].pose_a.position.x -= 0.05;
        let a = compare_contacts(&sim, &wrong, &pairs, CONTACT_TOLERANCE);
        // The record no longer sits at the end-of-frame poses: checked at its own poses
        // (wrong depth there), and rapier's end-of-frame pair is then missing from Ricochet.
        assert_eq!((a.ricochet_only, a.rapier_only), (1, 1), "{a:?}");
    }

    /// Kinematic and static bodies never collide with each other in Ricochet; rapier is set
    /// up the same way (only dynamic bodies' colliders enable fixed–fixed pairs).
    #[test]
    fn pairs_without_a_dynamic_body_are_not_tested_by_either_engine() {
        let text = r#"
layers = ["a"]
collide = [{ a = "a", b = "a", response = "report" }]
[[bodies]]
layer = "a"
kind = "kinematic"
shape = { kind = "circle", radius = 0.5 }
velocity = [1, 0]
[[bodies]]
layer = "a"
kind = "static"
shape = { kind = "aabb", half_extents = [0.5, 0.5] }
position = [0.5, 0]
[[bodies]]
layer = "a"
kind = "static"
shape = { kind = "circle", radius = 0.5 }
position = [0.5, 0.5]
"#;
        let scenario = ricochet_sim::load_scenario(text, "t.toml").unwrap();
        let mut sim = Simulation::new(&scenario);
        let mut rapier = RapierScene::new(&sim).unwrap();
        for _ in 0..2 {
            let out = sim.step();
            rapier.sync(&sim).unwrap();
            rapier.step();
            assert!(out.contacts.is_empty());
            assert!(rapier.penetrating().is_empty());
        }
    }
}
