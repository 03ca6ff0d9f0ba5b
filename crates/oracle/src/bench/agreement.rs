//! [`compare_contacts`]: whether one frame's contact sets agree, by the rule documented on it.

use std::collections::{BTreeMap, BTreeSet};

use ricochet_sim::{ContactRecord, Entity, FrameOutput, Response, Simulation};

use super::MAX_AGREEMENT_DETAILS;
use super::frame_pairs::{FramePairs, threshold, wrapped};
#[cfg(doc)]
use super::{CONTACT_TOLERANCE, RapierScene};
use crate::OracleError;
use crate::convert::depth;
use crate::referee::{Recheck, body, recheck};

/// How one frame's (or a whole run's) contact sets compare. Every compared item either
/// agrees or is counted as a disagreement with a sentence in `details`. Serialisable: the
/// bench sends it from the process that ran the scene.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
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
    let layers = &sim.scenario().world.layers;
    let frame = out.frame;
    let FramePairs {
        at_end: ricochet,
        swept: covered,
        elsewhere,
        excluded,
    } = FramePairs::of(sim, out, |c| {
        check_at_record_poses(sim, out, c, tol, &mut report);
    });
    report.excluded += excluded;
    let wrapped = |e: Entity| wrapped(sim, e);

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
                let threshold = threshold(response);
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
    let w = sim.world();
    let (Some(a), Some(b), Some(ia), Some(ib)) = (
        body(sim, out, ea),
        body(sim, out, eb),
        w.index_of(ea),
        w.index_of(eb),
    ) else {
        return Err(OracleError::Conversion("a body of the pair is gone"));
    };
    depth(a.shape, &w.pose(ia), b.shape, &w.pose(ib), tol)
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
    match recheck(a.shape, b.shape, c, tol) {
        Ok(Recheck::Agrees(_)) => {
            report.at_record_poses += 1;
            report.agree();
        }
        Ok(Recheck::Differs(r)) => report.disagree(true, || {
            format!(
                "{}: depth {:e} at the record's poses, parry {:e}",
                who(),
                c.depth,
                r.depth
            )
        }),
        Ok(Recheck::Apart) => report.disagree(true, || {
            format!(
                "{}: depth {:e} at the record's poses, parry finds the shapes apart",
                who(),
                c.depth
            )
        }),
        Err(e) => report.disagree(true, || format!("{}: {e}", who())),
    }
}
