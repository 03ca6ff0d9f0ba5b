//! One call's steps, once its bodies are counted and grouped: choose the algorithm (what
//! `Auto` picks) and the layers sort and sweep filters, find the pairs, and resolve their
//! handles to sorted dense indices. [`BroadPhase::pairs`] and `split` take them in turn. A
//! caller that leaves a layer out of the entries (`left_out.rs`) makes them between the
//! choice and the pairs (`tally.rs`: `begin_counted`, `finish_counted`).

use super::{
    BodyEntry, BroadPhase, BroadPhaseKind, BroadPhaseStats, Extent, Interactions, STATIC_BIT,
};

impl BroadPhase {
    /// Starts a call whose bodies are grouped: chooses the algorithm (what `Auto` picks,
    /// into `chosen`) and the layers sort and sweep filters (`cell_filter.rs`).
    pub(super) fn choose(&mut self, bodies: &[BodyEntry], interactions: &Interactions) {
        assert!(
            self.statics.keys.len() + self.movers.len() < STATIC_BIT as usize,
            "fewer than 2^31 bodies"
        );
        self.frame += 1;
        let kind = match self.kind {
            BroadPhaseKind::Auto => self.auto_kind(bodies, interactions),
            k => k,
        };
        self.chosen = kind;
        let layers = std::mem::take(&mut self.mover_layers);
        self.plan_filters(kind, &layers, interactions);
        self.mover_layers = layers;
    }

    /// Finds the pairs of a call [`BroadPhase::choose`] started and, with `dense`, resolves
    /// them (`all_given`: whether `bodies` holds the static bodies too).
    ///
    /// The moving bodies' extent, if the caller gave it ([`BroadPhase::give_extent`]), is
    /// taken here, whichever algorithm runs.
    pub(super) fn execute(
        &mut self,
        bodies: &[BodyEntry],
        (all_given, dense): (bool, bool),
        interactions: &Interactions,
        out: &mut Vec<(u32, u32)>,
    ) -> BroadPhaseStats {
        out.clear();
        // A caller's extent is for this call only.
        let given = self.given_extent.take();
        let n_movers = self.movers.len();
        let n_statics = self.statics.count();
        let kind = self.chosen;
        let mut stats = BroadPhaseStats {
            kind,
            movers: n_movers as u64,
            statics: n_statics as u64,
            ..BroadPhaseStats::default()
        };
        if kind == BroadPhaseKind::BruteForce {
            self.brute_force(bodies, interactions, out, &mut stats);
        } else {
            self.by_layers(kind, (bodies, given), interactions, out, &mut stats);
        }
        if dense {
            self.resolve(bodies, all_given, out);
        }
        stats.pairs = out.len() as u64;
        stats.static_rebuilds = self.static_rebuilds;
        stats
    }

    /// Whether the next call would use its movers' [`Extent`] ([`BroadPhase::give_extent`]):
    /// when the last one ran `Strips`, which choose their height from it. A call that turns
    /// to strips without it reads the entries for it itself.
    pub(crate) fn wants_extent(&self) -> bool {
        self.chosen == BroadPhaseKind::Strips
    }

    /// Gives the next call the [`Extent`] of its moving bodies' bounds, measured by the
    /// caller as it made every one of their entries: `Strips` then chooses its strip height
    /// without another pass over them (a tenth of the strips' time at rain-10000). Checked
    /// against that pass in a debug build.
    pub(crate) fn give_extent(&mut self, extent: Extent) {
        self.given_extent = Some(extent);
    }

    /// Turns handles into dense indices, orders each pair and sorts them.
    fn resolve(&self, bodies: &[BodyEntry], all_given: bool, out: &mut [(u32, u32)]) {
        let st = &self.statics;
        let dense = |h: u32| -> u32 {
            match (h & STATIC_BIT != 0, all_given) {
                (false, true) => h,
                (true, true) => st.dense[(h & !STATIC_BIT) as usize],
                // Ranks in the other slice; the first two checks spare a binary search (and
                // its cache misses) when every static body comes before every moving one.
                (false, false) => {
                    let key = bodies[h as usize].key;
                    let rank = match st.keys.last() {
                        Some(&last) if last > key => st.keys.partition_point(|&k| k < key),
                        _ => st.keys.len(),
                    };
                    h + rank as u32
                }
                (true, false) => {
                    let s = h & !STATIC_BIT;
                    let key = st.keys[s as usize];
                    let rank = match bodies.first() {
                        Some(first) if first.key < key => bodies.partition_point(|b| b.key < key),
                        _ => 0,
                    };
                    s + rank as u32
                }
            }
        };
        for p in out.iter_mut() {
            let (i, j) = (dense(p.0), dense(p.1));
            *p = (i.min(j), i.max(j));
        }
        // One integer comparison per step.
        out.sort_unstable_by_key(|&(i, j)| (u64::from(i) << 32) | u64::from(j));
        debug_assert!(out.windows(2).all(|w| w[0] < w[1]), "each pair once");
    }
}
