//! Counting the moving bodies per layer (here, or by a caller from its own columns), and
//! grouping them by layer from the counts.

use crate::def::BodyKind;

use super::{BodyEntry, BroadPhase, BroadPhaseStats, Interactions, LAYERS};

impl BroadPhase {
    /// Starts the count of this call's moving bodies, for a caller that counts them itself:
    /// from columns of its own ([`Tally::add_run`], then [`Tally::flush`]), faster than
    /// from the entries, or from the entries ([`Tally::count`]). It then calls
    /// [`BroadPhase::pairs_counted_handles`] with the bodies it counted, which are not read
    /// again to be counted.
    pub(crate) fn tally(&mut self) -> Tally<'_> {
        Tally::new(&mut self.layer_start, &mut self.dynamic, &mut self.runs)
    }

    /// [`BroadPhase::pairs_split_handles`] of moving bodies counted by the caller through
    /// [`BroadPhase::tally`] (checked against a count of the entries in a debug build).
    pub(crate) fn pairs_counted_handles(
        &mut self,
        statics: &[BodyEntry],
        static_generation: u64,
        movers: &[BodyEntry],
        interactions: &Interactions,
        out: &mut Vec<(u32, u32)>,
    ) -> BroadPhaseStats {
        self.check_counted(movers);
        self.load_statics(statics, static_generation);
        self.begin_counted(movers, interactions);
        self.finish_counted(movers, interactions, out)
    }

    /// In a debug build, checks that the caller counted `movers` (all of them made) as a
    /// count of them would: call it before [`BroadPhase::begin_counted`].
    pub(crate) fn check_counted(&self, movers: &[BodyEntry]) {
        #[cfg(debug_assertions)]
        {
            let (mut counts, mut dynamic, mut runs) = (
                vec![0; self.layer_start.len()],
                vec![0; self.dynamic.len()],
                Vec::new(),
            );
            Tally::new(&mut counts, &mut dynamic, &mut runs).count(movers);
            assert_eq!(
                (counts, dynamic, runs),
                (
                    self.layer_start.clone(),
                    self.dynamic.clone(),
                    self.runs.clone()
                ),
                "the caller's count is the entries'"
            );
            assert!(
                movers.windows(2).all(|w| w[0].key < w[1].key),
                "keys increase"
            );
        }
        #[cfg(not(debug_assertions))]
        let _ = movers;
    }

    /// Starts a call of moving bodies the caller counted ([`BroadPhase::tally`]), once the
    /// statics are loaded: groups them and chooses the algorithm. `movers` need hold only
    /// the entries `Auto` reads (those of a layer that meets itself), and
    /// [`BroadPhase::big_pass`] tells which others must be made before
    /// [`BroadPhase::finish_counted`].
    pub(crate) fn begin_counted(&mut self, movers: &[BodyEntry], interactions: &Interactions) {
        self.group_movers(movers, |_| true);
        self.choose(movers, interactions);
    }

    /// Finds the pairs of a call [`BroadPhase::begin_counted`] started, as handles
    /// ([`BroadPhase::pairs_split_handles`]).
    pub(crate) fn finish_counted(
        &mut self,
        movers: &[BodyEntry],
        interactions: &Interactions,
        out: &mut Vec<(u32, u32)>,
    ) -> BroadPhaseStats {
        self.execute(movers, (false, false), interactions, out)
    }

    /// Groups the moving bodies by layer (a counting sort, so key order is kept within),
    /// once `layer_start[l + 1]` holds layer `l`'s count.
    pub(super) fn group_movers(
        &mut self,
        bodies: &[BodyEntry],
        moving: impl Fn(&BodyEntry) -> bool,
    ) {
        let counts = &mut self.layer_start;
        self.mover_layers.clear();
        for l in 0..LAYERS {
            if counts[l + 1] > 0 {
                self.mover_layers.push(l as u8);
            }
            counts[l + 1] += counts[l];
        }
        self.movers.clear();
        if self.runs.len() <= MAX_RUNS {
            // Bodies of a layer usually come in a few runs of consecutive indices: each
            // layer's, in order, appended (no cleared buffer to scatter into).
            for &l in &self.mover_layers {
                for &(start, len, _) in self.runs.iter().filter(|r| r.2 == l) {
                    self.movers.extend(start..start + len);
                }
            }
            debug_assert_eq!(self.movers.len(), counts[LAYERS] as usize);
            return;
        }
        self.movers.resize(counts[LAYERS] as usize, 0);
        let mut next: [u32; LAYERS] = [0; LAYERS];
        next.copy_from_slice(&counts[..LAYERS]);
        // Too many runs: scatter body by body, the current layer's cursor in a register.
        let (mut layer, mut at) = (0, next[0]);
        for (i, b) in bodies.iter().enumerate() {
            if !moving(b) {
                continue;
            }
            let l = usize::from(b.layer);
            if l != layer {
                next[layer] = at;
                layer = l;
                at = next[l];
            }
            self.movers[at as usize] = i as u32;
            at += 1;
        }
    }
}

/// Counts moving bodies per layer (into `counts[layer + 1]`) and dynamic ones (into
/// `dynamic[layer]`), a run of one layer in registers, and notes the runs of consecutive
/// indices (up to [`MAX_RUNS`], and one more to say there were more).
pub(crate) struct Tally<'a> {
    counts: &'a mut [u32],
    dynamic: &'a mut [u32],
    runs: &'a mut Vec<(u32, u32, u8)>,
    /// The current run: its layer, first index, bodies and dynamic bodies.
    layer: usize,
    start: u32,
    n: u32,
    d: u32,
}

/// How many runs of consecutive indices [`Tally`] notes before giving up on them.
pub(super) const MAX_RUNS: usize = 64;

impl<'a> Tally<'a> {
    /// Starts a tally into `counts`, `dynamic` and `runs`, which it clears.
    pub(super) fn new(
        counts: &'a mut [u32],
        dynamic: &'a mut [u32],
        runs: &'a mut Vec<(u32, u32, u8)>,
    ) -> Tally<'a> {
        counts.fill(0);
        dynamic.fill(0);
        runs.clear();
        Tally {
            counts,
            dynamic,
            runs,
            layer: 0,
            start: 0,
            n: 0,
            d: 0,
        }
    }

    /// Counts body `b`, at index `i`.
    #[inline]
    pub(super) fn add(&mut self, b: &BodyEntry, i: u32) {
        let l = usize::from(b.layer);
        if l != self.layer || i != self.start + self.n {
            self.flush();
            (self.layer, self.start) = (l, i);
        }
        self.n += 1;
        self.d += u32::from(b.kind == BodyKind::Dynamic);
    }

    /// Counts `len` bodies of `layer` at indices `start..start + len`, `dynamic` of them
    /// dynamic: what [`Tally::add`] of each would count.
    pub(crate) fn add_run(&mut self, layer: u8, start: u32, len: u32, dynamic: u32) {
        let l = usize::from(layer);
        if l != self.layer || start != self.start + self.n {
            self.flush();
            (self.layer, self.start) = (l, start);
        }
        self.n += len;
        self.d += dynamic;
    }

    /// Counts every body of `bodies` (all moving), at its place, and flushes.
    pub(crate) fn count(mut self, bodies: &[BodyEntry]) {
        for (i, b) in bodies.iter().enumerate() {
            self.add(b, i as u32);
        }
        self.flush();
    }

    /// Adds the current run to the counts; call once after the last [`Tally::add`].
    pub(crate) fn flush(&mut self) {
        if self.n == 0 {
            return;
        }
        self.counts[self.layer + 1] += self.n;
        self.dynamic[self.layer] += self.d;
        if self.runs.len() <= MAX_RUNS {
            self.runs.push((self.start, self.n, self.layer as u8));
        }
        (self.n, self.d) = (0, 0);
    }
}
