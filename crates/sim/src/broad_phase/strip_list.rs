//! One list of `Strips` (`strips.rs`): a layer's bodies filed in every strip their bounds
//! reach, sorted by strip, then by `min.x`, with their bounds beside them in the same order
//! for the sweeps.
//!
//! `H` is at least as tall as every body (`strip_height.rs`), so a body reaches one strip or
//! two: the strip of its `min.y` (its lower slot) and, when its top is in the next one, that
//! one too (its upper slot). Two bodies whose bounds overlap then share the strip of
//! `max(p.min.y, q.min.y)`, which both reach; the sweeps look within strips only, and keep a
//! pair only in that strip.
//!
//! Like `SortAndSweep`, a moving list is kept from the previous call and re-sorted by
//! insertion sort. The bodies are read once in key order, in sequence, for their new `min.x`
//! keys and strips; a slot whose body still reaches its strip then gets its new key in
//! place, read from that 8-byte-a-body column (nearly sorted: `min.x` moves a little a
//! frame). Reading the 48-byte entries in list order instead, at random, was most of the
//! list's cost at 10,000 bodies. A body that reaches other strips than last time keeps its
//! slots in the strips it still reaches (a lower slot that becomes its upper one, or the
//! reverse, turns one bit: the same place in the list, up to ties in `min.x`), its slots in
//! strips it left leave, and a strip newly reached gets a fresh slot, sorted apart and merged
//! in (a body that wraps from the bottom of the world to the top would cost an insertion sort
//! the whole list). A body falling through the strips thus makes one fresh slot a crossing,
//! not three. A slot is only the sort key and the body's index (16 bytes), so the sorts and
//! the merge move little; once the order is settled the bounds are gathered beside it.
//!
//! # Determinism
//! The order is `(strip, min.x as f64::total_cmp, upper, local)`, `local` the body's index in
//! the list's key order: a function of the input.

use super::sorted::{self, order_key};
use super::strip_reach::{Fate, Reach};
use super::strip_slot::Slot;
use super::{BodyEntry, Member, member};

/// No index: a body gone from a list.
const NONE: u32 = u32::MAX;

/// One list: bodies sorted by strip, then by `min.x`.
#[derive(Debug, Default, Clone)]
pub(super) struct StripList {
    /// The call the list was last brought up to (moving bodies).
    pub(super) frame: u64,
    /// `1 / H` of the current order (0: one strip).
    pub(super) inv_h: f64,
    /// The slots' sort keys, sorted.
    order: Vec<Slot>,
    /// The slots' bounds in `order`'s order, gathered once the order is settled: the sweeps
    /// read this one array in sequence.
    swept: Vec<Swept>,
    /// The keys of the list's bodies at the last update, in key order (`local` indexes it).
    keys: Vec<u64>,
    /// Each body's lower strip and whether it has an upper slot, by `local`, at the last
    /// update (moving lists); and the buffer it is remade in when the bodies change.
    reach: Vec<Reach>,
    reach_next: Vec<Reach>,
    /// The widest body's `max.x - min.x` (at least 0; NaN ignored).
    pub(super) width: f64,
    /// `(strip, first slot)` of each run of one strip, in order, then `(_, order.len())`.
    runs: Vec<(i32, u32)>,
    /// Update buffers: old local to new; this call's `min.x` keys and what becomes of each
    /// body's slots (its [`Fate`]'s code), by `local`; the bodies that reach other strips
    /// than last time; fresh slots; the merge.
    remap: Vec<u32>,
    x: Vec<u64>,
    fate: Vec<u8>,
    moved: Vec<(u32, Reach)>,
    fresh: Vec<Slot>,
    merged: Vec<Slot>,
}

/// What a sweep reads of a body, in list order: 40 bytes, where the bounds alone are 32 (the
/// gather writes every slot each frame and the sweeps read them; 16 bytes more cost rain-10000
/// 1% to 5%).
///
/// Along x only the two keys: `min <= max` of two of them is `min.x <= max.x` of the
/// numbers (`max.x + 0.0` makes no `-0.0` that `total_cmp` would put first). A box with a
/// NaN anywhere overlaps nothing, as `Bounds::overlaps` says: its `min_y` is NaN, so every
/// comparison of its `y` range is false.
#[derive(Clone, Copy, Debug)]
pub(super) struct Swept {
    /// `min.x` as [`order_key`].
    pub(super) min: u64,
    /// `max.x + 0.0` as [`order_key`].
    pub(super) max: u64,
    /// `min.y`, or NaN when the box holds a NaN.
    pub(super) min_y: f64,
    /// `max.y`.
    pub(super) max_y: f64,
    /// The body's handle ([`Member::handle`]).
    pub(super) handle: u32,
    /// [`Swept::DYNAMIC`] when the body is dynamic, and [`Swept::LOWER`] when this is the
    /// body's lower slot (its `min.y` is in this strip), not its upper one: two overlapping
    /// bodies' pair is kept in this strip when one of them is (`strips.rs`, `Sink::verdict`).
    /// One byte, so a pair's two tests are one `or` of two bytes: two `bool`s made the
    /// compiler unpack them with vector instructions at every test.
    pub(super) flags: u8,
}

const _: () = assert!(size_of::<Swept>() == 40, "a slot of the sweeps stays lean");

impl Swept {
    /// A slot that overlaps nothing: room not yet written.
    const NONE: Swept = Swept {
        min: 0,
        max: 0,
        min_y: f64::NAN,
        max_y: f64::NAN,
        handle: 0,
        flags: 0,
    };

    /// [`Swept::flags`]: the body is dynamic.
    pub(super) const DYNAMIC: u8 = 1;
    /// [`Swept::flags`]: this is the body's lower slot.
    pub(super) const LOWER: u8 = 2;

    #[inline]
    fn new(m: Member, lower: bool) -> Swept {
        let b = &m.bounds;
        let numbers = !(b.min.x.is_nan() || b.max.x.is_nan() || b.max.y.is_nan());
        Swept {
            min: order_key(b.min.x),
            max: order_key(b.max.x + 0.0),
            min_y: if numbers { b.min.y } else { f64::NAN },
            max_y: b.max.y,
            handle: m.handle,
            flags: (u8::from(m.dynamic) * Swept::DYNAMIC) | (u8::from(lower) * Swept::LOWER),
        }
    }

    /// `min.x` again: [`order_key`] undone, the same bits.
    #[inline]
    pub(super) fn min_x(&self) -> f64 {
        sorted::from_order_key(self.min)
    }
}

impl StripList {
    /// A list of static `members` (in key order), fully sorted.
    pub(super) fn statics(members: &[Member], inv_h: f64) -> StripList {
        let mut list = StripList {
            inv_h,
            ..StripList::default()
        };
        for (i, m) in members.iter().enumerate() {
            let reach = Reach::of(&m.bounds, inv_h);
            let (lower, upper) = Slot::both(reach, order_key(m.bounds.min.x), i as u32);
            list.order.push(lower);
            list.order.extend(upper);
        }
        list.order.sort_unstable();
        list.swept = list
            .order
            .iter()
            .map(|s| Swept::new(members[s.local() as usize], s.is_lower()))
            .collect();
        list.width = members
            .iter()
            .map(|m| m.bounds.max.x - m.bounds.min.x)
            .fold(0.0, f64::max);
        list.find_runs();
        list
    }

    /// Reconciles the list with this call's bodies (`handles` into `bodies`, key order) and
    /// strip height: bodies gone are dropped, and every slot in a strip its body still
    /// reaches gets its new key (its role turned if need be, [`Fate`]); the others leave, and
    /// a strip newly reached gets a fresh slot, sorted apart and merged in during the same
    /// pass. One insertion sort then orders the list, and the bounds are gathered in the new
    /// order. Returns the insertion sort's moves (the fresh slots' included).
    pub(super) fn update(&mut self, handles: &[u32], bodies: &[BodyEntry], inv_h: f64) -> u64 {
        self.inv_h = inv_h;
        self.fresh.clear();
        // Usually the bodies are the same as last time: their keys are checked in the same
        // pass that reads their bounds, and only when one differs is the list reconciled
        // and the pass made again.
        let same = self.keys.len() == handles.len() && self.reach.len() == handles.len();
        if !(same && self.read_bodies(handles, bodies, inv_h)) {
            self.reconcile(handles, bodies);
            let read = self.read_bodies(handles, bodies, inv_h);
            debug_assert!(read, "the reconciled keys are the bodies'");
        }
        // The moved bodies: what becomes of their slots, and their slots in strips they did
        // not reach, made and sorted apart (a few hundred among thousands).
        for &(local, now) in &self.moved {
            let l = local as usize;
            let fate = Fate::of(self.reach[l], now);
            self.fate[l] = fate.code;
            self.reach[l] = now;
            let (lower, upper) = Slot::both(now, self.x[l], local);
            if fate.new_lower {
                self.fresh.push(lower);
            }
            if fate.new_upper {
                self.fresh.extend(upper);
            }
        }
        self.fresh.sort_unstable();
        self.merge_moved();
        let moves = sorted::insertion_sort(&mut self.order, Slot::cmp);
        #[cfg(debug_assertions)]
        self.check_order();
        self.gather(handles, bodies);
        self.find_runs();
        moves
    }

    /// Debug builds, lists of up to 1,024 slots (the broad-phase tests' scenes; the debug
    /// build's big scenes would sort their list again every frame): the list is every
    /// body's slots made afresh from its reach and key, sorted.
    #[cfg(debug_assertions)]
    fn check_order(&self) {
        if self.order.len() > 1024 {
            return;
        }
        let mut afresh = Vec::with_capacity(self.order.len());
        for (local, (&reach, &x)) in self.reach.iter().zip(&self.x).enumerate() {
            let (lower, upper) = Slot::both(reach, x, local as u32);
            afresh.push(lower);
            afresh.extend(upper);
        }
        afresh.sort_unstable();
        assert!(
            self.order == afresh,
            "the kept list is its slots made afresh"
        );
    }

    /// One pass over the list in its order, into `merged`, which becomes the list: each slot
    /// gets its body's new key from `x` (8 bytes a body, where the bodies are 48), the slots
    /// of strips their bodies left leave, and the fresh slots come in. A fresh slot goes
    /// before the first old slot (kept or leaving, at its new key) that it sorts before: the
    /// kept slots are nearly sorted (their keys moved a little), so the list is nearly sorted
    /// too, and the insertion sort that follows puts it in order. The result is the one
    /// sorted list of its slots (the body breaks ties), however the fresh ones were placed. A
    /// body whose `min.x` jumped far (a wrap along x) costs that sort a walk over its run.
    ///
    /// Every kept slot is written at the cursor without a branch (a leaving slot is written
    /// too, and the cursor stays: it is at most the old slots before it plus the fresh ones,
    /// so within the room of both lists). `merged` keeps its length from call to call, so
    /// only growth is filled.
    ///
    /// The next fresh slot is kept at hand ([`Slot::GONE`] once they are all in: no slot sorts
    /// after it, as a body's index is below `2^31 - 1`), and the rare slot it goes before
    /// sends the walk out of line to [`put_fresh`]. Never inlined either. With the fresh
    /// slots' loop in line, and this one in line in [`StripList::update`], the compiler kept
    /// the loop's state on the stack and loaded it again at every slot: rain-10000's merge
    /// took 800,000 instructions a frame, where it takes 560,000.
    #[inline(never)]
    fn merge_moved(&mut self) {
        let room = self.order.len() + self.fresh.len();
        if self.merged.len() < room {
            self.merged.resize(room, Slot::GONE);
        }
        let (fresh, merged) = (&self.fresh[..], &mut self.merged[..room]);
        // The columns as local slices (read through `self`, they were loaded again at every
        // slot), of the same length: one bounds check for both.
        let xs = &self.x[..];
        let fates = &self.fate[..xs.len()];
        let (mut w, mut f) = (0, 0);
        let mut next = fresh.first().copied().unwrap_or(Slot::GONE);
        for &old in &self.order {
            let local = old.local() as usize;
            let fate = Fate::slot_bits(fates[local], !old.is_lower());
            let new = old.at_x(xs[local]).turned(fate & Fate::TURNS != 0);
            debug_assert!(new < Slot::GONE, "no slot sorts after the last fresh one");
            if next < new {
                (w, f, next) = put_fresh(merged, fresh, (w, f), new);
            }
            merged[w] = new;
            w += usize::from(fate & Fate::STAYS);
        }
        for &s in &fresh[f..] {
            merged[w] = s;
            w += 1;
        }
        std::mem::swap(&mut self.order, &mut self.merged);
        self.order.truncate(w);
    }

    /// [`StripList::update`]'s pass over the bodies, in key order, in sequence: each body's
    /// `min.x` key and the strips it reaches. A body that reaches other strips than last time
    /// (or is new) is `moved`, with its new reach (written to `reach` once the pass is
    /// through). A slot is numbers only (strip, key, body), so when `H` changed, a body whose
    /// strips have the same numbers as before keeps its slots. Returns false, having changed
    /// nothing the next pass reads, at the first body whose key is not the list's.
    fn read_bodies(&mut self, handles: &[u32], bodies: &[BodyEntry], inv_h: f64) -> bool {
        let n = handles.len();
        // Written in place, by body: the columns keep their length from call to call, so no
        // length is stored a body.
        self.x.resize(n, 0);
        self.fate.resize(n, Fate::SAME);
        self.moved.clear();
        let (keys, reach) = (&self.keys[..n], &self.reach[..n]);
        let out = (&mut self.x[..], &mut self.fate[..], &mut self.moved);
        // Read without the handles when they are every body: the loop's state then fits in
        // registers.
        if every_body(handles, bodies) {
            read_into(bodies.iter(), (keys, reach), out, inv_h)
        } else {
            let each = handles.iter().map(|&h| &bodies[h as usize]);
            read_into(each, (keys, reach), out, inv_h)
        }
    }

    /// [`StripList::update`]'s first step when the bodies are not the same as last time:
    /// merges the old keys with the new ones (both ascending), drops the slots of bodies
    /// gone, renumbers the kept ones, and gives each body new to the list (it has no slot
    /// yet) [`Reach::NONE`], so that it is made as a moved one.
    fn reconcile(&mut self, handles: &[u32], bodies: &[BodyEntry]) {
        self.remap.clear();
        self.remap.resize(self.keys.len(), NONE);
        let mut reach = std::mem::take(&mut self.reach_next);
        reach.clear();
        // A body new to the list has no slot: a reach no body has makes it a moved one.
        reach.resize(handles.len(), Reach::NONE);
        let (remap, was) = (&mut self.remap, &self.reach);
        sorted::match_keys(
            &self.keys,
            handles,
            bodies,
            |i, j| {
                remap[i] = j as u32;
                reach[j] = was[i];
            },
            |_, _| {},
        );
        self.reach_next = std::mem::replace(&mut self.reach, reach);
        self.keys.clear();
        self.keys
            .extend(handles.iter().map(|&h| bodies[h as usize].key));
        for s in &mut self.order {
            let j = self.remap[s.local() as usize];
            *s = if j == NONE {
                Slot::GONE
            } else {
                s.with_local(j)
            };
        }
        self.order.retain(|&s| s != Slot::GONE);
    }

    /// Reads the bodies' bounds in list order into `swept`, and the widest body.
    fn gather(&mut self, handles: &[u32], bodies: &[BodyEntry]) {
        // Written in place (only growth is filled), the widest body in a local: through
        // `extend`, the loop was a call that kept it in memory, and read the body's bounds
        // again after each store to it.
        let n = self.order.len();
        self.swept.resize(n, Swept::NONE);
        if every_body(handles, bodies) {
            self.width = gather_into(&mut self.swept, &self.order, |local| local, bodies);
        } else {
            let at = |local: u32| handles[local as usize];
            self.width = gather_into(&mut self.swept, &self.order, at, bodies);
        }
    }

    /// Finds the runs of one strip in `order`. The slots sort by strip first, so each run's
    /// end is found by a galloping search from its start: about `2 log2(run)` reads a run
    /// (a hundred runs of a hundred slots at 10,000 drops of rain) instead of one a slot.
    fn find_runs(&mut self) {
        self.runs.clear();
        let mut k = 0;
        while k < self.order.len() {
            let strip = self.order[k].strip();
            self.runs.push((strip, k as u32));
            k += sorted::gallop(&self.order[k..], |s| s.strip() == strip);
        }
        self.runs.push((i32::MAX, self.order.len() as u32));
        #[cfg(debug_assertions)]
        {
            // Every slot in the run that holds it, every run one strip, in order.
            for r in 0..self.runs.len() - 1 {
                let ((strip, start), (_, end)) = (self.runs[r], self.runs[r + 1]);
                assert!(start < end, "a run holds a slot");
                let run = &self.order[start as usize..end as usize];
                assert!(run.iter().all(|s| s.strip() == strip), "one strip a run");
                assert!(r == 0 || self.runs[r - 1].0 < strip, "runs in strip order");
            }
        }
    }

    /// The strip of run `r`.
    #[inline]
    pub(super) fn run_strip(&self, r: usize) -> i32 {
        self.runs[r].0
    }

    /// The bodies of run `r`, and its strip.
    #[inline]
    pub(super) fn run(&self, r: usize) -> (i32, &[Swept]) {
        let (strip, start) = self.runs[r];
        (
            strip,
            &self.swept[start as usize..self.runs[r + 1].1 as usize],
        )
    }

    /// How many runs.
    #[inline]
    pub(super) fn run_count(&self) -> usize {
        self.runs.len() - 1
    }

    /// The heap bytes the list holds (capacities, its update buffers included), for the
    /// broad-phase study.
    pub(super) fn heap_bytes(&self) -> usize {
        let slots = self.order.capacity() + self.fresh.capacity() + self.merged.capacity();
        slots * size_of::<Slot>()
            + self.swept.capacity() * size_of::<Swept>()
            + self.keys.capacity() * 8
            + (self.reach.capacity() + self.reach_next.capacity()) * size_of::<Reach>()
            + self.runs.capacity() * size_of::<(i32, u32)>()
            + self.remap.capacity() * 4
            + self.moved.capacity() * size_of::<(u32, Reach)>()
            + self.x.capacity() * 8
            + self.fate.capacity()
    }
}

/// Whether the list's `handles` are every one of `bodies`, in order: they ascend (key order)
/// within `bodies`, so as many of them are all of them. Then a body is read by its index in
/// the list, without the handles.
fn every_body(handles: &[u32], bodies: &[BodyEntry]) -> bool {
    let every = handles.len() == bodies.len();
    debug_assert!(!every || handles.iter().enumerate().all(|(k, &h)| h as usize == k));
    every
}

/// [`StripList::read_bodies`]' loop over the list's bodies in key order (`bodies`), with
/// their keys and reach at the last update: false at the first body whose key differs.
#[inline(always)]
fn read_into<'a>(
    bodies: impl Iterator<Item = &'a BodyEntry>,
    (keys, reach): (&[u64], &[Reach]),
    (xs, fates, moved): (&mut [u64], &mut [u8], &mut Vec<(u32, Reach)>),
    inv_h: f64,
) -> bool {
    let columns = keys.iter().zip(reach).zip(xs.iter_mut().zip(fates));
    for (j, (body, ((&key, &was), (x, fate)))) in bodies.zip(columns).enumerate() {
        if body.key != key {
            return false;
        }
        let now = Reach::of(&body.bounds, inv_h);
        if now != was {
            moved.push((j as u32, now));
        }
        *x = order_key(body.bounds.min.x);
        // A moved body's fate is written once the pass is through.
        *fate = Fate::SAME;
    }
    true
}

/// [`StripList::gather`]'s loop: each slot's bounds (its body's handle `handle(local)`) into
/// `swept`, as long as `order`; returns the widest body (NaN ignored: a maximum, so any order
/// gives it).
#[inline(always)]
fn gather_into(
    swept: &mut [Swept],
    order: &[Slot],
    handle: impl Fn(u32) -> u32,
    bodies: &[BodyEntry],
) -> f64 {
    let mut width = 0.0;
    for (out, s) in swept.iter_mut().zip(order) {
        let h = handle(s.local());
        let b = &bodies[h as usize];
        let x = b.bounds.max.x - b.bounds.min.x;
        width = if x > width { x } else { width };
        *out = Swept::new(member(b, h), s.is_lower());
    }
    width
}

/// [`StripList::merge_moved`]'s fresh slots that sort before `new`, from the `f`-th on,
/// written from the cursor `w`: returns the cursor, the next fresh slot's index, and that
/// slot ([`Slot::GONE`] when none is left).
#[cold]
#[inline(never)]
fn put_fresh(
    merged: &mut [Slot],
    fresh: &[Slot],
    (mut w, mut f): (usize, usize),
    new: Slot,
) -> (usize, usize, Slot) {
    while f < fresh.len() && fresh[f] < new {
        merged[w] = fresh[f];
        (w, f) = (w + 1, f + 1);
    }
    (w, f, fresh.get(f).copied().unwrap_or(Slot::GONE))
}
