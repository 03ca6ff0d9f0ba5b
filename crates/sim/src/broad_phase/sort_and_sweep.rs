//! `SortAndSweep` for moving bodies: per layer, the moving bodies sorted along x, kept from
//! the previous call and re-sorted by insertion sort (nearly sorted: about `O(n)`; bodies that
//! appeared are sorted apart and merged in, and a sort that moves more than `8n` places falls
//! back to a full sort). A self-interacting layer is swept against itself. Two interacting
//! layers never look at pairs within one layer: each body of the smaller layer, in its own
//! sorted order, finds its candidates in the larger one's order by binary search
//! (`[min.x - widest, max.x]`), or, when that would visit more than the larger layer holds,
//! the two orders are swept together.
//!
//! **Kept x ranges.** A body's place in the order is not its exact `[min.x, max.x]` but an
//! enlarged range (the exact one widened by half its width on each side), kept from
//! call to call while the exact range stays inside it: a body that moved a little costs two
//! comparisons and leaves the order as it was, and a call where no range was renewed sorts
//! nothing. The enlarged ranges only choose the candidates; every candidate is tested with
//! its exact bounds, so the pairs are exactly those of the exact ranges. (Half a width: on
//! asteroids-10000 a quarter renewed so many ranges a frame that the update cost more
//! instructions than re-sorting exact ranges; half renews fewer and widens the
//! bullets' search windows.)

use std::cmp::Ordering;

use ricochet_geom::Bounds;

use super::sorted::{self, order_key};
use super::{BodyEntry, Member, Scratch, member};

/// No index: a body gone from a layer's list.
const NONE: u32 = u32::MAX;

/// `SortAndSweep`: one layer's moving bodies, kept across calls.
#[derive(Debug, Default, Clone)]
pub(super) struct SweepList {
    /// The call the list was last brought up to.
    pub(super) frame: u64,
    /// The bodies, sorted by `(min, local)` of their kept ranges: small, so the re-sort moves
    /// little.
    order: Vec<Slot>,
    /// The keys of the layer's bodies at the last update, in key order (`local` indexes it,
    /// as it does the layer's handles).
    keys: Vec<u64>,
    /// At least the widest kept range (`max - min` as `f64`, at least 0; NaN ignored).
    width: f64,
}

/// A body's place in a [`SweepList`]'s order: its kept x range, which holds its exact
/// `[min.x, max.x]` (see the module docs).
#[derive(Clone, Copy, Debug)]
pub(super) struct Slot {
    /// The range's start as [`order_key`].
    min: u64,
    /// The range's end as [`order_key`] of `end + 0.0`: `min <= max` exactly when the start
    /// is at most the end (besides NaN, which overlaps nothing anyway).
    max: u64,
    /// The body's index among its layer's bodies, in key order.
    local: u32,
}

impl Slot {
    /// Body `local` with bounds `b`: its exact x range widened by half its width on
    /// each side (not at all when the width is not finite). Returns the slot and the width
    /// of its range.
    #[inline]
    fn kept(b: &Bounds, local: u32) -> (Slot, f64) {
        let w = b.max.x - b.min.x;
        // `x - m <= x <= x + m` for `m >= 0` in any rounding, so the range holds the exact
        // one; a NaN bound stays NaN (and overlaps nothing).
        let m = if w.is_finite() && w > 0.0 {
            w * 0.5
        } else {
            0.0
        };
        let (lo, hi) = (b.min.x - m, b.max.x + m);
        let slot = Slot {
            min: order_key(lo),
            max: order_key(hi + 0.0),
            local,
        };
        (slot, hi - lo)
    }

    /// Whether the slot's range still holds `b`'s x range (compared as keys, in the total
    /// order).
    #[inline]
    fn holds(&self, b: &Bounds) -> bool {
        order_key(b.min.x) >= self.min && order_key(b.max.x + 0.0) <= self.max
    }

    /// The slot of `b` for body `local`: this one, renumbered, while it holds `b`, else a new
    /// kept range, its width taken into `width`. `true` when the range is new.
    #[inline]
    fn renewed(&mut self, b: &Bounds, local: u32, width: &mut f64) -> bool {
        self.local = local;
        if self.holds(b) {
            return false;
        }
        let (s, w) = Slot::kept(b, local);
        *self = s;
        // A branch, not `f64::max`: rarely taken, and no dependency chain.
        if w > *width {
            *width = w;
        }
        true
    }

    /// The width of the slot's range, from its keys.
    fn width(&self) -> f64 {
        from_key(self.max) - from_key(self.min)
    }
}

/// The `f64` whose [`order_key`] is `k`.
#[inline]
fn from_key(k: u64) -> f64 {
    f64::from_bits(if k >> 63 == 1 { k ^ (1 << 63) } else { !k })
}

/// The key order as tie-break, so the order is a function of the ranges, never of how the
/// insertion sort met them.
#[inline]
fn sweep_order(a: &Slot, b: &Slot) -> Ordering {
    a.min.cmp(&b.min).then(a.local.cmp(&b.local))
}

/// A [`SweepList`] with this call's bodies of its layer.
#[derive(Clone, Copy)]
pub(super) struct SweepView<'a> {
    /// The layer's list.
    pub(super) list: &'a SweepList,
    /// The layer's bodies (handles into `bodies`), in key order.
    pub(super) handles: &'a [u32],
    /// The caller's bodies.
    pub(super) bodies: &'a [BodyEntry],
}

impl SweepView<'_> {
    /// The body `local` of the layer.
    #[inline]
    fn member(&self, local: u32) -> Member {
        let h = self.handles[local as usize];
        member(&self.bodies[h as usize], h)
    }
}

impl SweepList {
    /// Reconciles the list with this call's bodies of the layer (`handles`, key order):
    /// bodies gone are dropped, bodies kept keep their range while it holds their new bounds
    /// (else get a new one), new bodies are sorted and merged in. Returns the insertion
    /// sort's moves, or, with the same bodies as the last call, the ranges renewed.
    pub(super) fn update(
        &mut self,
        handles: &[u32],
        bodies: &[BodyEntry],
        scratch: &mut Scratch,
    ) -> u64 {
        // The usual case: the same bodies as last time (the keys compared in the caller's
        // order).
        let same = self.keys.len() == handles.len()
            && handles
                .iter()
                .zip(&self.keys)
                .all(|(&h, &k)| bodies[h as usize].key == k);
        if same {
            return self.renew(handles, bodies, scratch);
        }
        // Merge the old keys with the new ones (both ascending).
        let (remap, fresh) = (&mut scratch.remap, &mut scratch.fresh);
        remap.clear();
        remap.resize(self.keys.len(), NONE);
        fresh.clear();
        let mut i = 0;
        for (j, &h) in handles.iter().enumerate() {
            let b = &bodies[h as usize];
            while i < self.keys.len() && self.keys[i] < b.key {
                i += 1;
            }
            if i < self.keys.len() && self.keys[i] == b.key {
                remap[i] = j as u32;
                i += 1;
            } else {
                fresh.push(Slot::kept(&b.bounds, j as u32).0);
            }
        }
        self.keys.clear();
        self.keys
            .extend(handles.iter().map(|&h| bodies[h as usize].key));
        let mut unused = 0.0;
        self.order.retain_mut(|s| {
            let j = remap[s.local as usize];
            if j != NONE {
                s.renewed(&bodies[handles[j as usize] as usize].bounds, j, &mut unused);
            }
            j != NONE
        });
        let moved = sorted::insertion_sort(&mut self.order, sweep_order, |_, _| {});
        if !fresh.is_empty() {
            fresh.sort_unstable_by(sweep_order);
            let merged = &mut scratch.merged;
            merged.clear();
            merged.reserve(self.order.len() + fresh.len());
            let (mut i, mut j) = (0, 0);
            while i < self.order.len() && j < fresh.len() {
                if sweep_order(&self.order[i], &fresh[j]) == Ordering::Less {
                    merged.push(self.order[i]);
                    i += 1;
                } else {
                    merged.push(fresh[j]);
                    j += 1;
                }
            }
            merged.extend_from_slice(&self.order[i..]);
            merged.extend_from_slice(&fresh[j..]);
            std::mem::swap(&mut self.order, merged);
        }
        // The widest range of the bodies now in the list.
        self.width = 0.0;
        for s in &self.order {
            let w = s.width();
            if w > self.width {
                self.width = w;
            }
        }
        moved
    }

    /// [`SweepList::update`] with the same bodies as the last call: each slot whose range
    /// still holds its body stays (closed up in one pass, in order), the others get new
    /// ranges, are sorted apart and merged back in (a binary search and a block copy each).
    /// Returns the ranges renewed.
    fn renew(&mut self, handles: &[u32], bodies: &[BodyEntry], scratch: &mut Scratch) -> u64 {
        let renewed = &mut scratch.fresh;
        renewed.clear();
        let mut width = self.width;
        let mut kept = 0;
        for r in 0..self.order.len() {
            let s = self.order[r];
            let b = &bodies[handles[s.local as usize] as usize].bounds;
            if s.holds(b) {
                self.order[kept] = s;
                kept += 1;
            } else {
                let (s, w) = Slot::kept(b, s.local);
                renewed.push(s);
                // A branch, not `f64::max`: rarely taken, and no dependency chain.
                if w > width {
                    width = w;
                }
            }
        }
        // Only grows while the bodies stay: at least the widest range, never less.
        self.width = width;
        if renewed.is_empty() {
            return 0;
        }
        self.order.truncate(kept);
        renewed.sort_unstable_by(sweep_order);
        let merged = &mut scratch.merged;
        merged.clear();
        merged.reserve(self.order.len() + renewed.len());
        let mut rest = &self.order[..];
        for s in renewed.iter() {
            let before = rest.partition_point(|o| sweep_order(o, s) == Ordering::Less);
            merged.extend_from_slice(&rest[..before]);
            merged.push(*s);
            rest = &rest[before..];
        }
        merged.extend_from_slice(rest);
        std::mem::swap(&mut self.order, merged);
        renewed.len() as u64
    }
}

/// Tests `p` (whose `max.x` key is `max`) against the bodies of `others` (sorted) ahead of
/// it, until one starts past its end along x. Returns the tests.
#[inline]
fn scan(p: &Member, max: u64, others: &[Slot], v: SweepView, out: &mut Vec<(u32, u32)>) -> u64 {
    let mut tested = 0;
    for s in others {
        if s.min > max {
            break;
        }
        let q = v.member(s.local);
        if p.dynamic || q.dynamic {
            tested += 1;
            if p.bounds.overlaps(&q.bounds) {
                out.push((p.handle, q.handle));
            }
        }
    }
    tested
}

/// All overlapping pairs within one list with a dynamic body. Returns the tests.
pub(super) fn sweep_self(v: SweepView, out: &mut Vec<(u32, u32)>) -> u64 {
    let mut tested = 0;
    let order = &v.list.order;
    for (k, s) in order.iter().enumerate() {
        let rest = &order[k + 1..];
        // Most bodies overlap nothing ahead: look at the body only when something starts
        // before its end.
        if rest.first().is_some_and(|next| next.min <= s.max) {
            tested += scan(&v.member(s.local), s.max, rest, v, out);
        }
    }
    tested
}

/// All overlapping pairs with one body from each list (and a dynamic one). When the smaller
/// list's bodies, taken in their list's order, find few candidates by binary search in the
/// larger (a hundred bullets among ten thousand asteroids), that is all; otherwise the two lists are walked in merged order,
/// each body scanning only the other list ahead of it.
pub(super) fn sweep_cross(
    x: SweepView,
    y: SweepView,
    ranges: &mut Vec<(u32, u32)>,
    out: &mut Vec<(u32, u32)>,
) -> u64 {
    let (small, large) = if x.handles.len() <= y.handles.len() {
        (x, y)
    } else {
        (y, x)
    };
    ranges.clear();
    let mut candidates = 0;
    // The small layer in its own order along x: the searches, and the candidates they
    // find, move along the large order instead of jumping about it (fewer cache misses).
    let queries = || {
        small
            .list
            .order
            .iter()
            .map(|s| small.handles[s.local as usize])
    };
    for h in queries() {
        let (lo, hi) = x_range(&large.list.order, large.list.width, &x.bodies[h as usize]);
        candidates += hi - lo;
        if candidates > large.handles.len() {
            return sweep_merged(x, y, out);
        }
        ranges.push((lo as u32, hi as u32));
    }
    let mut tested = 0;
    for (h, &(lo, hi)) in queries().zip(ranges.iter()) {
        let q = member(&x.bodies[h as usize], h);
        for s in &large.list.order[lo as usize..hi as usize] {
            let m = large.member(s.local);
            if q.dynamic || m.dynamic {
                tested += 1;
                if q.bounds.overlaps(&m.bounds) {
                    out.push((q.handle, m.handle));
                }
            }
        }
    }
    tested
}

/// The slots of `order` (sorted, none wider than `width`) that can overlap `q` along x:
/// `order[lo..hi]`. Conservative by a relative margin far above rounding error.
fn x_range(order: &[Slot], width: f64, q: &BodyEntry) -> (usize, usize) {
    let q = &q.bounds;
    if [q.min.x, q.min.y, q.max.x, q.max.y]
        .iter()
        .any(|v| v.is_nan())
    {
        return (0, 0); // overlaps nothing
    }
    // Bodies starting before `lower` end before `q.min.x`.
    let mut lower = q.min.x - width * (1.0 + 1e-12);
    lower -= lower.abs() * 1e-12 + f64::MIN_POSITIVE;
    let (lower, upper) = (order_key(lower), order_key(q.max.x + 0.0));
    let lo = order.partition_point(|s| s.min < lower);
    let hi = order.partition_point(|s| s.min <= upper);
    (lo, hi.max(lo))
}

/// The merged walk of [`sweep_cross`].
fn sweep_merged(x: SweepView, y: SweepView, out: &mut Vec<(u32, u32)>) -> u64 {
    let mut tested = 0;
    let (xs, ys) = (&x.list.order, &y.list.order);
    let (mut i, mut j) = (0, 0);
    while i < xs.len() && j < ys.len() {
        if xs[i].min <= ys[j].min {
            if ys[j].min <= xs[i].max {
                tested += scan(&x.member(xs[i].local), xs[i].max, &ys[j..], y, out);
            }
            i += 1;
        } else {
            if xs[i].min <= ys[j].max {
                tested += scan(&y.member(ys[j].local), ys[j].max, &xs[i..], x, out);
            }
            j += 1;
        }
    }
    tested
}
