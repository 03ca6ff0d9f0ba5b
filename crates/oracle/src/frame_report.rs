//! What one frame's check found: the counts, the worst errors, the rules that explained
//! each legitimate difference, and a sentence per unexplained one.

use std::collections::BTreeMap;

/// What one frame's check found.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameReport {
    /// The frame checked.
    pub frame: u64,
    /// Contact records of the frame (all phases) recomputed by parry.
    pub contacts_compared: u64,
    /// Differences no rule explains: each has a line in `details`.
    pub mismatches: u64,
    /// Largest `|depth_ricochet - depth_rapier|` over the compared contacts, world units.
    pub worst_depth_error: f64,
    /// Largest angle between the two normals, radians, over the compared contacts whose
    /// normals were not explained by [`crate::rules::TIED_NORMAL`].
    pub worst_normal_error: f64,
    /// How many differences each named rule explained (see [`crate::rules`]).
    pub explained: BTreeMap<&'static str, u64>,
    /// Per rule, the deepest parry depth among the differences it explained, at the poses
    /// Ricochet tested each pair (shows, for example, that `per-axis-boxes` pairs are flush).
    pub explained_depth: BTreeMap<&'static str, f64>,
    /// `all`-pass contacts whose pair rapier's narrow phase also finds penetrating at the
    /// detect poses.
    pub pairs_confirmed: u64,
    /// `swept` contacts that are parry's first touch along the frame's motion.
    pub swept_confirmed: u64,
    /// Compared contacts per phase (`x`, `y`, `all`, `swept`).
    pub by_phase: BTreeMap<&'static str, u64>,
    /// Compared contacts per shape pairing (`circle-obb`, `aabb-compound`, ...).
    pub by_pairing: BTreeMap<String, u64>,
    /// One sentence per unexplained difference.
    pub details: Vec<String>,
}

impl FrameReport {
    pub(crate) fn explain(&mut self, rule: &'static str, depth: f64) {
        *self.explained.entry(rule).or_default() += 1;
        let deepest = self
            .explained_depth
            .entry(rule)
            .or_insert(f64::NEG_INFINITY);
        *deepest = deepest.max(depth);
    }

    pub(crate) fn mismatch(&mut self, detail: String) {
        self.mismatches += 1;
        self.details.push(detail);
    }
}
