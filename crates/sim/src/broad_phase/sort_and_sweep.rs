//! `SortAndSweep` for moving bodies: per layer, the moving bodies sorted by `min.x`, kept from
//! the previous call and re-sorted by insertion sort (nearly sorted: about `O(n)`; bodies that
//! appeared are sorted apart and merged in, and a sort that moves more than `8n` places falls
//! back to a full sort). A self-interacting layer is swept against itself. Two interacting
//! layers never look at pairs within one layer: each body of the smaller layer finds its
//! candidates in the larger one's order by binary search (`[min.x - widest, max.x]`), or,
//! when that would visit more than the larger layer holds, the two orders are swept together.

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
    /// The bodies, sorted by `(min.x, local)`: small, so the re-sort moves little.
    order: Vec<Slot>,
    /// The keys of the layer's bodies at the last update, in key order (`local` indexes it,
    /// as it does the layer's handles).
    keys: Vec<u64>,
    /// The widest body's `max.x - min.x` (at least 0; NaN ignored).
    width: f64,
}

/// A body's place in a [`SweepList`]'s order.
#[derive(Clone, Copy, Debug)]
pub(super) struct Slot {
    /// `min.x` as [`order_key`].
    min: u64,
    /// `max.x` as [`order_key`] of `max.x + 0.0`: `min <= max` exactly when `min.x <= max.x`
    /// (besides NaN, which overlaps nothing anyway).
    max: u64,
    /// The body's index among its layer's bodies, in key order.
    local: u32,
}

impl Slot {
    /// Body `local` with bounds `b`.
    #[inline]
    fn new(b: &Bounds, local: u32) -> Slot {
        Slot {
            min: order_key(b.min.x),
            max: order_key(b.max.x + 0.0),
            local,
        }
    }
}

/// The key order as tie-break, so the order is a function of the input, never of the calls
/// before.
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

    /// Hands `f` every body of the layer that can overlap `q` along x (a binary search of
    /// the sorted list, as [`sweep_cross`] does).
    #[inline]
    pub(super) fn each_along_x(&self, q: &BodyEntry, mut f: impl FnMut(&Member)) {
        let order = &self.list.order;
        let (lo, hi) = x_range(order, self.list.width, q);
        for s in &order[lo..hi] {
            f(&self.member(s.local));
        }
    }
}

impl SweepList {
    /// Reconciles the list with this call's bodies of the layer (`handles`, key order):
    /// bodies gone are dropped, bodies kept get their new bounds, new bodies are sorted and
    /// merged in. Returns the insertion sort's moves.
    pub(super) fn update(
        &mut self,
        handles: &[u32],
        bodies: &[BodyEntry],
        scratch: &mut Scratch,
    ) -> u64 {
        // The usual case: the same bodies as last time. The keys compared in the caller's
        // order, then the slots rewritten in list order (written in sequence, the bodies read
        // at random: reads overlap where scattered writes queue), and sorted with nothing
        // else to keep up to date.
        let same = self.keys.len() == handles.len()
            && handles
                .iter()
                .zip(&self.keys)
                .all(|(&h, &k)| bodies[h as usize].key == k);
        if same {
            let mut width: f64 = 0.0;
            for s in &mut self.order {
                let b = &bodies[handles[s.local as usize] as usize].bounds;
                *s = Slot::new(b, s.local);
                // A branch, not `f64::max`: rarely taken, and no dependency chain.
                let w = b.max.x - b.min.x;
                if w > width {
                    width = w;
                }
            }
            self.width = width;
            return sorted::insertion_sort(&mut self.order, sweep_order);
        }
        // Merge the old keys with the new ones (both ascending).
        let (remap, fresh) = (&mut scratch.remap, &mut scratch.fresh);
        remap.clear();
        remap.resize(self.keys.len(), NONE);
        fresh.clear();
        sorted::match_keys(
            &self.keys,
            handles,
            bodies,
            |i, j| remap[i] = j as u32,
            |j, b| fresh.push(Slot::new(&b.bounds, j as u32)),
        );
        self.keys.clear();
        self.keys
            .extend(handles.iter().map(|&h| bodies[h as usize].key));
        self.order.retain_mut(|s| {
            let j = remap[s.local as usize];
            if j != NONE {
                *s = Slot::new(&bodies[handles[j as usize] as usize].bounds, j);
            }
            j != NONE
        });
        let moved = sorted::insertion_sort(&mut self.order, sweep_order);
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
        self.width = 0.0;
        for &h in handles {
            let b = &bodies[h as usize].bounds;
            self.width = self.width.max(b.max.x - b.min.x);
        }
        moved
    }

    /// The heap bytes the list holds (capacities), for the broad-phase study.
    pub(super) fn heap_bytes(&self) -> usize {
        self.order.capacity() * size_of::<Slot>() + self.keys.capacity() * 8
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
/// list's bodies find few candidates by binary search in the larger (a hundred bullets among
/// ten thousand asteroids), that is all; otherwise the two lists are walked in merged order,
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
    for &h in small.handles {
        let (lo, hi) = x_range(&large.list.order, large.list.width, &x.bodies[h as usize]);
        candidates += hi - lo;
        if candidates > large.handles.len() {
            return sweep_merged(x, y, out);
        }
        ranges.push((lo as u32, hi as u32));
    }
    let mut tested = 0;
    for (&h, &(lo, hi)) in small.handles.iter().zip(ranges.iter()) {
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
