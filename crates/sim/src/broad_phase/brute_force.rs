//! `BruteForce`: every pair, `O(n²)`. The reference, and the fastest below a few dozen
//! bodies.

use super::{BodyEntry, BroadPhase, BroadPhaseStats, Interactions, Member, STATIC_BIT, member};

impl BroadPhase {
    /// Every pair, filters first.
    pub(super) fn brute_force(
        &mut self,
        bodies: &[BodyEntry],
        interactions: &Interactions,
        out: &mut Vec<(u32, u32)>,
        stats: &mut BroadPhaseStats,
    ) {
        let all = &mut self.scratch.all;
        all.clear();
        all.extend(self.movers.iter().map(|&h| {
            let b = &bodies[h as usize];
            (member(b, h), b.layer)
        }));
        let st = &self.statics;
        all.extend(st.entries.iter().enumerate().map(|(s, &(bounds, layer))| {
            let m = Member {
                bounds,
                handle: s as u32 | STATIC_BIT,
                dynamic: false,
            };
            (m, layer)
        }));
        // The same count `by_layers` keeps: layer combinations present that never interact.
        for (k, &a) in self.mover_layers.iter().enumerate() {
            let with_statics = if self.dynamic[usize::from(a)] > 0 {
                &self.statics.layers[..]
            } else {
                &[]
            };
            for &b in self.mover_layers[k..].iter().chain(with_statics) {
                if !interactions.interacts(a, b) {
                    stats.layer_pairs_skipped += 1;
                }
            }
        }
        for (k, (a, la)) in all.iter().enumerate() {
            for (b, lb) in &all[k + 1..] {
                if (a.dynamic || b.dynamic) && interactions.interacts(*la, *lb) {
                    stats.tested += 1;
                    if a.bounds.overlaps(&b.bounds) {
                        out.push((a.handle, b.handle));
                    }
                }
            }
        }
    }
}
