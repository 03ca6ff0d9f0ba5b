//! The `detect` stage: broad phase, exact narrow phase, and the responses of the layer-pair
//! matrix at the frame's final poses.
//!
//! Broad phase: sort and sweep along x over every body's bounds. A candidate pair is dropped
//! before the narrow phase when neither body can move (static or kinematic against static or
//! kinematic), when its layers `ignore` each other (counted in `pairs_ignored_by_layer`), or
//! when two boxes `separate` (the per-axis stages own those). The rest are tested exactly, in
//! `(a, b)` id order, and respond:
//! - `report`: the contact is logged and a `contact` event raised;
//! - `destroy`: the doomed bodies are removed after the pass (children of a split spawned);
//! - `separate`: the dynamic body is pushed out along the normal by the depth (two dynamic
//!   bodies half each), and its velocity into the other is removed.

use ricochet_geom::{Bounds, Vec2, contact};

use crate::def::{BodyKind, Doomed, Response};
use crate::entity::Entity;
use crate::output::{ContactRecord, EventRecord, FrameOutput, Phase};
use crate::pipeline::{SLOP, Simulation};
use crate::stages::remove::remove;
use crate::stages::separate::is_box;

pub(crate) fn has_work(sim: &Simulation) -> bool {
    sim.world.len() >= 2 && sim.scenario.world.layers.any(|r| r != Response::Ignore)
}

/// Candidate pairs `(i, j)`, `i < j` (dense index order is id order), whose bounds overlap.
fn sweep(bounds: &[Bounds]) -> Vec<(usize, usize)> {
    let mut order: Vec<usize> = (0..bounds.len()).collect();
    // total_cmp and the index as tie-break: a deterministic order even with equal keys.
    order.sort_by(|&p, &q| bounds[p].min.x.total_cmp(&bounds[q].min.x).then(p.cmp(&q)));
    let mut pairs = Vec::new();
    for (k, &p) in order.iter().enumerate() {
        for &q in &order[k + 1..] {
            if bounds[q].min.x > bounds[p].max.x {
                break;
            }
            if bounds[p].overlaps(&bounds[q]) {
                pairs.push((p.min(q), p.max(q)));
            }
        }
    }
    pairs.sort_unstable();
    pairs
}

pub(crate) fn run(sim: &mut Simulation, out: &mut FrameOutput) {
    let layers = sim.scenario.world.layers.clone();
    let w = &sim.world;
    if sim.capture_detect_poses {
        out.detect_poses = Some((0..w.len()).map(|i| (w.entity[i], w.pose(i))).collect());
    }
    let bounds: Vec<Bounds> = (0..w.len())
        .map(|i| w.shape[i].bounds(&w.pose(i)))
        .collect();
    let pairs = sweep(&bounds);
    let mut doomed: Vec<(Entity, String)> = Vec::new();
    for (i, j) in pairs {
        let w = &sim.world;
        if w.kind[i] != BodyKind::Dynamic && w.kind[j] != BodyKind::Dynamic {
            continue;
        }
        let response = layers.response(w.layer[i], w.layer[j]);
        if response == Response::Ignore {
            out.stats.pairs_ignored_by_layer += 1;
            continue;
        }
        if response == Response::Separate && is_box(&w.shape[i]) && is_box(&w.shape[j]) {
            continue;
        }
        out.stats.broad_pairs += 1;
        out.stats.narrow_tests += 1;
        let (la, lb) = (w.layer[i].min(w.layer[j]), w.layer[i].max(w.layer[j]));
        *out.stats
            .tests_by_layer_pair
            .entry(format!("{}/{}", layers.name(la), layers.name(lb)))
            .or_default() += 1;
        let (pose_a, pose_b) = (w.pose(i), w.pose(j));
        let c = contact(&w.shape[i], &pose_a, &w.shape[j], &pose_b);
        let threshold = if response == Response::Separate {
            SLOP
        } else {
            0.0
        };
        if c.depth <= threshold {
            continue;
        }
        let mut resolved = Vec2::ZERO;
        let (ea, eb) = (w.entity[i], w.entity[j]);
        let (na, nb) = (w.name[i].clone(), w.name[j].clone());
        match response {
            Response::Ignore => {}
            Response::Report => out.events.push(EventRecord {
                kind: "contact",
                message: format!("{na} #{ea} touches {nb} #{eb}, depth {}", c.depth),
            }),
            Response::Destroy(which) => {
                let why = format!("hit by {nb} #{eb}");
                let why_b = format!("hit by {na} #{ea}");
                if matches!(which, Doomed::First | Doomed::Both) {
                    doomed.push((ea, why));
                }
                if matches!(which, Doomed::Second | Doomed::Both) {
                    doomed.push((eb, why_b));
                }
            }
            Response::Separate => {
                resolved = separate_along_normal(sim, i, j, c.normal, c.depth);
                let w = &sim.world;
                out.events.push(EventRecord {
                    kind: "hit",
                    message: format!(
                        "{} #{ea} and {} #{eb} pushed apart by {}",
                        w.name[i], w.name[j], c.depth
                    ),
                });
            }
        }
        out.contacts.push(ContactRecord {
            a: ea,
            b: eb,
            phase: Phase::All,
            normal: c.normal,
            depth: c.depth,
            point: c.point,
            pose_a,
            pose_b,
            response,
            resolved,
        });
    }
    doomed.sort();
    doomed.dedup_by_key(|(e, _)| *e);
    for (e, why) in doomed {
        remove(sim, out, e, "destroy", &why, true);
    }
}

/// Pushes the dynamic body (or both, half each) apart along `normal` (from `i` to `j`), and
/// removes the velocity that drives them into each other. Returns the push on the body that
/// moved (`j`'s when both did).
fn separate_along_normal(
    sim: &mut Simulation,
    i: usize,
    j: usize,
    normal: Vec2,
    depth: f64,
) -> Vec2 {
    let w = &mut sim.world;
    let (di, dj) = (
        w.kind[i] == BodyKind::Dynamic,
        w.kind[j] == BodyKind::Dynamic,
    );
    let share = if di && dj { 0.5 } else { 1.0 };
    let mut pushed = Vec2::ZERO;
    if di {
        let p = -normal * (depth * share);
        w.position[i] += p;
        let vn = w.velocity[i].dot(normal);
        if vn > 0.0 {
            w.velocity[i] -= normal * vn;
        }
        if normal.y < -0.7 {
            w.grounded[i] = true;
        }
        pushed = p;
    }
    if dj {
        let p = normal * (depth * share);
        w.position[j] += p;
        let vn = w.velocity[j].dot(normal);
        if vn < 0.0 {
            w.velocity[j] -= normal * vn;
        }
        if normal.y > 0.7 {
            w.grounded[j] = true;
        }
        pushed = p;
    }
    pushed
}
