//! The wrap seam: in a world with `bounds` and `wrap = true`, bodies collide through the
//! edges. A body near an edge also collides, through its **images** (the body translated
//! by whole world sizes, [`WorldBounds::image_offsets`]), with bodies near the opposite
//! edge, or the opposite corner.
//!
//! **Broad phase.** Only moving bodies get images, and only those near an edge. "Near" is
//! within the world's *reach* of the edge: how far any body's bounds stick out of the world
//! on that axis (static bodies measured when they change, moving ones every frame), plus a
//! rounding margin. That is enough: if `b` translated by `+width` overlaps `a`, then
//! `a.max.x >= b.min.x + width >= max.x - reach` and
//! `b.min.x <= a.max.x - width <= min.x + reach`, so *both* bodies are near the edges the
//! offset crosses (on both axes for a corner), and the moving one of the two has the image.
//! The images go to a broad phase of their own, with the near moving bodies and the static
//! bodies (whose structures it builds only when they change), never to the main one, whose
//! sorted lists stay as they were; the pairs it finds with an image are mapped back to the
//! real bodies and merged into the main pairs (sorted `(i, j)`, `i < j`, each once). When
//! nothing sticks out of the world the reach is zero and only bodies touching an edge get an
//! image. A frame without any costs four comparisons per moving body, made as its broad-phase
//! entry is built (against the edges moved in by a guessed reach: a quarter more than the
//! last frame's; a frame whose reach outgrew the guess looks at the moving bodies again).
//!
//! **Narrow phase.** A pair with an image is tested directly and at every offset either
//! body's images suggest, with `b` translated next to `a`; the deepest contact wins, the
//! first in [`WorldBounds::image_offsets`] order (the direct one first) on a tie. The
//! contact, and its logged `pose_b`, are in `a`'s coordinates: `pose_b` is `b`'s image.
//! Swept pairs take the earliest touch the same way.
//!
//! **Far out.** Offsets are whole world sizes `-1, 0, 1` on each axis. They are enough when
//! every body's bounds stick out of the world by less than half its size: an image two
//! sizes away would need `reach_a + reach_b >= size`. A moving body can end its motion any
//! number of sizes out (200 units a frame in a 100-unit world, or placed there), so before
//! the pass [`bring_in`] wraps every active body whose bounds stick out by half the size or
//! more, on that axis, into the world (the `bounds` stage's exact wrap, [`wrap_coordinate`]),
//! and moves its frame's start by the same whole sizes (its motion over the frame, which
//! swept tests follow, is unchanged). Bodies less far out are left to the images, so a
//! body that just crossed an edge is tested where it was before. The contacts of any scene
//! at any speed are then those of the same scene with every body wrapped into the world
//! first. A swept pair whose path over the frame reaches two or more world sizes (a bullet
//! faster than the world a frame) is cast at the images its path meets instead, in time
//! order until its first hit, within a per-pair and a per-frame bound (`far_path.rs`).
//! Not covered: a static body placed half
//! the world's size or more outside (statics are never moved; scenario files refuse a
//! static body outside a wrapping world, a scene built in code is not checked).

use ricochet_geom::{Bounds, Vec2};

use crate::broad_phase::{BodyEntry, BroadPhase, BroadPhaseKind, Interactions, STATIC_BIT};
use crate::def::WorldBounds;
use crate::world::World;

/// Keys of image entries: above every real key (an entity's index is below `2^31`).
const IMAGE_KEY: u64 = 1 << 63;

/// The rounding margin of "near an edge" and of an image's bounds, relative to the world's
/// size: `2^-40`, far above the rounding of `x + width`, far below any shape.
const SLACK: f64 = 1.0 / (1u64 << 40) as f64;

/// The wrap seam's state (see the module docs).
#[derive(Debug, Clone)]
pub(crate) struct Seam {
    /// The images' own broad phase.
    broad_phase: BroadPhase,
    /// [`WorldBounds::image_offsets`] of the world.
    offsets: [Vec2; 9],
    /// This frame's broad-phase entries: the near moving bodies, then their images.
    entries: Vec<BodyEntry>,
    /// World index of each entry: a near moving body's, or the body an image is of.
    bodies: Vec<u32>,
    /// Entries from here on are images.
    first_image: usize,
    /// Per world index, the offsets of the body's images (bit `k`: `offsets[k]`): zero but
    /// at the indices in `bodies`.
    masks: Vec<u16>,
    /// How far the static bodies' bounds reach out of the world on each axis (`>= 0`).
    static_reach: Vec2,
    /// The reach guessed for this frame (from the last one's), and the world's edges moved
    /// in by it (plus the slack): a body inside them neither sticks out nor can be near.
    guess: Vec2,
    guess_lo: Vec2,
    guess_hi: Vec2,
    /// Moving bodies (places in the entries) outside the guessed edges.
    candidates: Vec<u32>,
    found: Vec<(u32, u32)>,
    /// The pairs met through the seam, sorted apart ([`merge_tail`]).
    tail: Vec<(u32, u32)>,
}

/// Sorts `v`, whose items before `sorted` are in order already: the rest (the few pairs met
/// through the seam, after thousands) are sorted apart into `buffer` and merged in from the
/// back, an item of the front moved once at most. The order of sorting the whole of `v`
/// (items that compare equal are equal), without sorting it again.
fn merge_tail<T: Copy + Ord>(v: &mut [T], sorted: usize, buffer: &mut Vec<T>) {
    debug_assert!(v[..sorted].is_sorted(), "the front is in order");
    buffer.clear();
    buffer.extend_from_slice(&v[sorted..]);
    buffer.sort_unstable();
    // `v[..front]` is what is left of the front; every place from `free` on is written.
    let (mut front, mut free) = (sorted, v.len());
    for &x in buffer.iter().rev() {
        while front > 0 && v[front - 1] > x {
            front -= 1;
            free -= 1;
            v[free] = v[front];
        }
        free -= 1;
        v[free] = x;
    }
}

/// `p` wrapped into `[min, max)` on one axis (`size = max - min`). `rem_euclid` is exact
/// (an IEEE remainder), so wrapping is deterministic and lands in one step from any
/// distance.
pub(crate) fn wrap_coordinate(p: f64, min: f64, max: f64, size: f64) -> f64 {
    let q = min + (p - min).rem_euclid(size);
    // -tiny.rem_euclid(size) can round up to size itself.
    if q >= max { min } else { q }
}

/// Wraps into the world, before `detect`'s pass, each active body whose bounds stick out
/// of it by half its size or more on an axis (see the module docs: the images then reach
/// every contact). Such a body is wrapped on that axis only, and its frame's start moved by
/// the same whole world sizes.
pub(crate) fn bring_in(world: &WorldBounds, w: &mut World) {
    let size = world.size();
    let half = size * 0.5;
    // A body centred in the world sticks out by at most half its width, less than half the
    // world's (a body wider than the world is refused at load): one tight pass finds the
    // others.
    let mut candidates = Vec::new();
    w.active_not_inside(world.min, world.max, &mut candidates);
    for &i in &candidates {
        let i = i as usize;
        let p = w.position[i];
        let outside = |axis: usize| p[axis] < world.min[axis] || p[axis] >= world.max[axis];
        if !outside(0) && !outside(1) {
            continue;
        }
        let r = reach(world, &w.bounds(i));
        let mut q = p;
        for axis in 0..2 {
            if outside(axis) && r[axis] >= half[axis] {
                q[axis] = wrap_coordinate(p[axis], world.min[axis], world.max[axis], size[axis]);
            }
        }
        if q != p {
            w.wrap_to(i, q);
        }
    }
    // The `bounds` stage asks the same after `detect`: if nothing is touched in between, the
    // bodies still outside are among these.
    w.keep_not_inside(world.min, world.max, &candidates);
}

/// How far `b` sticks out of the world on each axis (`>= 0`).
fn reach(world: &WorldBounds, b: &Bounds) -> Vec2 {
    (world.min - b.min).max(b.max - world.max).max(Vec2::ZERO)
}

/// The offset index `k` of `-offsets[k]` ([`WorldBounds::image_offsets`] lists them so).
fn negated(k: usize) -> usize {
    if k == 0 { 0 } else { 9 - k }
}

/// The offsets of `mask` (bit `k`: [`WorldBounds::image_offsets`]`[k]`, `k` from 1 to 8)
/// negated: bit `k` moved to bit [`negated`]`(k)`, that is `9 - k`, which reverses the eight
/// bits. Without a loop or a branch: every pair the narrow phase tests asks it.
fn negated_mask(mask: u16) -> u16 {
    let reversed = u16::from(((mask >> 1) as u8).reverse_bits()) << 1;
    debug_assert_eq!(
        reversed,
        (1..9)
            .filter(|k| mask & (1 << k) != 0)
            .fold(0, |m, k| m | 1 << negated(k)),
        "bit k to bit 9 - k"
    );
    reversed
}

/// Which offsets (bit `k`: [`WorldBounds::image_offsets`]`[k]`) a body with bounds `b`
/// has images at, given the edges moved in by the reach (`lo`, `hi`).
fn image_mask(b: &Bounds, lo: Vec2, hi: Vec2) -> u16 {
    // Near the upper edge: an image one size below; near the lower: one above.
    let steps = |axis: usize| [b.max[axis] >= hi[axis], true, b.min[axis] <= lo[axis]];
    let (xs, ys) = (steps(0), steps(1));
    let mut mask = 0u16;
    for (gx, &okx) in xs.iter().enumerate() {
        for (gy, &oky) in ys.iter().enumerate() {
            let g = 3 * gx + gy;
            if okx && oky && g != 4 {
                mask |= 1 << if g < 4 { g + 1 } else { g };
            }
        }
    }
    mask
}

impl Seam {
    /// The seam of a world whose broad phase is `kind`.
    pub(crate) fn new(kind: BroadPhaseKind) -> Seam {
        Seam {
            broad_phase: BroadPhase::for_band(kind),
            offsets: [Vec2::ZERO; 9],
            entries: Vec::new(),
            bodies: Vec::new(),
            first_image: 0,
            masks: Vec::new(),
            static_reach: Vec2::ZERO,
            guess: Vec2::ZERO,
            guess_lo: Vec2::ZERO,
            guess_hi: Vec2::ZERO,
            candidates: Vec::new(),
            found: Vec::new(),
            tail: Vec::new(),
        }
    }

    /// Measures how far the static bodies reach out of the world: call it whenever the
    /// static bodies change.
    pub(crate) fn statics_changed(&mut self, world: &WorldBounds, statics: &[BodyEntry]) {
        self.static_reach = statics
            .iter()
            .fold(Vec2::ZERO, |r, s| r.max(reach(world, &s.bounds)));
    }

    /// Starts a frame: [`Seam::visitor`] then sees every moving body's entry.
    pub(crate) fn begin(&mut self, world: &WorldBounds) {
        let slack = world.size() * SLACK;
        let r = self.guess.max(self.static_reach);
        self.guess_lo = world.min + r + slack;
        self.guess_hi = world.max - r - slack;
        self.candidates.clear();
    }

    /// What notes the moving body at place `m` of the entries if its bounds `b` are outside
    /// the guessed edges, and says whether it did (one pass, as the entries are made, in any
    /// order; the edges held in it, not read again for each body). A noted body's entry is
    /// read again.
    pub(crate) fn visitor(&mut self) -> impl FnMut(usize, &Bounds) -> bool + '_ {
        let (lo, hi) = (self.guess_lo, self.guess_hi);
        let candidates = &mut self.candidates;
        move |m, b| {
            let near = !(b.min.x > lo.x && b.max.x < hi.x && b.min.y > lo.y && b.max.y < hi.y);
            if near {
                candidates.push(m as u32);
            }
            near
        }
    }

    /// This frame's reach, measured on the noted bodies (`movers`, the entries), the edges
    /// moved in by it, and whether the noted bodies hold every near one (the reach is within
    /// the guess).
    fn edges(&self, world: &WorldBounds, movers: &[BodyEntry]) -> (Vec2, Vec2, Vec2, bool) {
        let slack = world.size() * SLACK;
        let r = self.candidates.iter().fold(self.static_reach, |r, &m| {
            r.max(reach(world, &movers[m as usize].bounds))
        });
        let (lo, hi) = (world.min + r + slack, world.max - r - slack);
        // Inside the guessed edges is inside these: the candidates hold every near body.
        let within_guess = self.guess_lo.cmpge(lo).all() && self.guess_hi.cmple(hi).all();
        (r, lo, hi, within_guess)
    }

    /// Whether [`Seam::add_pairs`] will read every moving body's entry this frame, not only
    /// the noted ones' (the reach outgrew the guess).
    pub(crate) fn reads_every_mover(&self, world: &WorldBounds, movers: &[BodyEntry]) -> bool {
        !self.edges(world, movers).3
    }

    /// Adds to `pairs` (the main broad phase's: dense indices, sorted) the pairs that meet
    /// through the seam: the images of the moving bodies near an edge (`movers`, whose world
    /// indices are [`World::movers`], each seen by [`Seam::visitor`]) against the near moving
    /// bodies and the static bodies (`statics`, read only when `static_generation`
    /// changes; `static_index` holds the world index of each, as `detect` keeps it).
    ///
    /// Only bodies outside the guessed edges can stick out of the world, so the reach is
    /// measured on them; if it is within the guess, they hold every near body, else (the
    /// reach grew) every moving body is looked at again. The next frame guesses a quarter
    /// more than this one's reach.
    pub(crate) fn add_pairs(
        &mut self,
        world: &WorldBounds,
        w: &World,
        (statics, static_generation, static_index): (&[BodyEntry], u64, &[u32]),
        movers: &[BodyEntry],
        interactions: &Interactions,
        pairs: &mut Vec<(u32, u32)>,
    ) {
        self.offsets = world.image_offsets();
        // Last frame's masks zeroed where they were set, not the whole column (20 KB a frame
        // at 10,000 bodies): the indices may have moved since, but no other is set.
        for &i in &self.bodies {
            if let Some(mask) = self.masks.get_mut(i as usize) {
                *mask = 0;
            }
        }
        self.masks.resize(w.len(), 0);
        self.entries.clear();
        self.bodies.clear();
        let slack = world.size() * SLACK;
        let (r, lo, hi, within_guess) = self.edges(world, movers);
        self.guess = r * 1.25;
        if within_guess {
            // Noted in the order the entries were made, which need not be theirs.
            self.candidates.sort_unstable();
        } else {
            self.candidates.clear();
            self.candidates.extend(0..movers.len() as u32);
        }
        let indices = w.movers();
        for &m in &self.candidates {
            let (m, entry) = (m as usize, &movers[m as usize]);
            let b = &entry.bounds;
            if b.min.x > lo.x && b.max.x < hi.x && b.min.y > lo.y && b.max.y < hi.y {
                continue;
            }
            self.masks[indices[m] as usize] = image_mask(b, lo, hi);
            self.entries.push(*entry);
            self.bodies.push(indices[m]);
        }
        if self.entries.is_empty() {
            return;
        }
        self.first_image = self.entries.len();
        for n in 0..self.first_image {
            let (entry, i) = (self.entries[n], self.bodies[n]);
            let mask = self.masks[i as usize];
            for k in (1..9).filter(|k| mask & (1 << k) != 0) {
                let moved = entry.bounds.translated(self.offsets[k]);
                self.entries.push(BodyEntry {
                    key: IMAGE_KEY | ((n as u64) << 4) | k as u64,
                    bounds: Bounds {
                        min: moved.min - slack,
                        max: moved.max + slack,
                    },
                    ..entry
                });
                self.bodies.push(i);
            }
        }
        let mut found = std::mem::take(&mut self.found);
        self.broad_phase.pairs_split_handles(
            statics,
            static_generation,
            &self.entries,
            interactions,
            &mut found,
        );
        let before = pairs.len();
        let world_index = |h: u32| -> u32 {
            if h & STATIC_BIT != 0 {
                static_index[(h & !STATIC_BIT) as usize]
            } else {
                self.bodies[h as usize]
            }
        };
        let image = |h: u32| h & STATIC_BIT == 0 && h as usize >= self.first_image;
        for &(p, q) in &found {
            // Exactly one image: two images moved alike are a real pair, found already.
            if image(p) == image(q) {
                continue;
            }
            let (i, j) = (world_index(p), world_index(q));
            debug_assert!(i != u32::MAX && j != u32::MAX, "statics are this frame's");
            if i != j && i != u32::MAX && j != u32::MAX {
                pairs.push((i.min(j), i.max(j)));
            }
        }
        self.found = found;
        if pairs.len() > before {
            merge_tail(pairs, before, &mut self.tail);
            pairs.dedup();
        }
    }

    /// The offsets, besides the direct test, at which the pair `(i, j)` (world indices)
    /// may overlap through the seam: each a translation of `j` next to `i`, in
    /// [`WorldBounds::image_offsets`] order. Empty for a pair of bodies without images.
    pub(crate) fn offsets(&self, i: usize, j: usize) -> impl Iterator<Item = Vec2> + '_ {
        let mask = match self.masks.get(i).zip(self.masks.get(j)) {
            // `j + o` near `i`: `j`'s own images, and `i`'s images negated.
            Some((&mi, &mj)) => mj | negated_mask(mi),
            None => 0,
        };
        (1..9)
            .filter(move |k| mask & (1 << k) != 0)
            .map(|k| self.offsets[k])
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::merge_tail;

    #[test]
    fn a_negated_mask_moves_each_bit_to_its_negated_offset() {
        for k in 1..9 {
            assert_eq!(
                super::negated_mask(1 << k),
                1 << super::negated(k),
                "bit {k}"
            );
        }
        // Bit 0 (the direct test) and bits past 8 are not images: left out.
        assert_eq!(super::negated_mask(1), 0);
        assert_eq!(super::negated_mask(0b11_1111_1110), 0b1_1111_1110);
    }

    proptest! {
        /// A sorted front and any tail come out as the whole sorted: tails before, between,
        /// after and equal to the front's items, empty fronts and tails.
        #[test]
        fn a_merged_tail_is_the_whole_sorted(
            mut front in prop::collection::vec((0..40u32, 0..40u32), 0..60),
            tail in prop::collection::vec((0..40u32, 0..40u32), 0..12),
        ) {
            front.sort_unstable();
            let sorted = front.len();
            let mut v = front;
            v.extend(&tail);
            let mut want = v.clone();
            want.sort_unstable();
            merge_tail(&mut v, sorted, &mut Vec::new());
            prop_assert_eq!(v, want);
        }
    }
}
