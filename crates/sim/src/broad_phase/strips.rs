//! `Strips`: sort and sweep in horizontal strips.
//!
//! Space is cut into horizontal strips of height `H`, a power of two at least as tall as
//! every body (one `H` per call for every list, so lists can be swept against each other;
//! `strip_height.rs`). A body is filed in every strip its bounds reach: the strip of its
//! `min.y`, and the next one too when its top is there (`strip_list.rs`). Each list (one
//! layer's moving bodies, or one layer's static bodies) is sorted by `(strip, min.x)`. Two
//! boxes that overlap both reach the strip of `max(p.min.y, q.min.y)`: a list is swept
//! within each strip, two lists strip against the same strip, and a pair found is kept only
//! in that strip (so once). Where a single sort axis would test every body sharing an x
//! range (rain: thousands of drops over the same x range, falling in y), a strip holds only
//! the bodies within `H` in y of each other.
//!
//! Filing a body in both strips it reaches costs a second slot for one body in
//! `height / H`; it spares sweeping every strip against the next: at 10,000 drops of rain,
//! that walk of two runs at once (a branch on which run comes next, mispredicted half the
//! time) was the broad phase's largest cost.
//!
//! Two runs of very different sizes (a hundred actors over a floor of thousands of tiles)
//! are not walked together: each body of the smaller one finds its candidates in the larger
//! by binary search (`[min.x - widest, max.x]`).
//!
//! # Why two strips are enough
//! `H` is an exact power of two (so `y / H` is exact: a multiplication by a power of two),
//! at least `1 + 1e-9` times the tallest body's computed height, so `max.y < min.y + H` and
//! `floor(max.y / H)` is at most `floor(min.y / H) + 1`. If `p` and `q` overlap, `y =
//! max(p.min.y, q.min.y)` is in both `[min.y, max.y]` ranges, and floor is monotone, so
//! its strip is one each reaches. Strips are clamped to `i32`, which is monotone too. A body
//! with NaN or inverted bounds overlaps nothing and has one slot. With an infinite or NaN
//! height, or none below `2^1000`, there is one strip: plain sort and sweep.
//!
//! # Determinism
//! Orders are by `(strip, min.x as f64::total_cmp, upper, local)`: a function of the input.

use super::sorted::{lower_bounds, order_key};
use super::strip_height::{extent, inv_strip_height, restrip};
use super::strip_list::{StripList, Swept};
use super::{BodyEntry, BroadPhase, BroadPhaseStats, Extent, LAYERS, Member, STATIC_BIT, of_layer};

/// Where the sweeps of one call put their pairs, strip by strip. Both bodies of an
/// overlapping pair reach the strip of `max(p.min.y, q.min.y)` (`strip_list.rs`), and the
/// pair is kept there only: a pair sharing two strips is found in both and kept once.
///
/// That strip is this one when one of the two slots is its body's lower slot (its `min.y`
/// is in this strip), and the one below when both are upper slots (both `min.y` are in the
/// strip below): `floor(max(a, b) / H)` is `max(floor(a / H), floor(b / H))`, floor being
/// monotone. So the rule is one flag of each slot, not a strip computed a pair.
///
/// The pairs are written without a branch on the verdict: each tested pair is written at
/// `len`, and `len` moves past it only when it is kept. So `out` holds written slots past
/// `len` while the sink lives, and is cut back to `len` when it is dropped.
struct Sink<'a> {
    out: &'a mut Vec<(u32, u32)>,
    /// The pairs kept: `out`'s length once the sink is dropped.
    len: usize,
    /// What the debug check of the rule needs ([`Rule`]).
    rule: Rule,
}

/// What the debug check of [`Sink`]'s rule needs: the strip swept and `1 / H` (nothing in a
/// release build).
#[derive(Clone, Copy)]
struct Rule {
    #[cfg(debug_assertions)]
    strip: i32,
    #[cfg(debug_assertions)]
    inv_h: f64,
}

impl Rule {
    /// Whether the pair of `p` and `q` is kept (one is dynamic, their bounds overlap and
    /// this is their strip), and the tests it counts: 1 when one is dynamic and `q` starts
    /// before `p`'s end along x (always so for a slot that [`Sink::scan`] reaches), else 0.
    ///
    /// Without a branch: whether bounds overlap is a coin toss for the sweeps' candidates,
    /// and a mispredicted branch a test cost more than the test (see [`Sink`]).
    #[cfg_attr(not(debug_assertions), allow(clippy::unused_self))]
    #[inline(always)]
    fn verdict(self, p: &Swept, q: &Swept) -> (bool, u64) {
        let flags = p.flags | q.flags;
        let either = flags & Swept::DYNAMIC != 0;
        let starts = q.min <= p.max;
        // `Bounds::overlaps`, x by the keys (`strip_list.rs`, `Swept`).
        let overlap = (p.min <= q.max) & starts & (p.min_y <= q.max_y) & (q.min_y <= p.max_y);
        #[cfg(debug_assertions)]
        if overlap {
            // Overlapping bounds hold no NaN.
            let top = p.min_y.max(q.min_y);
            assert_eq!(
                super::grid::cell_coord(top, self.inv_h) == self.strip,
                flags & Swept::LOWER != 0,
                "the pair's strip is this one when one slot is a lower one"
            );
        }
        (
            either & overlap & (flags & Swept::LOWER != 0),
            u64::from(either & starts),
        )
    }
}

impl<'a> Sink<'a> {
    /// A sink for the sweeps of one call at `1 / H` = `inv_h` (kept for the debug check of
    /// the rule only).
    #[cfg_attr(not(debug_assertions), allow(unused_variables))]
    fn new(out: &'a mut Vec<(u32, u32)>, inv_h: f64) -> Sink<'a> {
        Sink {
            len: out.len(),
            out,
            rule: Rule {
                #[cfg(debug_assertions)]
                strip: 0,
                #[cfg(debug_assertions)]
                inv_h,
            },
        }
    }

    /// The sweeps that follow are of `strip` (kept for the debug check of the rule only).
    #[cfg_attr(not(debug_assertions), allow(unused_variables))]
    #[inline]
    fn at(&mut self, strip: i32) -> &mut Self {
        #[cfg(debug_assertions)]
        {
            self.rule.strip = strip;
        }
        self
    }

    /// [`Rule::verdict`] of this sink's strip.
    #[inline(always)]
    fn verdict(&self, p: &Swept, q: &Swept) -> (bool, u64) {
        self.rule.verdict(p, q)
    }

    /// Writes the pair of `p` and `q`, kept (`len` past it) when `keep`. The caller made
    /// room.
    #[inline(always)]
    fn put(&mut self, p: &Swept, q: &Swept, keep: bool) {
        self.out[self.len] = (p.handle, q.handle);
        self.len += usize::from(keep);
    }

    /// Tests `p` and `q` ([`Sink::verdict`]), keeping the pair when it is. Returns the tests.
    #[inline]
    fn test(&mut self, p: &Swept, q: &Swept) -> u64 {
        let (keep, tested) = self.verdict(p, q);
        room(self.out, self.len + 1);
        self.put(p, q, keep);
        tested
    }

    /// Tests `p` against the slots of `others` (sorted by `min.x`) until one starts past
    /// `p`'s end along x.
    #[inline]
    fn scan(&mut self, p: &Swept, others: &[Swept]) -> u64 {
        let mut tested = 0;
        for s in others {
            if s.min > p.max {
                break;
            }
            tested += self.test(p, s);
        }
        tested
    }

    /// [`Sink::scan`] out of line: the rare walk past the next slot. In line, the compiler
    /// kept `p`'s fields on the stack for it in every step of [`Sink::within`].
    #[inline(never)]
    fn scan_on(&mut self, p: &Swept, others: &[Swept]) -> u64 {
        self.scan(p, others)
    }

    /// Every overlapping pair within one run. Each slot is tested against the next without
    /// a branch on whether that one starts before its end (a coin toss, where it was the
    /// sweeps' costliest branch); the walk goes on, out of line, only when the slot after it
    /// does too.
    fn within(&mut self, run: &[Swept]) -> u64 {
        let mut tested = 0;
        let mut k = 0;
        loop {
            // Room for every slot's test of the next: the stretch grows nothing.
            room(self.out, self.len + run.len());
            let (stop, len, t) = next_pairs(&mut self.out[..], (self.len, self.rule), run, k);
            (self.len, k) = (len, stop + 1);
            tested += t;
            if stop + 2 >= run.len() {
                return tested;
            }
            // The slot at `stop` reaches past the next one: the rest of its walk.
            tested += self.scan_on(&run[stop], &run[stop + 2..]);
        }
    }

    /// Every overlapping pair with one slot from each run, walking both in `min.x` order.
    fn merged(&mut self, xs: &[Swept], ys: &[Swept]) -> u64 {
        let mut tested = 0;
        let (mut i, mut j) = (0, 0);
        while i < xs.len() && j < ys.len() {
            if xs[i].min <= ys[j].min {
                if ys[j].min <= xs[i].max {
                    tested += self.scan(&xs[i], &ys[j..]);
                }
                i += 1;
            } else {
                if xs[i].min <= ys[j].max {
                    tested += self.scan(&ys[j], &xs[i..]);
                }
                j += 1;
            }
        }
        tested
    }

    /// Every overlapping pair with one slot from each run, each slot of `small` finding its
    /// candidates in `large` (none wider than `width`) by binary search: [`LOCKSTEP`] slots'
    /// searches at a time, in lockstep ([`lower_bounds`]). One search alone waited for each of its
    /// reads in turn, about half of the walk of rain-10000's drops against the ground.
    fn searched(&mut self, small: &[Swept], large: &[Swept], width: f64) -> u64 {
        let mut tested = 0;
        for some in small.chunks(LOCKSTEP) {
            // The last few padded with no search (`None`, searched for 0 and not scanned).
            let lower: [Option<u64>; LOCKSTEP] =
                std::array::from_fn(|k| some.get(k).and_then(|p| lower_key(p, width)));
            let los = lower_bounds(large, |s| s.min, lower.map(|l| l.unwrap_or(0)));
            for ((p, l), lo) in some.iter().zip(lower).zip(los) {
                if l.is_some() {
                    tested += self.scan(p, &large[lo..]);
                }
            }
        }
        tested
    }

    /// Every overlapping pair of two runs, by whichever walk is cheaper. A step of the merged
    /// walk counts as two of a search: which run it moves on, and whether a slot's scan
    /// stops, are coin tosses the processor often mispredicts (one in four to eight at
    /// rain-10000, in cachegrind's model), where a binary search's steps are selections.
    /// Counted as one, the merged walk was chosen for strips where searching cost less
    /// (rain-10000 46,000 instructions a frame more).
    fn pair_runs(&mut self, (xs, x_width): (&[Swept], f64), (ys, y_width): (&[Swept], f64)) -> u64 {
        let log = |n: usize| u64::from(usize::BITS - n.leading_zeros()) + 2;
        let walk = 2 * (xs.len() + ys.len()) as u64;
        if xs.len() as u64 * log(ys.len()) < walk {
            self.searched(xs, ys, y_width)
        } else if ys.len() as u64 * log(xs.len()) < walk {
            self.searched(ys, xs, x_width)
        } else {
            self.merged(xs, ys)
        }
    }
}

/// How many searches [`Sink::searched`] makes in lockstep.
const LOCKSTEP: usize = 4;

/// The key before which a slot of a run whose slots are none wider than `width` ends
/// before `p` starts along x (a relative margin far above rounding error); `None` when
/// `p`'s `min.x` is NaN: it overlaps nothing.
#[inline]
fn lower_key(p: &Swept, width: f64) -> Option<u64> {
    let min_x = p.min_x();
    if min_x.is_nan() {
        return None;
    }
    let mut lower = min_x - width * (1.0 + 1e-12);
    lower -= lower.abs() * 1e-12 + f64::MIN_POSITIVE;
    Some(order_key(lower))
}

/// [`Sink::within`]'s stretch from slot `k` of `run`: each slot tested against the next
/// (written at `len` in `out`, kept past it when the pair is), up to the end of the run or
/// to the first slot whose walk goes past the next one. Returns that slot (or the last
/// one), `len`, and the tests. A free function over a slice, so that the stretch keeps its
/// state in registers (through the sink, the pairs' length and vector were stored and
/// loaded again at every slot).
#[inline(always)]
fn next_pairs(
    out: &mut [(u32, u32)],
    (mut len, rule): (usize, Rule),
    run: &[Swept],
    mut k: usize,
) -> (usize, usize, u64) {
    let mut tested = 0;
    while k + 1 < run.len() {
        let (p, next) = (&run[k], &run[k + 1]);
        let (keep, t) = rule.verdict(p, next);
        out[len] = (p.handle, next.handle);
        len += usize::from(keep);
        tested += t;
        // The run is sorted by `min`: a slot after one that starts past `p`'s end does too.
        if run.get(k + 2).is_some_and(|s| s.min <= p.max) {
            return (k, len, tested);
        }
        k += 1;
    }
    (k, len, tested)
}

/// `out` made at least `n` long (see [`Sink`]); its growth out of line, away from the
/// sweeps' loops (in line, the compiler kept the loops' values on the stack around it).
#[inline(always)]
fn room(out: &mut Vec<(u32, u32)>, n: usize) {
    #[cold]
    #[inline(never)]
    fn grow(out: &mut Vec<(u32, u32)>, n: usize) {
        out.resize(n.max(out.len() * 2), (0, 0));
    }
    if out.len() < n {
        grow(out, n);
    }
}

impl Drop for Sink<'_> {
    /// `out` cut back to the pairs kept.
    fn drop(&mut self) {
        self.out.truncate(self.len);
    }
}

/// Every overlapping pair within one list with a dynamic body. Returns the tests.
pub(super) fn strip_self(list: &StripList, out: &mut Vec<(u32, u32)>) -> u64 {
    let mut tested = 0;
    let mut sink = Sink::new(out, list.inv_h);
    for r in 0..list.run_count() {
        let (strip, run) = list.run(r);
        tested += sink.at(strip).within(run);
    }
    tested
}

/// Every overlapping pair with one body from each list (and a dynamic one); both lists
/// have the same strip height: each strip's run of one against the other's run of the same
/// strip. Returns the tests.
pub(super) fn strip_cross(x: &StripList, y: &StripList, out: &mut Vec<(u32, u32)>) -> u64 {
    debug_assert_eq!(x.inv_h.to_bits(), y.inv_h.to_bits(), "one strip height");
    let mut tested = 0;
    let mut k = 0;
    let mut sink = Sink::new(out, x.inv_h);
    for r in 0..x.run_count() {
        let (strip, run) = x.run(r);
        while k < y.run_count() && y.run_strip(k) < strip {
            k += 1;
        }
        if k == y.run_count() {
            break;
        }
        if y.run_strip(k) == strip {
            tested += sink
                .at(strip)
                .pair_runs((run, x.width), (y.run(k).1, y.width));
        }
    }
    tested
}

impl BroadPhase {
    /// Before a `Strips` call: the strip height for this call's bodies (kept while it fits,
    /// see [`restrip`]), and the static lists, sorted again when the static bodies or the
    /// height changed.
    pub(super) fn prepare_strips(&mut self, bodies: &[BodyEntry], given: Option<Extent>) {
        if !self.statics.built_strips {
            self.static_extent = extent(self.statics.entries.iter().map(|(b, _)| b));
        }
        // Every body given is a mover when there are as many movers (the usual call): the
        // caller's extent of them when it measured it, else read in place, in sequence.
        let all = self.movers.len() == bodies.len();
        let (height, max_abs) = match given {
            Some(given) if all => {
                let given = given.get();
                debug_assert_eq!(
                    (given.0.to_bits(), given.1.to_bits()),
                    {
                        let e = extent(bodies.iter().map(|b| &b.bounds));
                        (e.0.to_bits(), e.1.to_bits())
                    },
                    "the caller's extent is the bodies'"
                );
                given
            }
            _ if all => extent(bodies.iter().map(|b| &b.bounds)),
            _ => extent(self.movers.iter().map(|&h| &bodies[h as usize].bounds)),
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
                .all(|s| s.inv_h.to_bits() == inv_h.to_bits())
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
