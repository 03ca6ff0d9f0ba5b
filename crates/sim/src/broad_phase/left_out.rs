//! The big layer of sort and sweep's filter (`cell_filter.rs`) left out of the entries: a
//! caller that counts its moving bodies from its own columns ([`BroadPhase::tally`]) can
//! make the entries of every other layer first, and then, in one pass over the big layer,
//! find each body's bounds, test its corner cell on the bitmap the small layers marked,
//! and write an entry only for a body on a marked cell (or one it needs itself). The filter
//! then reads that list instead of every big body's 48-byte entry, and the 10,000 entries
//! of an asteroid field are neither written nor read again.
//!
//! Nothing else changes: the bitmap is the one the filter would mark (the same reach, from
//! the same small bodies), the marked bodies are listed in the order it would read them,
//! and when a body outgrew the reach (the filter would mark again) or the call turns out
//! not to filter the layer, the caller makes the rest of its entries and the call goes on
//! as if they had all been made.
//!
//! The order of a call that leaves a layer out:
//! 1. [`BroadPhase::tally`], flushed; [`BroadPhase::load_statics`];
//! 2. [`BroadPhase::layer_to_leave_out`]: the layer and its places, if any;
//! 3. the entries of every other place; [`BroadPhase::begin_counted`];
//! 4. [`BroadPhase::big_pass`]: `Some` when the call filters that layer. The
//!    [`Marking::keep`] of its [`BigPass::marking`] is shown every big body's place and
//!    bounds, in order, and says which to write (no body, when nothing is marked);
//!    [`BigPass::measured`] takes back the widest body it saw, and [`BigPass::finish`] says
//!    whether that was enough;
//! 5. else (or not enough), every remaining entry; then [`BroadPhase::finish_counted`].

use std::ops::Range;

use ricochet_geom::{Bounds, Vec2};

use super::cell_filter::{CELLS, Corner, WORDS, kept_reach, mark, worth_filtering};
use super::tally::MAX_RUNS;
use super::{BodyEntry, BroadPhase, BroadPhaseKind, Interactions, LAYERS, of_layer};

impl BroadPhase {
    /// After a count ([`BroadPhase::tally`], flushed) and [`BroadPhase::load_statics`],
    /// before any entry is made: the moving layer whose entries may be left out, with its
    /// places among the movers. That is a layer sort and sweep's filter would take (from
    /// the counts alone), of one run of places, meeting no static layer (whose pairs read
    /// its entries).
    pub(crate) fn layer_to_leave_out(
        &self,
        interactions: &Interactions,
    ) -> Option<(u8, Range<usize>)> {
        if !matches!(
            self.kind,
            BroadPhaseKind::Auto | BroadPhaseKind::SortAndSweep
        ) || self.runs.len() > MAX_RUNS
        {
            return None;
        }
        // Before grouping, `layer_start[l + 1]` holds layer `l`'s count.
        let count = |l: u8| self.layer_start[usize::from(l) + 1] as usize;
        // The moving layers, each once, in order (on the stack: a few runs).
        let (mut layers, mut n) = ([0u8; MAX_RUNS], 0);
        for &(_, _, l) in &self.runs {
            if !layers[..n].contains(&l) {
                layers[n] = l;
                n += 1;
            }
        }
        let layers = &mut layers[..n];
        layers.sort_unstable();
        let &big = layers
            .iter()
            .find(|&&l| worth_filtering(l, layers, count, interactions))?;
        let mut runs = self.runs.iter().filter(|r| r.2 == big);
        let &(start, len, _) = runs.next()?;
        let meets_static = self
            .statics
            .layers
            .iter()
            .any(|&s| interactions.interacts(big, s));
        if runs.next().is_some() || meets_static {
            return None;
        }
        Some((big, start as usize..(start + len) as usize))
    }

    /// After [`BroadPhase::begin_counted`], with every entry made but `big`'s
    /// ([`BroadPhase::layer_to_leave_out`]): the pass that makes `big`'s, when this call
    /// filters it; `None` when it does not (every entry is then needed).
    pub(crate) fn big_pass(
        &mut self,
        big: u8,
        bodies: &[BodyEntry],
        interactions: &Interactions,
    ) -> Option<BigPass<'_>> {
        if self.chosen != BroadPhaseKind::SortAndSweep || !self.filter.filtered(big) {
            return None;
        }
        let f = &mut self.filter;
        if f.reach.is_empty() {
            f.reach.resize(LAYERS, Vec2::ZERO);
        }
        let reach = f.reach[usize::from(big)];
        // The small layers it meets, as the filter lists them.
        let mut partners = std::mem::take(&mut f.partners);
        partners.clear();
        partners.extend(
            (self.mover_layers.iter().copied())
                .filter(|&m| m != big && interactions.interacts(big, m)),
        );
        let smalls = |m: u8| of_layer(&self.movers, &self.layer_start, m);
        let cells = mark(&mut f.bits, &partners, smalls, bodies, reach);
        f.partners = partners;
        f.marked.clear();
        // Left as it was when nothing is marked (and then not read).
        f.bits.resize(CELLS * WORDS, 0);
        let bits: &[u64; CELLS * WORDS] = f.bits[..].try_into().expect("sized just now");
        Some(BigPass {
            cells: cells.map(|(ax, ay)| Corner::new(ax, ay)),
            bits,
            marked: &mut f.marked,
            left_out: &mut f.left_out,
            reach,
            seen: Vec2::ZERO,
            layer: big,
        })
    }
}

/// [`BroadPhase::big_pass`]: shown each big body's place and bounds in order, it lists the
/// bodies on a marked cell and measures the layer's widest and tallest body.
pub(crate) struct BigPass<'a> {
    /// The map onto the bitmap, or `None` when no small body can pair (nothing is marked).
    cells: Option<Corner>,
    bits: &'a [u64; CELLS * WORDS],
    marked: &'a mut Vec<u32>,
    left_out: &'a mut Option<Vec2>,
    reach: Vec2,
    seen: Vec2,
    /// The big layer.
    layer: u8,
}

impl BigPass<'_> {
    /// The pass's test of each body, its state copied out of the pass to live in registers
    /// through the loop (behind `&mut`, it was stored and read again for every body), or
    /// `None` when no small body can pair (nothing is marked: no body is kept, none
    /// measured). [`BigPass::measured`] takes its measure back.
    #[inline(always)]
    pub(crate) fn marking(&mut self) -> Option<Marking<'_>> {
        Some(Marking {
            corner: self.cells?,
            bits: self.bits,
            marked: &mut *self.marked,
            seen: self.seen,
            layer: self.layer,
        })
    }

    /// The widest and tallest body a [`Marking`] measured.
    pub(crate) fn measured(&mut self, seen: Vec2) {
        self.seen = seen;
    }

    /// Ends the pass: whether the bodies it kept are all the call reads. If a body outgrew
    /// the reach the bitmap was marked with, they are not: the caller makes every entry, and
    /// the filter marks again as it does when it reads them.
    pub(crate) fn finish(self) -> bool {
        let (seen, reach) = (self.seen, self.reach);
        let enough = self.cells.is_none() || (seen.x <= reach.x && seen.y <= reach.y);
        *self.left_out = if enough {
            // The reach the filter keeps: unchanged when nothing was measured.
            Some(if self.cells.is_some() {
                kept_reach(seen)
            } else {
                self.reach
            })
        } else {
            None
        };
        enough
    }
}

/// [`BigPass::marking`]: it lists the big bodies on a marked cell and measures the layer's
/// widest and tallest body.
pub(crate) struct Marking<'a> {
    corner: Corner,
    bits: &'a [u64; CELLS * WORDS],
    marked: &'a mut Vec<u32>,
    /// The widest and tallest body seen so far.
    pub(crate) seen: Vec2,
    /// The big layer: every body shown is of it.
    pub(crate) layer: u8,
}

impl Marking<'_> {
    /// Whether the big body at place `k`, of bounds `b`, is on a marked cell: its entry is
    /// then read again and must be made.
    #[inline(always)]
    pub(crate) fn keep(&mut self, k: usize, b: &Bounds) -> bool {
        // Selections (`maxpd`), NaN ignored: no branch in the loop.
        let (size, seen) = (b.max - b.min, self.seen);
        self.seen = Vec2::new(
            if size.x > seen.x { size.x } else { seen.x },
            if size.y > seen.y { size.y } else { seen.y },
        );
        let c = self.corner.bit(b.min);
        let on = self.bits[c / 64] & (1 << (c % 64)) != 0;
        if on {
            self.marked.push(k as u32);
        }
        on
    }
}
