//! The `detect` stage: broad phase, exact narrow phase, and the responses of the layer-pair
//! matrix at the frame's final poses.
//!
//! Broad phase: [`crate::broad_phase`], chosen by the scenario's `broad_phase` (automatic
//! by default), fed with every body's bounds ([`World::bounds`]). Layers that `ignore` each
//! other are never paired (a layer that ignores itself is never swept against itself), and
//! static and kinematic bodies never pair with each other: those pairs are never produced,
//! so never counted. Static bodies are handed over only when they change
//! ([`World::static_generation`]). A candidate pair is then dropped before the narrow phase
//! when a body is frozen outside the active region, when both are at rest (asleep or
//! static), or when two boxes `separate` (the per-axis stages own those). The rest are
//! tested exactly, in `(a, b)` id order, and respond:
//! - `report`: the contact is logged and a `contact` event raised;
//! - `destroy`: the doomed bodies are removed after the pass (children of a split spawned);
//! - `separate`: the dynamic body is pushed out along the normal by the depth (two dynamic
//!   bodies half each), and its velocity into the other is removed.
//!
//! A sleeping body that touches an awake one wakes up (from the next frame on).
//!
//! Swept pairs (a layer in `fast_layers`, or `sweep = true` on the `[[collide]]` entry;
//! `report` and `destroy` only) are bounded over the whole frame's motion and tested by time
//! of impact instead: each moving body's hits are taken in time order and it stops at the
//! first that destroys it, so a bullet never passes through a rock, and hits the first one
//! on its path. Rotation during the frame is not swept (the end angles are used).

use ricochet_geom::{Contact, Pose, Shape, Vec2, contact};

use crate::broad_phase::{BodyEntry, BroadPhase, BroadPhaseKind, Interactions};
use crate::def::{BodyKind, Doomed, Layers, Response};
use crate::entity::Entity;
use crate::event::{GameEvent, Removal};
use crate::output::{ContactRecord, FrameOutput, Phase};
use crate::pipeline::{SLOP, Simulation};
use crate::stages::remove::remove;
use crate::stages::separate::is_box;

pub(crate) fn has_work(sim: &Simulation) -> bool {
    sim.world.len() >= 2 && sim.scenario.world.layers.any(|r| r != Response::Ignore)
}

/// What `detect` keeps from one frame to the next: the broad phase (its sorted lists and
/// static structures) and reused buffers.
#[derive(Debug)]
pub(crate) struct DetectState {
    broad_phase: BroadPhase,
    /// Layer pairs `detect` tests: not `ignore`, and not `separate` between two layers of
    /// boxes only (the per-axis stages own those). Rebuilt when `box_only` changes.
    interactions: Interactions,
    /// Per layer, whether all its bodies were boxes when `interactions` was built.
    box_only: Vec<bool>,
    layers: Layers,
    /// Layers with a swept pair.
    sweeping: Vec<bool>,
    /// The static generation `statics` was built at.
    static_generation: Option<u64>,
    statics: Vec<BodyEntry>,
    movers: Vec<BodyEntry>,
    pairs: Vec<(u32, u32)>,
    /// Narrow-phase tests per layer pair this frame, `[a * n + b]`.
    tests: Vec<u64>,
}

impl DetectState {
    pub(crate) fn new(layers: &Layers, kind: BroadPhaseKind) -> DetectState {
        let n = layers.names().len();
        let box_only = vec![false; n];
        DetectState {
            broad_phase: BroadPhase::new(kind),
            interactions: interactions(layers, &box_only),
            box_only,
            layers: layers.clone(),
            sweeping: (0..n)
                .map(|l| (0..n).any(|m| layers.sweeps(l as u8, m as u8)))
                .collect(),
            static_generation: None,
            statics: Vec::new(),
            movers: Vec::new(),
            pairs: Vec::new(),
            tests: vec![0; n * n],
        }
    }
}

fn interactions(layers: &Layers, box_only: &[bool]) -> Interactions {
    Interactions::from_fn(box_only.len(), |a, b| match layers.response(a, b) {
        Response::Ignore => false,
        Response::Separate => !(box_only[usize::from(a)] && box_only[usize::from(b)]),
        _ => true,
    })
}

/// Fills the broad phase's inputs and finds the candidate pairs (dense indices, sorted).
fn candidate_pairs(sim: &mut Simulation, out: &mut FrameOutput) -> Vec<(u32, u32)> {
    let st = &mut sim.detect;
    let w = &mut sim.world;
    let changed = (0..st.box_only.len()).any(|l| st.box_only[l] != w.only_boxes(l as u8));
    if changed {
        for (l, b) in st.box_only.iter_mut().enumerate() {
            *b = w.only_boxes(l as u8);
        }
        st.interactions = interactions(&st.layers, &st.box_only);
    }
    if st.static_generation != Some(w.static_generation()) {
        st.statics.clear();
        for i in 0..w.len() {
            if w.kind[i] == BodyKind::Static {
                let bounds = w.bounds(i);
                st.statics.push(BodyEntry {
                    key: w.key(i),
                    bounds,
                    layer: w.layer[i],
                    kind: BodyKind::Static,
                });
            }
        }
    }
    w.mover_entries(&st.sweeping, &mut st.movers);
    let generation = w.static_generation();
    let mut pairs = std::mem::take(&mut st.pairs);
    let bp = st.broad_phase.pairs_split(
        &st.statics,
        generation,
        &st.movers,
        &st.interactions,
        &mut pairs,
    );
    st.static_generation = Some(generation);
    out.stats.broad_phase = Some(bp.kind);
    out.stats.layer_pairs_skipped += bp.layer_pairs_skipped;
    pairs
}

pub(crate) fn run(sim: &mut Simulation, out: &mut FrameOutput) {
    let layers = sim.scenario.world.layers.clone();
    if sim.capture_detect_poses {
        let w = &sim.world;
        out.detect_poses = Some((0..w.len()).map(|i| (w.entity[i], w.pose(i))).collect());
    }
    let pairs = candidate_pairs(sim, out);
    // Tests per layer pair, counted in a flat table and listed once at the end.
    let n_layers = layers.names().len();
    let mut per_layer_pair = std::mem::take(&mut sim.detect.tests);
    // Each doomed body with the body that hit it.
    let mut doomed: Vec<(Entity, Entity)> = Vec::new();
    let mut swept: Vec<(usize, usize)> = Vec::new();
    let mut woken: Vec<usize> = Vec::new();
    for &(i, j) in &pairs {
        let (i, j) = (i as usize, j as usize);
        let w = &sim.world;
        let resting = |k: usize| w.kind[k] == BodyKind::Static || w.asleep[k];
        if w.frozen[i] || w.frozen[j] || (resting(i) && resting(j)) {
            continue;
        }
        let response = layers.response(w.layer[i], w.layer[j]);
        if response == Response::Separate && is_box(&w.shape[i]) && is_box(&w.shape[j]) {
            continue;
        }
        out.stats.broad_pairs += 1;
        let (la, lb) = (w.layer[i].min(w.layer[j]), w.layer[i].max(w.layer[j]));
        per_layer_pair[usize::from(la) * n_layers + usize::from(lb)] += 1;
        if response != Response::Separate && layers.sweeps(w.layer[i], w.layer[j]) {
            swept.push((i, j));
            continue;
        }
        out.stats.narrow_tests += 1;
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
        woken.extend([i, j].into_iter().filter(|&k| w.asleep[k]));
        respond(
            sim,
            out,
            &mut doomed,
            (i, j),
            response,
            Phase::All,
            c,
            (pose_a, pose_b),
        );
    }
    sim.detect.pairs = pairs;
    for (k, count) in per_layer_pair.iter_mut().enumerate() {
        if *count > 0 {
            let (la, lb) = ((k / n_layers) as u8, (k % n_layers) as u8);
            out.stats.tests_by_layer_pair.push(((la, lb), *count));
            *count = 0;
        }
    }
    sim.detect.tests = per_layer_pair;
    run_swept(sim, out, &mut doomed, &swept, &layers, &mut woken);
    for i in woken {
        sim.world.wake(i);
    }
    // In id order; a body hit twice is destroyed by the first hit found.
    doomed.sort_by_key(|(e, _)| *e);
    doomed.dedup_by_key(|(e, _)| *e);
    for (e, by) in doomed {
        remove(sim, out, e, Removal::HitBy(by), true);
    }
}

/// Swept pairs: each pair's first touch along the frame's motion, then, per moving body,
/// its hits in time order, stopping at the first hit that destroys it. So a bullet hits the
/// first rock on its path and no other, however fast it goes.
fn run_swept(
    sim: &mut Simulation,
    out: &mut FrameOutput,
    doomed: &mut Vec<(Entity, Entity)>,
    swept: &[(usize, usize)],
    layers: &Layers,
    woken: &mut Vec<usize>,
) {
    struct Hit {
        mover: Entity,
        toi: f64,
        pair: (usize, usize),
        contact: Contact,
        poses: (Pose, Pose),
    }
    let mut hits = Vec::new();
    for &(i, j) in swept {
        out.stats.narrow_tests += 1;
        let w = &sim.world;
        if let Some((toi, contact, poses)) = time_of_impact(w, i, j) {
            // The mover is the body that went further: a bullet against a drifting rock.
            let travel = |k: usize| (w.position[k] - w.start_position[k]).length();
            let mover = if travel(j) > travel(i) {
                w.entity[j]
            } else {
                w.entity[i]
            };
            hits.push(Hit {
                mover,
                toi,
                pair: (i, j),
                contact,
                poses,
            });
        }
    }
    // Per mover, earliest first; ties by the pair's ids (dense order is id order).
    hits.sort_by(|a, b| {
        a.mover
            .cmp(&b.mover)
            .then(a.toi.total_cmp(&b.toi))
            .then(a.pair.cmp(&b.pair))
    });
    let mut spent: Vec<Entity> = Vec::new();
    for hit in hits {
        if spent.contains(&hit.mover) {
            continue;
        }
        let w = &sim.world;
        let response = layers.response(w.layer[hit.pair.0], w.layer[hit.pair.1]);
        woken.extend(
            [hit.pair.0, hit.pair.1]
                .into_iter()
                .filter(|&k| w.asleep[k]),
        );
        let before = doomed.len();
        respond(
            sim,
            out,
            doomed,
            hit.pair,
            response,
            Phase::Swept,
            hit.contact,
            hit.poses,
        );
        if doomed[before..].iter().any(|(e, _)| *e == hit.mover) {
            spent.push(hit.mover);
        }
    }
}

/// How close a swept test must get, relative to the smaller shape's size.
const TOI_TOLERANCE: f64 = 1e-9;

/// The first moment in `[0, 1]` of this frame's motion (both bodies moving in straight
/// lines from their start to their end positions, at their end angles) when bodies `i` and
/// `j` come within `tol` of touching. Returns the time, the contact there and the two poses.
///
/// Each pair of convex parts is searched on its own, and the earliest touch wins. With the
/// angles fixed, the signed distance between two convex parts is a convex function of `t`
/// (the distance from a point moving on a line to a convex set), which makes the search
/// exact: conservative advancement first (distance ÷ relative speed can never step past the
/// first touch, and is quick when heading straight in); if that crawls, as on a grazing
/// path, a golden-section search finds the closest approach, and bisection the first
/// moment before it within `tol`.
fn time_of_impact(w: &crate::World, i: usize, j: usize) -> Option<(f64, Contact, (Pose, Pose))> {
    let (si, sj) = (w.start_position[i], w.start_position[j]);
    let (di, dj) = (w.position[i] - si, w.position[j] - sj);
    let speed = (di - dj).length();
    let size = |k: usize| w.shape[k].bounds(&w.pose(k)).half_extents().length();
    let tol = TOI_TOLERANCE * size(i).min(size(j));
    let poses = |t: f64| {
        (
            Pose::new(si + di * t, w.angle[i]),
            Pose::new(sj + dj * t, w.angle[j]),
        )
    };
    let mut first: Option<f64> = None;
    for pa in w.shape[i].primitives() {
        for pb in w.shape[j].primitives() {
            let (sa, sb) = (Shape::Primitive(*pa), Shape::Primitive(*pb));
            let gap = |t: f64| {
                let (pa, pb) = poses(t);
                -contact(&sa, &pa, &sb, &pb).depth
            };
            if let Some(t) = first_touch(gap, speed, tol)
                && first.is_none_or(|f| t < f)
            {
                first = Some(t);
            }
        }
    }
    let t = first?;
    let (pa, pb) = poses(t);
    Some((t, contact(&w.shape[i], &pa, &w.shape[j], &pb), (pa, pb)))
}

/// The first `t` in `[0, 1]` with `gap(t) <= tol`, for a convex `gap`.
fn first_touch(gap: impl Fn(f64) -> f64, speed: f64, tol: f64) -> Option<f64> {
    let mut t = 0.0;
    let mut g = gap(t);
    for _ in 0..16 {
        if g <= tol {
            return Some(t);
        }
        if speed == 0.0 {
            return None;
        }
        t += g / speed;
        if t > 1.0 {
            return None;
        }
        g = gap(t);
    }
    if g <= tol {
        return Some(t);
    }
    // Closest approach on [t, 1] (a convex function is unimodal).
    const INV_PHI: f64 = 0.618_033_988_749_894_8;
    let (mut lo, mut hi) = (t, 1.0);
    for _ in 0..80 {
        let m1 = hi - (hi - lo) * INV_PHI;
        let m2 = lo + (hi - lo) * INV_PHI;
        if gap(m1) <= gap(m2) {
            hi = m2;
        } else {
            lo = m1;
        }
    }
    let closest = 0.5 * (lo + hi);
    if gap(closest) > tol {
        return None;
    }
    // The gap falls from above tol at t to at most tol at `closest`: bisect the crossing.
    let (mut above, mut below) = (t, closest);
    for _ in 0..80 {
        let mid = 0.5 * (above + below);
        if gap(mid) > tol {
            above = mid;
        } else {
            below = mid;
        }
    }
    Some(below)
}

/// Records a contact and applies its response.
#[expect(
    clippy::too_many_arguments,
    reason = "one call site per pass; a struct would only rename them"
)]
fn respond(
    sim: &mut Simulation,
    out: &mut FrameOutput,
    doomed: &mut Vec<(Entity, Entity)>,
    (i, j): (usize, usize),
    response: Response,
    phase: Phase,
    c: Contact,
    (pose_a, pose_b): (Pose, Pose),
) {
    let w = &sim.world;
    let mut resolved = Vec2::ZERO;
    let (ea, eb) = (w.entity[i], w.entity[j]);
    match response {
        Response::Ignore => {}
        Response::Report => out.events.push(GameEvent::Contact {
            a: ea,
            b: eb,
            depth: c.depth,
        }),
        Response::Destroy(which) => {
            if matches!(which, Doomed::First | Doomed::Both) {
                doomed.push((ea, eb));
            }
            if matches!(which, Doomed::Second | Doomed::Both) {
                doomed.push((eb, ea));
            }
        }
        Response::Separate => {
            resolved = separate_along_normal(sim, i, j, c.normal, c.depth);
            out.events.push(GameEvent::PushedApart {
                a: ea,
                b: eb,
                depth: c.depth,
            });
        }
    }
    out.contacts.push(ContactRecord {
        a: ea,
        b: eb,
        phase,
        normal: c.normal,
        depth: c.depth,
        point: c.point,
        pose_a,
        pose_b,
        response,
        resolved,
    });
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
            w.on_static[i] |= w.kind[j] == BodyKind::Static;
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
            w.on_static[j] |= w.kind[i] == BodyKind::Static;
        }
        pushed = p;
    }
    pushed
}
