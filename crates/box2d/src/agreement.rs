//! [`compare_box2d`]: whether one frame's contact set agrees with Box2D's, by the rule
//! documented on it.

use std::collections::{BTreeMap, BTreeSet};

use ricochet_oracle::bench::{FramePairs, threshold, wrapped};
use ricochet_sim::{Entity, FrameOutput, Response, Simulation};

use crate::MAX_AGREEMENT_DETAILS;
#[cfg(doc)]
use crate::{BOX2D_CONTACT_TOLERANCE, Box2dScene};

/// How one frame's (or a whole run's) contact set compares with Box2D's. Every compared pair
/// either agrees or is counted as a disagreement with a sentence in `details`. Serialisable:
/// the bench sends it from the process that ran the scene.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Box2dAgreement {
    /// End-of-frame pairs compared (from either engine).
    pub compared: u64,
    /// Pairs on which the engines agree (`both + touching + swept`).
    pub agreed: u64,
    /// Pairs penetrating in both engines at the end of the frame.
    pub both: u64,
    /// Pairs in one engine only, within the tolerance of touching (see [`compare_box2d`]).
    pub touching: u64,
    /// Pairs Box2D finds penetrating at the end of the frame that a Ricochet swept test
    /// touched during the frame.
    pub swept: u64,
    /// Ricochet contact records at poses other than the end of the frame (`x`, `y`, `swept`,
    /// a body's image through the wrap seam): not compared, Box2D only sees the end-of-frame
    /// poses (the rapier column checks them at their own poses).
    pub other_poses: u64,
    /// Pairs and records left out because a body of the pair wrapped round the world after
    /// `detect` (Box2D sees it on the other side).
    pub excluded: u64,
    /// Disagreements where Ricochet found a penetration Box2D does not report.
    pub ricochet_only: u64,
    /// Disagreements where Box2D reports a penetration Ricochet did not log.
    pub box2d_only: u64,
    /// The largest `|Ricochet depth - Box2D depth|` over the pairs in both (Box2D's depth is
    /// minus its manifold's smallest separation). A figure, not a criterion: see
    /// [`compare_box2d`].
    pub max_depth_difference: f64,
    /// The first [`MAX_AGREEMENT_DETAILS`] disagreements, one sentence each.
    pub details: Vec<String>,
}

impl Box2dAgreement {
    /// Whether every compared pair agreed.
    #[must_use]
    pub fn all_agree(&self) -> bool {
        self.agreed == self.compared
    }

    /// Adds another frame's counts (and details, up to the limit).
    pub fn add(&mut self, other: &Box2dAgreement) {
        self.compared += other.compared;
        self.agreed += other.agreed;
        self.both += other.both;
        self.touching += other.touching;
        self.swept += other.swept;
        self.other_poses += other.other_poses;
        self.excluded += other.excluded;
        self.ricochet_only += other.ricochet_only;
        self.box2d_only += other.box2d_only;
        self.max_depth_difference = self.max_depth_difference.max(other.max_depth_difference);
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
            self.box2d_only += 1;
        }
        if self.details.len() < MAX_AGREEMENT_DETAILS {
            self.details.push(detail());
        }
    }
}

/// Compares one frame's contacts with the pairs Box2D reports touching at the end-of-frame
/// poses (`box2d` from [`Box2dScene::touching`], after [`Box2dScene::sync`] and
/// [`Box2dScene::step`] on the same `sim`: the smallest manifold separation of each pair).
/// `tol` is normally [`BOX2D_CONTACT_TOLERANCE`].
///
/// Box2D reports a pair as touching from a separation of `+0.02` (its speculative margin,
/// `4 × linear slop`), and computes it in `f32` relative to the pair; its polygons have no
/// skin (radius 0), so a manifold's smallest separation is minus the penetration depth. The
/// rule compares penetrations:
/// 1. **Excluded:** pairs (and records) with a body that the `bounds` stage wrapped round the
///    world this frame (it moved by more than half the world on an axis): Ricochet detected it
///    before the wrap, Box2D sees it on the other side.
/// 2. **Records at other poses** (`x` and `y`, whose bodies the per-axis passes moved before
///    `detect`; `swept`, logged at the time of impact; a pair met through the wrap seam, logged
///    at a body's image): counted in `other_poses` and not compared, since Box2D only ever
///    sees the end-of-frame poses. A `swept` record covers a penetration Box2D finds at the end
///    of the frame (the pair touched during the frame).
/// 3. **End-of-frame sets:** Ricochet's pairs with a record at the end-of-frame poses against
///    Box2D's pairs with a separation below 0. A pair in both agrees (`both`). A pair only
///    Ricochet has agrees when its depth is at most `tol`; a pair only Box2D has agrees when
///    its separation is at least `-(threshold + tol)`, the threshold being `SLOP` for a
///    `separate` pair and 0 otherwise (`touching`): this is where a box left inside a tile
///    would show. Anything else is a disagreement.
///
/// Depths are compared only as a figure (`max_depth_difference`): Box2D's manifold is built
/// for its solver, not as a minimum translation (its points are the incident edge clipped to
/// the reference face, a capsule's core clipped likewise), so its deepest point can differ
/// from the penetration depth even where both engines agree that the pair penetrates
/// (measured: 4 capsule pairs of 64 594 on `rain-10000` differ by more than `1e-5`, at most by
/// `4.9e-4`).
#[must_use]
pub fn compare_box2d(
    sim: &Simulation,
    out: &FrameOutput,
    box2d: &BTreeMap<(Entity, Entity), f64>,
    tol: f64,
) -> Box2dAgreement {
    let mut report = Box2dAgreement::default();
    let w = sim.world();
    let layers = &sim.scenario().world.layers;
    let frame = out.frame;
    let FramePairs {
        at_end: ricochet,
        swept: covered,
        elsewhere,
        excluded,
    } = FramePairs::of(sim, out, |_| report.other_poses += 1);
    report.excluded += excluded;
    let wrapped = |e: Entity| wrapped(sim, e);

    let penetrating = box2d.iter().filter(|&(_, &s)| s < 0.0).map(|(k, _)| *k);
    let keys: BTreeSet<(Entity, Entity)> = ricochet.keys().copied().chain(penetrating).collect();
    for key in keys {
        let (ea, eb) = key;
        if wrapped(ea) || wrapped(eb) {
            report.excluded += 1;
            continue;
        }
        let name = |e: Entity| {
            w.index_of(e)
                .map_or_else(|| format!("#{e}"), |i| format!("{} #{e}", w.name(i)))
        };
        let separation = box2d.get(&key).copied().filter(|&s| s < 0.0);
        match (ricochet.get(&key), separation) {
            (Some(&depth), Some(s)) => {
                report.both += 1;
                report.max_depth_difference = report.max_depth_difference.max((depth + s).abs());
                report.agree();
            }
            (Some(&depth), None) => {
                if depth <= tol {
                    report.touching += 1;
                    report.agree();
                    continue;
                }
                let theirs = box2d.get(&key).map_or_else(
                    || "no touching contact".to_owned(),
                    |s| format!("a touching contact {s:e} apart"),
                );
                report.disagree(true, || {
                    format!(
                        "frame {frame}: {} / {}: Ricochet depth {depth:e} at the end of the \
                         frame; Box2D reports {theirs}",
                        name(ea),
                        name(eb),
                    )
                });
            }
            (None, Some(s)) => {
                let response = match (w.index_of(ea), w.index_of(eb)) {
                    (Some(a), Some(b)) => layers.response(w.layer[a], w.layer[b]),
                    _ => Response::Ignore,
                };
                if covered.contains(&key) {
                    report.swept += 1;
                    report.agree();
                } else if s >= -(threshold(response) + tol) {
                    report.touching += 1;
                    report.agree();
                } else {
                    let logged = if elsewhere.contains(&key) {
                        "Ricochet logged it only at other poses"
                    } else {
                        "Ricochet logged no contact"
                    };
                    report.disagree(false, || {
                        format!(
                            "frame {frame}: {} / {}: Box2D depth {:e} ({} response) at the end \
                             of the frame; {logged}",
                            name(ea),
                            name(eb),
                            -s,
                            response.name(),
                        )
                    });
                }
            }
            (None, None) => {}
        }
    }
    report
}
