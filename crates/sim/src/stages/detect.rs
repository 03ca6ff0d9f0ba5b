//! The `detect` stage: broad phase, exact narrow phase, and the responses of the layer-pair
//! matrix at the frame's final poses.
//!
//! Broad phase: [`crate::broad_phase`], chosen by the scenario's `broad_phase` (automatic
//! by default), fed with every body's bounds ([`World::bounds`]). Layers that `ignore` each
//! other are never paired (a layer that ignores itself is never swept against itself), and
//! static and kinematic bodies never pair with each other: those pairs are never produced,
//! so never counted. Static bodies are handed over only when they change
//! ([`World::static_generation`]), and only those of a layer `detect` pairs with some layer:
//! a tile map that its actors meet only in the per-axis stages (two layers of boxes that
//! `separate`) is not indexed here at all (`BroadPhase::set_inert_statics` counts it, so the
//! choice of algorithm and the stats are as if it were). Pairs come back as handles and are
//! turned into world indices here. A candidate pair is then dropped before the narrow phase
//! when a body is frozen outside the active region, when both are at rest (asleep or
//! static), or when two boxes `separate` (the per-axis stages own those). The rest are
//! tested exactly, in `(a, b)` id order, and respond:
//! - `report`: the contact is logged (the `touch` stage turns a pair's first and last
//!   frames of contact into touch events);
//! - `destroy`: the doomed bodies are removed after the pass (children of a split spawned);
//! - `separate`: the dynamic body is pushed out along the normal by the depth (two dynamic
//!   bodies half each, clipped by the static bodies: `push.rs`), and its velocity into the
//!   other is removed.
//!
//! A sleeping body that touches an awake one wakes up (from the next frame on).
//!
//! A `separate` pair of a fast dynamic body and a static or kinematic one is also tested by
//! time of impact (`sweep_normal.rs`): when the end pose tunnelled, the body is stopped
//! where it touched and pushed there.
//!
//! Swept pairs (a layer in `fast_layers`, or `sweep = true` on the `[[collide]]` entry;
//! `report` and `destroy` only) are bounded over the whole frame's motion and tested by time
//! of impact instead: each moving body's hits are taken in time order and it stops at the
//! first that destroys it, so a bullet never passes through a rock, and hits the first one
//! on its path. Rotation during the frame is not swept (the end angles are used).
//!
//! In a wrapping world, pairs also meet through the seam (`wrap.rs`): a pair with an image
//! is tested directly and with `b` translated by whole world sizes next to `a`; the deepest
//! contact (the earliest touch) wins, the direct one on a tie, and is logged with `b`'s
//! image as `pose_b`. Responses are the same (a push moves the real bodies). A body that
//! ended its motion half the world's size or more outside it is wrapped in first
//! (`wrap::bring_in`), so the images reach every contact whatever the speed.

use ricochet_geom::{Contact, Pose, Vec2, beyond_reach, contact, contact_deeper_than};

use crate::broad_phase::{BodyEntry, BroadPhase, BroadPhaseKind, Interactions, STATIC_BIT};
use crate::def::{BodyKind, Doomed, Layers, Response, WorldDef};
use crate::entity::Entity;
use crate::event::Removal;
use crate::output::{ContactRecord, Phase};
use crate::parallel::Workers;
use crate::prefetch;
use crate::stages::mover_pairs::{MoverCall, mover_pairs};
use crate::stages::narrow_groups::ByClass;
use crate::stages::push::{Statics, separate_along_normal};
use crate::stages::remove::remove;
use crate::stages::separate::is_box;
use crate::stages::slope::Climb;
use crate::stages::sweep_normal;
use crate::stages::swept_pairs::run_swept;
use crate::stages::wrap::{self, Seam};
use crate::stages::{SLOP, StageCtx};
use crate::world::{MoverEntries, World};

/// Whether there are two bodies and a layer pair that does not `ignore`.
pub(crate) fn has_work(w: &World, def: &WorldDef) -> bool {
    w.len() >= 2 && def.layers.any(|r| r != Response::Ignore)
}

/// What `detect` keeps from one frame to the next: the broad phase (its sorted lists and
/// static structures) and reused buffers.
#[derive(Debug, Clone)]
pub(crate) struct DetectState {
    broad_phase: BroadPhase,
    /// Layer pairs `detect` tests: not `ignore`, and not `separate` between two layers of
    /// boxes only (the per-axis stages own those). Rebuilt when `box_only` changes.
    interactions: Interactions,
    /// Per layer, whether all its bodies were boxes when `interactions` was built.
    box_only: Vec<bool>,
    /// Layers with a swept pair.
    sweeping: Vec<bool>,
    /// Layers with a `separate` pair `detect` tests (not two layers of boxes only): a fast
    /// body of one is bounded over its motion (`sweep_normal.rs`).
    separate_swept: Vec<bool>,
    /// The static generation `statics` was built at.
    static_generation: Option<u64>,
    /// Bumped whenever `statics` is rebuilt: the broad phase's static generation.
    statics_version: u64,
    /// The world index of each of `statics`.
    static_index: StaticIndex,
    statics: Vec<BodyEntry>,
    movers: MoverEntries,
    pairs: Vec<(u32, u32)>,
    /// The wrap seam's images (a wrapping world only).
    seam: Seam,
    /// Narrow-phase tests per layer pair this frame, `[a * n + b]`.
    tests: Vec<u64>,
    /// This frame's pairs for the narrow phase (dense indices, response), their contacts at
    /// the poses the pass started from, and the bodies a response has moved since.
    plan: Vec<(usize, usize, Response)>,
    /// The order the contacts are computed in (`narrow_groups.rs`).
    by_class: ByClass,
    /// The contacts, in `by_class`'s order (a plan place's is at its `rank`).
    contacts: Vec<Option<Contact>>,
    /// Per body, all false between passes (only the `moved` ones are set, then cleared).
    pushed: Vec<bool>,
    moved: Vec<usize>,
    /// The static bodies that clip pushes between dynamic bodies (`push.rs`).
    push_statics: Statics,
}

impl DetectState {
    /// The state for a scene with these layers, with the scenario's broad phase.
    pub(crate) fn new(layers: &Layers, kind: BroadPhaseKind) -> DetectState {
        let n = layers.names().len();
        let box_only = vec![false; n];
        DetectState {
            broad_phase: BroadPhase::new(kind),
            interactions: interactions(layers, &box_only),
            separate_swept: separate_swept(layers, &box_only),
            box_only,
            sweeping: (0..n)
                .map(|l| (0..n).any(|m| layers.sweeps(l as u8, m as u8)))
                .collect(),
            static_generation: None,
            statics_version: 0,
            static_index: StaticIndex::default(),
            statics: Vec::new(),
            movers: MoverEntries::default(),
            pairs: Vec::new(),
            seam: Seam::new(kind),
            tests: vec![0; n * n],
            plan: Vec::new(),
            by_class: ByClass::default(),
            contacts: Vec::new(),
            pushed: Vec::new(),
            moved: Vec::new(),
            push_statics: Statics::default(),
        }
    }
}

/// The world index of each body of `detect`'s static list, found again only when the
/// bodies' order ([`World::layout`]) or the list changed; the main pairs and the wrap seam's
/// read it. Before, every pair with a static body searched the entity column for it, a
/// cache miss at each step of the search.
#[derive(Debug, Clone, Default)]
struct StaticIndex {
    /// The layout and the list's version the indices were found at.
    at: Option<(u64, u64)>,
    index: Vec<u32>,
}

impl StaticIndex {
    /// The world index of each of `statics` (of version `version`) in `w`.
    fn of(&mut self, w: &World, statics: &[BodyEntry], version: u64) -> &[u32] {
        let at = (w.layout(), version);
        if self.at != Some(at) {
            self.index.clear();
            // Every static body in `statics` is alive: it was rebuilt since the last change.
            self.index.extend(
                statics
                    .iter()
                    .map(|s| w.index_of_key(s.key).map_or(u32::MAX, |i| i as u32)),
            );
            self.at = Some(at);
        }
        &self.index
    }
}

/// The layer pairs `detect` pairs up, given which layers hold only boxes.
fn interactions(layers: &Layers, box_only: &[bool]) -> Interactions {
    Interactions::from_fn(box_only.len(), |a, b| match layers.response(a, b) {
        // One-way pairs are answered by their own pass (`one_way.rs`), never here.
        Response::Ignore | Response::OneWay(_) => false,
        Response::Separate => !(box_only[usize::from(a)] && box_only[usize::from(b)]),
        _ => true,
    })
}

/// The layers with a `separate` pair `detect` tests, given which layers hold only boxes.
fn separate_swept(layers: &Layers, box_only: &[bool]) -> Vec<bool> {
    let n = box_only.len();
    (0..n)
        .map(|a| {
            (0..n).any(|b| {
                layers.response(a as u8, b as u8) == Response::Separate
                    && !(box_only[a] && box_only[b])
            })
        })
        .collect()
}

/// From how many candidate pairs [`candidate_pairs`] sorts them by a radix sort.
const RADIX_PAIRS: usize = 256;

/// Fills the broad phase's inputs and finds the candidate pairs (dense indices, sorted).
fn candidate_pairs(ctx: &mut StageCtx, st: &mut DetectState) -> Vec<(u32, u32)> {
    let w = &mut *ctx.world;
    let wrap = ctx.def.bounds.filter(|b| b.wrap);
    let changed = (0..st.box_only.len()).any(|l| st.box_only[l] != w.only_boxes(l as u8));
    if changed {
        for (l, b) in st.box_only.iter_mut().enumerate() {
            *b = w.only_boxes(l as u8);
        }
        st.interactions = interactions(&ctx.def.layers, &st.box_only);
        st.separate_swept = separate_swept(&ctx.def.layers, &st.box_only);
        // The static layers detect pairs may have changed.
        st.static_generation = None;
    }
    if st.static_generation != Some(w.static_generation()) {
        // Only static bodies of a layer that detect pairs with some layer: a tile map that
        // meets its actors only in the per-axis stages costs the broad phase nothing.
        let n_layers = st.box_only.len();
        let paired: Vec<bool> = (0..n_layers)
            .map(|l| (0..n_layers).any(|m| st.interactions.interacts(l as u8, m as u8)))
            .collect();
        st.statics.clear();
        st.statics_version += 1;
        let (mut inert, mut inert_layers) = (0, Vec::new());
        for i in 0..w.len() {
            if w.kind[i] != BodyKind::Static {
                continue;
            }
            let layer = w.layer[i];
            if paired.get(usize::from(layer)).copied().unwrap_or(false) {
                let bounds = w.bounds(i);
                st.statics.push(BodyEntry {
                    key: w.key(i),
                    bounds,
                    layer,
                    kind: BodyKind::Static,
                });
            } else {
                inert += 1;
                if !inert_layers.contains(&layer) {
                    inert_layers.push(layer);
                }
            }
        }
        // Counted as the broad phase always counted them (its choice, the stats), not kept.
        st.broad_phase.set_inert_statics(inert, &inert_layers);
        if let Some(b) = wrap {
            st.seam.statics_changed(&b, &st.statics);
        }
    }
    let generation = st.statics_version;
    let mut pairs = std::mem::take(&mut st.pairs);
    // By handles (a place among the movers, or among `statics` with `STATIC_BIT`), turned
    // into world indices here: `statics` holds only some of the static bodies, so places
    // in the broad phase's dense order are not world indices.
    let call = MoverCall {
        world: w,
        broad_phase: &mut st.broad_phase,
        widen: (&st.sweeping, &st.separate_swept),
        statics: (&st.statics, generation),
        interactions: &st.interactions,
        movers: &mut st.movers,
    };
    let (bp, not_made) = match wrap {
        Some(b) => {
            st.seam.begin(&b);
            mover_pairs(call, st.seam.visitor(), &mut pairs)
        }
        None => mover_pairs(call, |_, _| false, &mut pairs),
    };
    if let Some(b) = wrap
        && !not_made.is_empty()
        && st.seam.reads_every_mover(&b, st.movers.list())
    {
        let widen = (&st.sweeping[..], &st.separate_swept[..]);
        w.some_mover_entries(widen, &mut st.movers, not_made, |_, _| false, None);
    }
    let static_index = st.static_index.of(w, &st.statics, st.statics_version);
    {
        let movers = w.movers();
        let world_index = |h: u32| -> u32 {
            if h & STATIC_BIT == 0 {
                movers[h as usize]
            } else {
                static_index[(h & !STATIC_BIT) as usize]
            }
        };
        for p in &mut pairs {
            let (i, j) = (world_index(p.0), world_index(p.1));
            *p = (i.min(j), i.max(j));
        }
        // By the pair's key; equal keys are equal pairs, so the order is the same whichever
        // sort. Many pairs by a radix sort: it sorts by the bytes that differ (four at most
        // below 65,536 bodies), where a comparison sort took 2% of rain-10000's step; a few
        // by a comparison sort (a radix sort's tables cost asteroids-2000, 2 to 7 pairs a
        // frame, 7,000 instructions a frame).
        let key = |&(i, j): &(u32, u32)| (u64::from(i) << 32) | u64::from(j);
        if pairs.len() >= RADIX_PAIRS {
            radsort::sort_by_key(&mut pairs, key);
        } else {
            pairs.sort_unstable_by_key(key);
        }
    }
    st.static_generation = Some(w.static_generation());
    if let Some(b) = wrap {
        st.seam.add_pairs(
            &b,
            w,
            (&st.statics, generation, static_index),
            st.movers.list(),
            &st.interactions,
            &mut pairs,
        );
    }
    ctx.out.stats.broad_phase = Some(bp.kind);
    ctx.out.stats.layer_pairs_skipped += bp.layer_pairs_skipped;
    pairs
}

/// Runs the pass. With `capture_poses`, every body's pose at the start of it goes into
/// [`crate::FrameOutput::detect_poses`].
/// `workers` compute the narrow phase's contacts (the thread count changes nothing else).
pub(crate) fn run(
    ctx: &mut StageCtx,
    st: &mut DetectState,
    capture_poses: bool,
    workers: &Workers,
) {
    let def = ctx.def;
    let layers = &def.layers;
    if let Some(b) = def.bounds.filter(|b| b.wrap) {
        // Before the poses are taken: the pass, and its referee, see the bodies wrapped.
        wrap::bring_in(&b, ctx.world);
    }
    if capture_poses {
        let w = &ctx.world;
        ctx.out.detect_poses = Some((0..w.len()).map(|i| (w.entity[i], w.pose(i))).collect());
    }
    let pairs = candidate_pairs(ctx, st);
    // Tests per layer pair, counted in a flat table and listed once at the end.
    let n_layers = layers.names().len();
    let mut per_layer_pair = std::mem::take(&mut st.tests);
    // Each doomed body with the body that hit it.
    let mut doomed: Vec<(Entity, Entity)> = Vec::new();
    let mut swept: Vec<(usize, usize)> = Vec::new();
    let mut woken: Vec<usize> = Vec::new();
    // The pairs the narrow phase tests, in order, with their responses.
    let mut plan = std::mem::take(&mut st.plan);
    plan.clear();
    // With every body awake and none frozen, no pair is dropped for them: the broad phase
    // never pairs two static bodies. Their columns are not read then (a pair's bodies are
    // anywhere in them: a cache miss each, once the bench's other engines ran between frames).
    let quiet = ctx.world.all_awake_and_free();
    for &(i, j) in &pairs {
        let (i, j) = (i as usize, j as usize);
        let w = &ctx.world;
        let resting = |k: usize| w.kind[k] == BodyKind::Static || w.asleep(k);
        debug_assert!(
            !quiet || !(w.frozen(i) || w.frozen(j) || (resting(i) && resting(j))),
            "a quiet world drops no pair for its bodies' state"
        );
        if !quiet && (w.frozen(i) || w.frozen(j) || (resting(i) && resting(j))) {
            continue;
        }
        let response = layers.response(w.layer[i], w.layer[j]);
        if response == Response::Separate && is_box(w.shape(i)) && is_box(w.shape(j)) {
            continue;
        }
        ctx.out.stats.broad_pairs += 1;
        let (la, lb) = (w.layer[i].min(w.layer[j]), w.layer[i].max(w.layer[j]));
        per_layer_pair[usize::from(la) * n_layers + usize::from(lb)] += 1;
        if response != Response::Separate && layers.sweeps(w.layer[i], w.layer[j]) {
            swept.push((i, j));
            continue;
        }
        plan.push((i, j, response));
    }
    // Every planned pair's contact at the poses the pass starts from, on the workers
    // (`parallel.rs`): a pure function of shapes and poses, gathered in order. Computed
    // grouped by the pairs' shapes (`narrow_groups.rs`), used in the plan's order.
    let mut contacts = std::mem::take(&mut st.contacts);
    st.by_class
        .sort(ctx.world, &plan, workers.chunk(plan.len()));
    {
        let w = &*ctx.world;
        let order = st.by_class.order();
        let pair = |m: usize| order.get(m).map(|&k| plan[k as usize]);
        workers.map(
            plan.len(),
            |m| {
                // What the narrow phase reads of the pairs ahead is asked for now
                // (`prefetch.rs`): their shapes (a table far bigger than the cache, read at
                // random) and poses miss the cache, and asked for here they overlap this
                // pair's work instead of stalling their own. The bodies' columns first (the
                // shape id says where the shape is: read while it missed, it stalled the
                // loop); then a shape's first line; then, once it is in, the rest of it.
                if let Some((i, j, _)) = pair(m + AHEAD_IDS) {
                    w.prefetch_columns(i);
                    w.prefetch_columns(j);
                }
                if let Some((i, j, _)) = pair(m + AHEAD) {
                    w.prefetch_shape(i);
                    w.prefetch_shape(j);
                }
                if let Some((i, j, _)) = pair(m + AHEAD_REST) {
                    prefetch::rest_of(w.shape(i));
                    prefetch::rest_of(w.shape(j));
                }
                let (i, j, response) = plan[order[m] as usize];
                narrow(w, (i, j), response, &w.pose(j))
            },
            &mut contacts,
        );
    }
    // Room at once for about the records this pass makes: the contacts found, and a few
    // more through the seam (growing the list by doubling copied it about ten times a frame
    // at rain-10000, and a few records past room for exactly the contacts found copied it
    // once more).
    let found = contacts.iter().filter(|c| c.is_some()).count();
    ctx.out.contacts.reserve(found + found / 8 + 16);
    // Bodies a response of this pass moved: their later pairs are tested again. Only those
    // are set, and cleared after the pass, so a million tiles cost nothing here.
    let (pushed, moved) = (&mut st.pushed, &mut st.moved);
    pushed.resize(ctx.world.len(), false);
    for (k, &(i, j, response)) in plan.iter().enumerate() {
        ctx.out.stats.narrow_tests += 1;
        let w = &ctx.world;
        let (pose_a, mut pose_b) = (w.pose(i), w.pose(j));
        // No body was pushed yet in this pass (a pass of `report` pairs never pushes): the
        // flags need not be read.
        let mut c = if !moved.is_empty() && (pushed[i] || pushed[j]) {
            narrow(w, (i, j), response, &pose_b)
        } else {
            contacts[st.by_class.rank(k)]
        };
        let before = (w.position[i], w.position[j]);
        let mut note_pushes = |w: &World| {
            for (k, was) in [(i, before.0), (j, before.1)] {
                let bits = |p: Vec2| p.to_array().map(f64::to_bits);
                if bits(w.position[k]) != bits(was) && !pushed[k] {
                    pushed[k] = true;
                    moved.push(k);
                }
            }
        };
        // A fast body against static or kinematic geometry: time of impact, then the push
        // (`sweep_normal.rs`; not through the wrap seam). A `separate` pair's contact is
        // always computed (`narrow`).
        if response == Response::Separate
            && let Some(direct) = &c
            && st.seam.offsets(i, j).next().is_none()
            && let Some(hit) =
                sweep_normal::stop(w, (i, j), direct, &mut ctx.out.stats.narrow_tests)
        {
            sweep_normal::apply(ctx, (i, j), &hit);
            note_pushes(ctx.world);
            continue;
        }
        // Through the seam: `b`'s images next to `a`, the deepest (the first on a tie). A
        // contact left out is no deeper than the threshold below, so it never wins over one
        // that passes it, and when every one is left out the pair is skipped either way.
        for offset in st.seam.offsets(i, j) {
            ctx.out.stats.narrow_tests += 1;
            let image = Pose::new(w.position[j] + offset, w.angle[j]);
            if let Some(d) = narrow(w, (i, j), response, &image)
                && c.is_none_or(|c| d.depth > c.depth)
            {
                (c, pose_b) = (Some(d), image);
            }
        }
        let Some(c) = c.filter(|c| c.depth > threshold(response)) else {
            continue;
        };
        if w.sleeping() > 0 {
            // Else none is asleep: their columns are not read (a cache miss a body).
            woken.extend([i, j].into_iter().filter(|&k| w.asleep(k)));
        }
        respond(
            ctx,
            (&mut doomed, &mut st.push_statics),
            (i, j),
            response,
            Phase::All,
            c,
            (pose_a, pose_b),
        );
        note_pushes(ctx.world);
    }
    for k in st.moved.drain(..) {
        st.pushed[k] = false;
    }
    st.plan = plan;
    st.contacts = contacts;
    st.pairs = pairs;
    for (k, count) in per_layer_pair.iter_mut().enumerate() {
        if *count > 0 {
            let (la, lb) = ((k / n_layers) as u8, (k % n_layers) as u8);
            ctx.out.stats.tests_by_layer_pair.push(((la, lb), *count));
            *count = 0;
        }
    }
    st.tests = per_layer_pair;
    run_swept(
        ctx,
        &mut st.push_statics,
        &mut doomed,
        &swept,
        &st.seam,
        &mut woken,
    );
    for i in woken {
        ctx.world.wake(i);
    }
    // In id order; a body hit twice is destroyed by the first hit found.
    doomed.sort_by_key(|(e, _)| *e);
    doomed.dedup_by_key(|(e, _)| *e);
    for (e, by) in doomed {
        remove(ctx, e, Removal::HitBy(by), true);
    }
}

/// The depth a contact must exceed to respond: a `separate` pair leaves [`SLOP`] of overlap.
fn threshold(response: Response) -> f64 {
    if response == Response::Separate {
        SLOP
    } else {
        0.0
    }
}

/// How many pairs ahead of the narrow phase the first line of their shapes is asked for,
/// and ([`AHEAD_REST`]) how many the rest of their shapes (`prefetch.rs`). Chosen by timing
/// rain-10000 (`step_scene`, eight rounds alternated), when this step asked for the poses
/// too: 8 and 2 took the step from 0.714 to 0.676 ms; 4 and 2, 12 and 3, 16 and 2 within a
/// percent of that.
const AHEAD: usize = 8;
/// How many pairs ahead the bodies' columns (shape ids, positions, angles) are asked for,
/// before [`AHEAD`] reads the shape ids for the shapes' lines. Chosen by timing rain-10000
/// (`step_scene` with a 16 MB buffer written between frames, as the bench's other engines
/// do, eight rounds of four): medians 0.714 ms with the ids read at 8 (no third stage),
/// 0.703 at 16, 0.700 at 24 (with shapes at 10), 0.704 at 32 (12); alone about 1% better.
const AHEAD_IDS: usize = 16;
/// See [`AHEAD`].
const AHEAD_REST: usize = 2;

/// The contact of bodies `i` and `j` with `j` at `pose_b`: always for a `separate` pair (its
/// time of impact starts from it), else `None` when no deeper than the threshold: at once for
/// bodies too far apart for their shapes to meet (`beyond_reach`: no shape read or placed),
/// else by `contact_deeper_than`. A contact that comes back is `contact`'s, bit for bit.
fn narrow(w: &World, (i, j): (usize, usize), response: Response, pose_b: &Pose) -> Option<Contact> {
    let pose_a = w.pose(i);
    if response == Response::Separate {
        return Some(contact(w.shape(i), &pose_a, w.shape(j), pose_b));
    }
    if beyond_reach(pose_b.position - pose_a.position, w.reach(i) + w.reach(j)) {
        return None;
    }
    contact_deeper_than(w.shape(i), &pose_a, w.shape(j), pose_b, threshold(response))
}

/// Records a contact and applies its response: a `destroy` adds to `doomed`, a `separate`
/// between two dynamic bodies is clipped by `push_statics` (`push.rs`).
pub(super) fn respond(
    ctx: &mut StageCtx,
    (doomed, push_statics): (&mut Vec<(Entity, Entity)>, &mut Statics),
    (i, j): (usize, usize),
    response: Response,
    phase: Phase,
    c: Contact,
    (pose_a, pose_b): (Pose, Pose),
) {
    let w = &ctx.world;
    let mut resolved = Vec2::ZERO;
    let (ea, eb) = (w.entity[i], w.entity[j]);
    match response {
        Response::Ignore | Response::Report | Response::OneWay(_) => {}
        Response::Destroy(which) => {
            if matches!(which, Doomed::First | Doomed::Both) {
                doomed.push((ea, eb));
            }
            if matches!(which, Doomed::Second | Doomed::Both) {
                doomed.push((eb, ea));
            }
        }
        Response::Separate => {
            let statics = Some((push_statics, &ctx.def.layers));
            let climb = Climb::of(ctx.def);
            resolved =
                separate_along_normal(ctx.world, statics, (i, j), (c.normal, c.depth), climb);
        }
    }
    ctx.out.contacts.push(ContactRecord {
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
