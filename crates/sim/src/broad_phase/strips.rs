//! `Strips`: sort and sweep in horizontal strips.
//!
//! Space is cut into horizontal strips of height `H`, a power of two at least as tall as
//! every body (one `H` per call for every list, so lists can be swept against each other).
//! A body belongs to the strip holding its `min.y`; each list (one layer's moving bodies, or
//! one layer's static bodies) is sorted by `(strip, min.x)`. Two boxes that overlap have
//! their `min.y` less than `H` apart, so their strips are the same or neighbours: a list is
//! swept within each strip and against the next strip, two lists strip against neighbouring
//! strip, and nothing else is ever looked at. Where a single sort axis would test every
//! body sharing an x range (rain: thousands of drops over the same x range, falling in y),
//! a strip holds only the bodies within `H` in y of each other.
//!
//! Like `SortAndSweep`, a moving list is kept from the previous call and re-sorted by
//! insertion sort (nearly sorted: a body changes strip rarely). A slot is only the sort key
//! and the body's index (16 bytes), so the sorts and the merge move little; once the order
//! is settled the bounds are gathered beside it in the same order, so a sweep reads one
//! array in sequence. Static lists are sorted once, and again only when the static bodies or
//! `H` change.
//!
//! Two runs of very different sizes (a hundred actors over a floor of thousands of tiles)
//! are not walked together: each body of the smaller one finds its candidates in the larger
//! by binary search (`[min.x - widest, max.x]`).
//!
//! # Why neighbouring strips are enough
//! `H` is an exact power of two (so `y / H` is exact: a multiplication by a power of two),
//! at least `1 + 1e-9` times the tallest body's computed height. If `p.min.y <= q.min.y` and
//! they overlap, `q.min.y <= p.max.y < p.min.y + H`, so `floor(q.min.y / H)` is at most
//! `floor(p.min.y / H) + 1`. Strips are clamped to `i32`, which is monotone: it only merges
//! strips, so two bodies further apart than one strip still do not overlap. A body with NaN
//! or inverted bounds overlaps nothing wherever it is filed. With an infinite or NaN
//! height, or none below `2^1000`, there is one strip: plain sort and sweep.
//!
//! # Determinism
//! Orders are by `(strip, min.x as f64::total_cmp, handle)`: a function of the input.

use ricochet_geom::Bounds;

use super::grid::cell_coord;
use super::sorted::{self, order_key};
use super::strip_height::{extent, inv_strip_height, restrip};
use super::{BodyEntry, BroadPhase, BroadPhaseStats, LAYERS, Member, STATIC_BIT, member, of_layer};

/// No index: a body gone from a list.
const NONE: u32 = u32::MAX;

/// One list: bodies sorted by strip, then by `min.x`.
#[derive(Debug, Default, Clone)]
pub(super) struct StripList {
    /// The call the list was last brought up to (moving bodies).
    pub(super) frame: u64,
    /// `1 / H` of the current order (0: one strip).
    inv_h: f64,
    /// The bodies' sort keys, sorted.
    order: Vec<Slot>,
    /// The bodies' bounds in `order`'s order, gathered once the order is settled: the sweeps
    /// read this one array in sequence.
    swept: Vec<Swept>,
    /// The keys of the list's bodies at the last update, in key order (`local` indexes it).
    keys: Vec<u64>,
    /// The widest body's `max.x - min.x` (at least 0; NaN ignored).
    width: f64,
    /// `(strip, first slot)` of each run of one strip, in order, then `(_, order.len())`.
    runs: Vec<(i32, u32)>,
    /// Update buffers: old local to new, bodies new to the list.
    remap: Vec<u32>,
    fresh: Vec<Slot>,
    merged: Vec<Slot>,
}

/// A body's place in a [`StripList`] (16 bytes, so the insertion sort and the merge move a
/// quarter of what they would with the bounds): `(strip, min.x, local)` packed into one
/// integer whose order is the list order. From the high bits: the strip (`floor(min.y / H)`,
/// clamped) with its sign bit flipped, `min.x` as [`order_key`], and the body's index in the
/// list's key order, which breaks ties so the order is a function of the input.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct Slot(u128);

impl Slot {
    #[inline]
    fn new(b: &Bounds, local: u32, inv_h: f64) -> Slot {
        let strip = cell_coord(b.min.y, inv_h) as u32 ^ (1 << 31);
        Slot(u128::from(strip) << 96 | u128::from(order_key(b.min.x)) << 32 | u128::from(local))
    }

    #[inline]
    fn strip(self) -> i32 {
        ((self.0 >> 96) as u32 ^ (1 << 31)) as i32
    }

    #[inline]
    fn local(self) -> u32 {
        self.0 as u32
    }

    /// A slot that sorts after every other (a body gone from the list).
    const GONE: Slot = Slot(u128::MAX);
}

/// What a sweep reads of a body, in list order.
#[derive(Clone, Copy, Debug)]
struct Swept {
    /// `min.x` as [`order_key`].
    min: u64,
    /// `max.x + 0.0` as [`order_key`].
    max: u64,
    m: Member,
}

impl Swept {
    #[inline]
    fn new(m: Member) -> Swept {
        Swept {
            min: order_key(m.bounds.min.x),
            max: order_key(m.bounds.max.x + 0.0),
            m,
        }
    }
}

impl StripList {
    /// The list's `1 / H`.
    pub(super) fn inv_h(&self) -> f64 {
        self.inv_h
    }

    /// A list of static `members` (in key order), fully sorted.
    pub(super) fn statics(members: &[Member], inv_h: f64) -> StripList {
        let mut list = StripList {
            inv_h,
            ..StripList::default()
        };
        list.order = members
            .iter()
            .enumerate()
            .map(|(i, m)| Slot::new(&m.bounds, i as u32, inv_h))
            .collect();
        list.order.sort_unstable();
        list.swept = list
            .order
            .iter()
            .map(|s| Swept::new(members[s.local() as usize]))
            .collect();
        list.width = members
            .iter()
            .map(|m| m.bounds.max.x - m.bounds.min.x)
            .fold(0.0, f64::max);
        list.find_runs();
        list
    }

    /// Reconciles the list with this call's bodies (`handles` into `bodies`, key order) and
    /// strip height: bodies gone are dropped, bodies kept get their new keys, and bodies
    /// new to the list or to their strip are sorted apart and merged in (a body that wraps
    /// from the bottom of the world to the top would cost an insertion sort the whole list).
    /// Then the bounds are gathered in the new order. Returns the insertion sort's moves.
    pub(super) fn update(&mut self, handles: &[u32], bodies: &[BodyEntry], inv_h: f64) -> u64 {
        let restripped = self.inv_h.to_bits() != inv_h.to_bits();
        self.inv_h = inv_h;
        self.fresh.clear();
        let same = self.keys.len() == handles.len()
            && handles
                .iter()
                .zip(&self.keys)
                .all(|(&h, &k)| bodies[h as usize].key == k);
        if same {
            // In list order: the slots are written in sequence, the bodies read at random.
            // A body that changed strip leaves the list for `fresh`: the rest close up
            // behind a write cursor in the same pass.
            let mut kept = 0;
            for k in 0..self.order.len() {
                let old = self.order[k];
                let local = old.local();
                let b = &bodies[handles[local as usize] as usize];
                let slot = Slot::new(&b.bounds, local, inv_h);
                if slot.strip() == old.strip() && !restripped {
                    self.order[kept] = slot;
                    kept += 1;
                } else {
                    self.fresh.push(slot);
                }
            }
            self.order.truncate(kept);
        } else {
            self.reconcile(handles, bodies, inv_h, restripped);
        }
        let reordered = !same || !self.fresh.is_empty();
        let moved = if reordered {
            self.settle()
        } else {
            insertion_sort(&mut self.order)
        };
        self.gather(handles, bodies);
        self.find_runs();
        moved
    }

    /// [`StripList::update`] when the bodies are not the same as last time: merges the old
    /// keys with the new ones (both ascending). Kept bodies get their new keys in place,
    /// or go to `fresh` with the new ones when their strip changed.
    fn reconcile(&mut self, handles: &[u32], bodies: &[BodyEntry], inv_h: f64, restripped: bool) {
        self.remap.clear();
        self.remap.resize(self.keys.len(), NONE);
        let mut i = 0;
        for (j, &h) in handles.iter().enumerate() {
            let b = &bodies[h as usize];
            while i < self.keys.len() && self.keys[i] < b.key {
                i += 1;
            }
            if i < self.keys.len() && self.keys[i] == b.key {
                self.remap[i] = j as u32;
                i += 1;
            } else {
                self.fresh.push(Slot::new(&b.bounds, j as u32, inv_h));
            }
        }
        self.keys.clear();
        self.keys
            .extend(handles.iter().map(|&h| bodies[h as usize].key));
        for s in &mut self.order {
            let j = self.remap[s.local() as usize];
            if j == NONE {
                *s = Slot::GONE;
                continue;
            }
            let h = handles[j as usize];
            let slot = Slot::new(&bodies[h as usize].bounds, j, inv_h);
            if slot.strip() == s.strip() && !restripped {
                *s = slot;
            } else {
                *s = Slot::GONE;
                self.fresh.push(slot);
            }
        }
        self.order.retain(|&s| s != Slot::GONE);
    }

    /// Sorts `order` again (no slot is [`Slot::GONE`] any more): insertion-sorts it (nearly
    /// sorted) and merges in `fresh` (sorted first). Returns the insertion sort's moves.
    fn settle(&mut self) -> u64 {
        let moved = insertion_sort(&mut self.order);
        self.fresh.sort_unstable();
        self.merged.clear();
        self.merged.reserve(self.order.len() + self.fresh.len());
        // A few fresh slots among thousands: each finds its place by binary search and the
        // slots between are copied as one block. The order is total (`local` breaks ties),
        // so this is the one merge of the two lists.
        let mut from = 0;
        for &f in &self.fresh {
            let rest = &self.order[from..];
            let at = from + rest.partition_point(|&s| s < f);
            self.merged.extend_from_slice(&self.order[from..at]);
            self.merged.push(f);
            from = at;
        }
        self.merged.extend_from_slice(&self.order[from..]);
        std::mem::swap(&mut self.order, &mut self.merged);
        moved
    }

    /// Reads the bodies' bounds in list order into `swept`, and the widest body.
    fn gather(&mut self, handles: &[u32], bodies: &[BodyEntry]) {
        // The widest body (NaN ignored): a maximum, so any order gives it.
        let mut width = 0.0;
        self.swept.clear();
        self.swept.extend(self.order.iter().map(|s| {
            let h = handles[s.local() as usize];
            let b = &bodies[h as usize];
            let x = b.bounds.max.x - b.bounds.min.x;
            if x > width {
                width = x;
            }
            Swept::new(member(b, h))
        }));
        self.width = width;
    }

    /// Finds the runs of one strip in `order`.
    fn find_runs(&mut self) {
        self.runs.clear();
        let mut last = None;
        for (k, s) in self.order.iter().enumerate() {
            if last != Some(s.strip()) {
                self.runs.push((s.strip(), k as u32));
                last = Some(s.strip());
            }
        }
        self.runs.push((i32::MAX, self.order.len() as u32));
    }

    /// The bodies of run `r`, and its strip.
    #[inline]
    fn run(&self, r: usize) -> (i32, &[Swept]) {
        let (strip, start) = self.runs[r];
        (
            strip,
            &self.swept[start as usize..self.runs[r + 1].1 as usize],
        )
    }

    /// How many runs.
    #[inline]
    fn run_count(&self) -> usize {
        self.runs.len() - 1
    }

    /// The heap bytes the list holds (capacities, its update buffers included), for the
    /// broad-phase study.
    pub(super) fn heap_bytes(&self) -> usize {
        let slots = self.order.capacity() + self.fresh.capacity() + self.merged.capacity();
        slots * size_of::<Slot>()
            + self.keys.capacity() * 8
            + self.runs.capacity() * size_of::<(i32, u32)>()
            + self.remap.capacity() * 4
    }
}

/// Insertion sort for a nearly sorted list.
fn insertion_sort(order: &mut [Slot]) -> u64 {
    sorted::insertion_sort(order, Slot::cmp, |_, _| {})
}

/// Tests `p` and `q`, emitting the pair when one is dynamic and their bounds overlap.
#[inline]
fn test(p: &Member, q: &Member, out: &mut Vec<(u32, u32)>) -> u64 {
    if !(p.dynamic || q.dynamic) {
        return 0;
    }
    if p.bounds.overlaps(&q.bounds) {
        out.push((p.handle, q.handle));
    }
    1
}

/// Tests `p` against the slots of `others` (sorted by `min.x`) until one starts past `p`'s
/// end along x.
#[inline]
fn scan(p: &Swept, others: &[Swept], out: &mut Vec<(u32, u32)>) -> u64 {
    let mut tested = 0;
    for s in others {
        if s.min > p.max {
            break;
        }
        tested += test(&p.m, &s.m, out);
    }
    tested
}

/// Every overlapping pair within one run.
fn within(run: &[Swept], out: &mut Vec<(u32, u32)>) -> u64 {
    let mut tested = 0;
    for (k, p) in run.iter().enumerate() {
        let rest = &run[k + 1..];
        if rest.first().is_some_and(|next| next.min <= p.max) {
            tested += scan(p, rest, out);
        }
    }
    tested
}

/// Every overlapping pair with one slot from each run, walking both in `min.x` order.
fn merged(xs: &[Swept], ys: &[Swept], out: &mut Vec<(u32, u32)>) -> u64 {
    let mut tested = 0;
    let (mut i, mut j) = (0, 0);
    while i < xs.len() && j < ys.len() {
        if xs[i].min <= ys[j].min {
            if ys[j].min <= xs[i].max {
                tested += scan(&xs[i], &ys[j..], out);
            }
            i += 1;
        } else {
            if xs[i].min <= ys[j].max {
                tested += scan(&ys[j], &xs[i..], out);
            }
            j += 1;
        }
    }
    tested
}

/// Every overlapping pair with one slot from each run, each slot of `small` finding its
/// candidates in `large` (none wider than `width`) by binary search.
fn searched(small: &[Swept], large: &[Swept], width: f64, out: &mut Vec<(u32, u32)>) -> u64 {
    let mut tested = 0;
    for p in small {
        let b = &p.m.bounds;
        if b.min.x.is_nan() {
            continue; // overlaps nothing
        }
        // Slots starting before `lower` end before `b.min.x` (a relative margin far above
        // rounding error).
        let mut lower = b.min.x - width * (1.0 + 1e-12);
        lower -= lower.abs() * 1e-12 + f64::MIN_POSITIVE;
        let lower = order_key(lower);
        let lo = large.partition_point(|s| s.min < lower);
        tested += scan(p, &large[lo..], out);
    }
    tested
}

/// Every overlapping pair of two runs, by whichever walk is cheaper.
fn pair_runs(
    (xs, x_width): (&[Swept], f64),
    (ys, y_width): (&[Swept], f64),
    out: &mut Vec<(u32, u32)>,
) -> u64 {
    let log = |n: usize| u64::from(usize::BITS - n.leading_zeros()) + 2;
    let walk = (xs.len() + ys.len()) as u64;
    if xs.len() as u64 * log(ys.len()) < walk {
        searched(xs, ys, y_width, out)
    } else if ys.len() as u64 * log(xs.len()) < walk {
        searched(ys, xs, x_width, out)
    } else {
        merged(xs, ys, out)
    }
}

/// Every overlapping pair within one list with a dynamic body. Returns the tests.
pub(super) fn strip_self(list: &StripList, out: &mut Vec<(u32, u32)>) -> u64 {
    let mut tested = 0;
    for r in 0..list.run_count() {
        let (strip, run) = list.run(r);
        tested += within(run, out);
        if r + 1 < list.run_count() {
            let (next, above) = list.run(r + 1);
            if i64::from(next) == i64::from(strip) + 1 {
                tested += pair_runs((run, list.width), (above, list.width), out);
            }
        }
    }
    tested
}

/// Every overlapping pair with one body from each list (and a dynamic one); both lists
/// have the same strip height. Returns the tests.
pub(super) fn strip_cross(x: &StripList, y: &StripList, out: &mut Vec<(u32, u32)>) -> u64 {
    debug_assert_eq!(x.inv_h.to_bits(), y.inv_h.to_bits(), "one strip height");
    let mut tested = 0;
    let mut first = 0;
    for r in 0..x.run_count() {
        let (strip, run) = x.run(r);
        let strip = i64::from(strip);
        while first < y.run_count() && i64::from(y.runs[first].0) < strip - 1 {
            first += 1;
        }
        let mut k = first;
        while k < y.run_count() && i64::from(y.runs[k].0) <= strip + 1 {
            let (_, other) = y.run(k);
            tested += pair_runs((run, x.width), (other, y.width), out);
            k += 1;
        }
    }
    tested
}

impl BroadPhase {
    /// Before a `Strips` call: the strip height for this call's bodies (kept while it fits,
    /// see [`restrip`]), and the static lists, sorted again when the static bodies or the
    /// height changed.
    pub(super) fn prepare_strips(&mut self, bodies: &[BodyEntry]) {
        if !self.statics.built_strips {
            self.static_extent = extent(self.statics.entries.iter().map(|(b, _)| b));
        }
        // Every body given is a mover when there are as many movers (the usual call): read
        // them in place, in sequence.
        let (height, max_abs) = if self.movers.len() == bodies.len() {
            extent(bodies.iter().map(|b| &b.bounds))
        } else {
            extent(self.movers.iter().map(|&h| &bodies[h as usize].bounds))
        };
        let want = inv_strip_height(
            height.max(self.static_extent.0),
            max_abs.max(self.static_extent.1),
        );
        if restrip(self.inv_h, want) {
            self.inv_h = want;
        }
        let inv_h = self.inv_h;
        if self.statics.built_strips
            && self
                .static_strips
                .iter()
                .all(|s| s.inv_h().to_bits() == inv_h.to_bits())
        {
            return;
        }
        self.statics.built_strips = true;
        self.static_rebuilds += 1;
        let mut by_layer: Vec<Vec<Member>> = (0..LAYERS).map(|_| Vec::new()).collect();
        for (s, &(bounds, layer)) in self.statics.entries.iter().enumerate() {
            by_layer[usize::from(layer)].push(Member {
                bounds,
                handle: s as u32 | STATIC_BIT,
                dynamic: false,
            });
        }
        self.static_strips = by_layer
            .iter()
            .map(|members| StripList::statics(members, inv_h))
            .collect();
    }

    /// The pairs of moving layers `a` and `b` (the same, or two).
    pub(super) fn strip_pairs(
        &mut self,
        (a, b): (u8, u8),
        bodies: &[BodyEntry],
        out: &mut Vec<(u32, u32)>,
        stats: &mut BroadPhaseStats,
    ) {
        stats.resorted += self.ensure_strip(a, bodies);
        stats.resorted += self.ensure_strip(b, bodies);
        let list = |l: u8| &self.strips[usize::from(l)];
        stats.tested += if a == b {
            strip_self(list(a), out)
        } else {
            strip_cross(list(a), list(b), out)
        };
    }

    /// The pairs of moving layer `a` with static layer `b`.
    pub(super) fn strip_static_pairs(
        &mut self,
        (a, b): (u8, u8),
        bodies: &[BodyEntry],
        out: &mut Vec<(u32, u32)>,
        stats: &mut BroadPhaseStats,
    ) {
        stats.resorted += self.ensure_strip(a, bodies);
        stats.tested += strip_cross(
            &self.strips[usize::from(a)],
            &self.static_strips[usize::from(b)],
            out,
        );
    }

    /// Brings layer `l`'s moving list up to this call, once per call. Returns the re-sort's
    /// moves.
    fn ensure_strip(&mut self, l: u8, bodies: &[BodyEntry]) -> u64 {
        let list = &mut self.strips[usize::from(l)];
        if list.frame == self.frame {
            return 0;
        }
        list.frame = self.frame;
        list.update(
            of_layer(&self.movers, &self.layer_start, l),
            bodies,
            self.inv_h,
        )
    }
}
