//! The `touch` stage: which pairs touch at the end of the frame, and the begin and end
//! events of the pairs whose touching changed (Box2D's begin/end touch events;
//! `docs/touches.md`).
//!
//! The pairs touching at the end of frame `f`, `T_f`, are
//! - every pair with a contact record this frame (any phase, any response), and
//! - every pair of `T_{f-1}` with no record this frame whose bodies are both alive and
//!   either both at rest (static, asleep or frozen: neither pose changed, so neither did
//!   the contact) or still within [`SLOP`] at the end-of-frame poses (through the seam in a
//!   wrapping world): resting flush.
//!
//! Pairs whose layers do not [`touch`](crate::Layers::touches) are left out. A pair in
//! `T_f` and not in `T_{f-1}` begins ([`GameEvent::TouchBegin`], with its first record of
//! the frame); one in `T_{f-1}` and not in `T_f` ends ([`GameEvent::TouchEnd`]); a pair with
//! a body removed this frame is not in `T_f` (one that began this frame ends too). Begins
//! then ends, each in pair order, after every other event of the frame.
//!
//! Cost: the frame's records are sorted by pair (a few thousand at most in a busy scene)
//! and merged with the last frame's sorted set; only a pair that lingers without a record
//! and is not at rest gets a narrow-phase test. Buffers are reused: nothing is allocated
//! per frame once they have grown.

use ricochet_geom::{Bounds, Pose, Vec2};

use crate::def::{BodyKind, LayerId, Layers, WorldDef};
use crate::entity::Entity;
use crate::event::GameEvent;
use crate::output::FrameOutput;
use crate::stages::box_contact::box_contact;
use crate::stages::{SLOP, StageCtx};
use crate::world::World;

/// A pair of bodies, the lower id first.
pub(crate) type Pair = (Entity, Entity);

/// A contact record's pair and its index in the frame's records.
type Record = (Entity, Entity, u32);

/// Sorts `v` by merging its ascending runs, `scratch` and `runs` reused: `O(n log r)` for
/// `r` runs, and nothing allocated once they have grown. The frame's records come in a few
/// runs already sorted by pair (the `x` pass, the `y` pass, the full pass; swept hits in
/// time order), and their indices ascend, so a platformer's thousand records are a few
/// merges, not a sort.
fn sort_runs(v: &mut Vec<Record>, scratch: &mut Vec<Record>, runs: &mut Vec<usize>) {
    runs.clear();
    runs.push(0);
    runs.extend((1..v.len()).filter(|&k| v[k] < v[k - 1]));
    runs.push(v.len());
    // `runs` holds the start of each run, then the end of the last.
    while runs.len() > 2 {
        scratch.clear();
        let mut kept = 1;
        let mut k = 0;
        while k + 1 < runs.len() {
            let (lo, mid) = (runs[k], runs[k + 1]);
            let hi = runs.get(k + 2).copied().unwrap_or(mid);
            let (mut x, mut y) = (lo, mid);
            while x < mid && y < hi {
                if v[y] < v[x] {
                    scratch.push(v[y]);
                    y += 1;
                } else {
                    scratch.push(v[x]);
                    x += 1;
                }
            }
            scratch.extend_from_slice(&v[x..mid]);
            scratch.extend_from_slice(&v[y..hi]);
            runs[kept] = hi;
            kept += 1;
            k += 2;
        }
        runs.truncate(kept);
        std::mem::swap(v, scratch);
    }
}

/// What the `touch` stage keeps between frames: the touching set and reused buffers.
#[derive(Clone, Debug, Default)]
pub(crate) struct TouchState {
    /// Whether some layer pair touches: without one the stage never runs.
    any: bool,
    /// Whether every tested layer pair touches: then a record's layers need no lookup.
    all: bool,
    /// The pairs touching at the end of the last frame run, sorted.
    touching: Vec<Pair>,
    /// The static generation of the last frame run: a static body teleported since then is
    /// not at rest.
    static_generation: u64,
    /// This frame's pairs with records, each with its first record's index, sorted.
    recorded: Vec<Record>,
    /// Reused by [`sort_runs`].
    scratch: Vec<Record>,
    runs: Vec<usize>,
    /// `T_f` as it is built.
    next: Vec<Pair>,
    /// The pairs that end this frame, in pair order.
    ends: Vec<Pair>,
}

impl TouchState {
    /// The state for a scene with these layers: nothing touching.
    pub(crate) fn new(layers: &Layers) -> TouchState {
        TouchState {
            any: layers.any_touches(),
            all: layers.all_touch(),
            ..TouchState::default()
        }
    }

    /// The pairs touching at the end of the last frame, sorted by `(a, b)`, `a < b`.
    pub(crate) fn touching(&self) -> &[Pair] {
        &self.touching
    }

    /// The static generation of the last frame run (a snapshot keeps whether the world's has
    /// moved on since).
    pub(crate) fn static_generation(&self) -> u64 {
        self.static_generation
    }

    /// The state for a scene with these layers, `touching` (sorted) at the end of the last
    /// frame, which ran at `static_generation` (a restore).
    pub(crate) fn restored(layers: &Layers, touching: Vec<Pair>, static_generation: u64) -> Self {
        TouchState {
            touching,
            static_generation,
            ..TouchState::new(layers)
        }
    }
}

/// Whether some layer pair touches, and something touched at the end of the last frame or
/// was recorded in this one (else `T_f` is empty, as `T_{f-1}` was).
pub(crate) fn has_work(st: &TouchState, out: &FrameOutput) -> bool {
    st.any && !(st.touching.is_empty() && out.contacts.is_empty())
}

/// Body `e`'s layer: alive, from the world; removed this frame, from the frame's removed
/// bodies.
fn layer_of(w: &World, out: &FrameOutput, e: Entity) -> Option<LayerId> {
    match w.index_of(e) {
        Some(i) => Some(w.layer[i]),
        None => out.removed.iter().find(|r| r.entity == e).map(|r| r.layer),
    }
}

/// Whether a pair of `T_{f-1}` without a record this frame still touches: both alive, and
/// both at rest or within [`SLOP`] at the end-of-frame poses.
fn lingers(w: &World, def: &WorldDef, statics_moved: bool, (a, b): Pair) -> bool {
    let (Some(i), Some(j)) = (w.index_of(a), w.index_of(b)) else {
        return false;
    };
    let at_rest =
        |k: usize| (w.kind[k] == BodyKind::Static && !statics_moved) || w.asleep(k) || w.frozen(k);
    if at_rest(i) && at_rest(j) {
        return true;
    }
    let (pose_a, pose_b) = (w.pose(i), w.pose(j));
    let (shape_a, shape_b) = (w.shape(i), w.shape(j));
    // Two boxes (a tile and its actor) skip `contact`'s general path, bit for bit.
    if box_contact(shape_a, &pose_a, shape_b, &pose_b).depth >= -SLOP {
        return true;
    }
    let Some(world) = def.bounds.filter(|b| b.wrap) else {
        return false;
    };
    // Through the seam: `b`'s images next to `a`, as `detect` meets them (`wrap.rs`); the
    // deepest counts, so any within `SLOP` does. Only an image whose box comes within
    // `SLOP` of `a`'s (padded for the rounding of the translation) can be.
    let (bounds_a, bounds_b) = (shape_a.bounds(&pose_a), shape_b.bounds(&pose_b));
    world.image_offsets()[1..].iter().any(|&offset| {
        let far = (bounds_b.min.abs().max(bounds_b.max.abs()) + offset.abs()).max_element();
        let pad = Vec2::splat(SLOP + far * 4.0 * f64::EPSILON);
        let image = Bounds {
            min: bounds_b.min + offset - pad,
            max: bounds_b.max + offset + pad,
        };
        image.overlaps(&bounds_a) && {
            let pose = Pose::new(pose_b.position + offset, pose_b.angle);
            box_contact(shape_a, &pose_a, shape_b, &pose).depth >= -SLOP
        }
    })
}

/// Builds `T_f` from the frame's records and `T_{f-1}`, and raises the begin and end events.
pub(crate) fn run(ctx: &mut StageCtx, st: &mut TouchState) {
    let (w, def, out) = (&*ctx.world, ctx.def, &mut *ctx.out);
    let layers = &def.layers;
    st.recorded.clear();
    for (k, c) in out.contacts.iter().enumerate() {
        let touches = st.all
            || matches!(
                (layer_of(w, out, c.a), layer_of(w, out, c.b)),
                (Some(la), Some(lb)) if layers.touches(la, lb)
            );
        if touches {
            st.recorded.push((c.a, c.b, k as u32));
        }
    }
    // By pair, then record: the first of each pair's records in detection order is kept.
    sort_runs(&mut st.recorded, &mut st.scratch, &mut st.runs);
    st.recorded.dedup_by_key(|r| (r.0, r.1));
    let statics_moved = w.static_generation() != st.static_generation;
    st.static_generation = w.static_generation();
    st.next.clear();
    st.ends.clear();
    // Without a removal this frame every recorded body is alive.
    let removals = !out.removed.is_empty();
    let (mut p, mut r) = (0, 0);
    loop {
        let old = st.touching.get(p).copied();
        let new = st.recorded.get(r).map(|&(a, b, k)| ((a, b), k));
        // The lower of the two heads, or both when they are the same pair.
        let (pair, was, recorded) = match (old, new) {
            (None, None) => break,
            (Some(o), Some((n, k))) if o == n => (o, true, Some(k)),
            (Some(o), n) if n.is_none_or(|(n, _)| o < n) => (o, true, None),
            (_, Some((n, k))) => (n, false, Some(k)),
            (Some(o), None) => (o, true, None),
        };
        p += usize::from(was);
        r += usize::from(recorded.is_some());
        let keep = match recorded {
            None => lingers(w, def, statics_moved, pair),
            Some(k) => {
                if !was {
                    let c = &out.contacts[k as usize];
                    out.events.push(GameEvent::TouchBegin {
                        a: pair.0,
                        b: pair.1,
                        normal: c.normal,
                        depth: c.depth,
                        point: c.point,
                    });
                }
                // A recorded pair whose body was removed this frame ends in it.
                !removals || (w.index_of(pair.0).is_some() && w.index_of(pair.1).is_some())
            }
        };
        if keep {
            st.next.push(pair);
        } else {
            st.ends.push(pair);
        }
    }
    out.events
        .extend(st.ends.iter().map(|&(a, b)| GameEvent::TouchEnd { a, b }));
    std::mem::swap(&mut st.touching, &mut st.next);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Merging the runs is sorting: runs of every length, one element, none, reversed.
    #[test]
    fn sort_runs_sorts() {
        let e = |index| Entity {
            index,
            generation: index % 3,
        };
        let (mut scratch, mut runs) = (Vec::new(), Vec::new());
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        for len in [0, 1, 2, 3, 7, 64, 1000] {
            for spread in [1, 4, 1000] {
                let mut v: Vec<Record> = (0..len)
                    .map(|k| {
                        seed ^= seed << 13;
                        seed ^= seed >> 7;
                        seed ^= seed << 17;
                        let a = (seed % spread) as u32;
                        (e(a), e(a + 1 + (seed >> 32) as u32 % 3), k)
                    })
                    .collect();
                let mut sorted = v.clone();
                sorted.sort_unstable();
                sort_runs(&mut v, &mut scratch, &mut runs);
                assert_eq!(v, sorted, "{len} records, spread {spread}");
                v.reverse();
                sort_runs(&mut v, &mut scratch, &mut runs);
                assert_eq!(v, sorted, "{len} records reversed");
            }
        }
    }
}
