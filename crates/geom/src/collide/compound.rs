//! The part pairs of two compounds worth testing, culled by their bounds: the cost of a pair
//! of compounds follows the parts near each other, not parts × parts.
//!
//! The answer is the brute force's, bit for bit: the deepest contact of all part pairs, the
//! first in `(part of a, part of b)` order among equals. A pair is left out only when its
//! bounds are so far apart that it can neither be deeper than, nor tie with, the best pair
//! found (its depth is at most minus the gap between its bounds, and the gap is compared with
//! a margin far above the rounding of either).

use crate::bounds::Bounds;
use crate::contact::Contact;
use crate::math::{Rot, Vec2};
use crate::placed::{PlacedPrimitive, place_with};
use crate::shape::Primitive;

use super::{contact_placed, contact_placed_unless, overlaps_placed};

/// Up to this many part pairs, every pair is tested in order: nothing to place ahead, sort
/// or allocate (a body's shape is usually one primitive, or a handful).
pub(crate) const ALL_PAIRS: usize = 64;

/// One side of a pair: its parts and how they are placed, in the frame of the pair.
#[derive(Clone, Copy)]
pub(crate) struct Side<'a> {
    /// The parts.
    pub(crate) parts: &'a [Primitive],
    /// The body's position in the pair's frame.
    pub(crate) position: Vec2,
    /// The body's rotation.
    pub(crate) rot: Rot,
    /// The body's angle, radians.
    pub(crate) angle: f64,
}

impl Side<'_> {
    fn place(&self, part: &Primitive) -> PlacedPrimitive {
        place_with(part, self.position, self.rot, self.angle)
    }

    fn placed(&self) -> (Vec<PlacedPrimitive>, Vec<Bounds>) {
        let placed: Vec<PlacedPrimitive> = self.parts.iter().map(|p| self.place(p)).collect();
        let bounds = placed.iter().map(PlacedPrimitive::bounds).collect();
        (placed, bounds)
    }
}

/// The deepest contact of any part of `a` with any part of `b` (the nearest when none
/// overlaps), in the pair's frame; `None` only when a side has no parts.
pub(crate) fn deepest(a: Side<'_>, b: Side<'_>) -> Option<Contact> {
    if a.parts.len() * b.parts.len() <= ALL_PAIRS {
        return every_pair(a, b, |pa, pb| Some(contact_placed(pa, pb)));
    }
    culled(a, b)
}

/// `deepest(a, b)` when its depth is above `threshold`, `None` otherwise, with the same bits.
/// A part pair at most `threshold` deep can't be the deepest of a pair deeper than that, so
/// the part pairs that an axis rules out are left out ([`contact_placed_unless`]).
pub(crate) fn deepest_above(a: Side<'_>, b: Side<'_>, threshold: f64) -> Option<Contact> {
    let best = if a.parts.len() * b.parts.len() <= ALL_PAIRS {
        every_pair(a, b, |pa, pb| contact_placed_unless(pa, pb, threshold))
    } else {
        culled(a, b)
    };
    best.filter(|c| c.depth > threshold)
}

/// The deepest of `test`'s contacts over every part pair in order, the first among equals.
#[inline]
fn every_pair(
    a: Side<'_>,
    b: Side<'_>,
    test: impl Fn(&PlacedPrimitive, &PlacedPrimitive) -> Option<Contact>,
) -> Option<Contact> {
    let mut best: Option<Contact> = None;
    for pa in a.parts {
        let pa = a.place(pa);
        for pb in b.parts {
            #[cfg(test)]
            TESTED.with(|t| t.set(t.get() + 1));
            if let Some(c) = test(&pa, &b.place(pb))
                && best.is_none_or(|best| c.depth > best.depth)
            {
                best = Some(c);
            }
        }
    }
    best
}

/// [`deepest`] of more than [`ALL_PAIRS`] part pairs: only those near each other are tested.
fn culled(a: Side<'_>, b: Side<'_>) -> Option<Contact> {
    let ((pa, ba), (pb, bb)) = (a.placed(), b.placed());
    let margin = margin(&ba, &bb);
    let near = Near::new(&ba, &bb);
    let total = ba.len() * bb.len();
    // Rounds of growing reach: the pairs whose bounds are at most `reach` apart (and more
    // than the last round's), until the best pair found is nearer than any pair left.
    let (mut done, mut visited) = (f64::NEG_INFINITY, 0);
    let mut reach = margin;
    let mut best: Option<(Contact, (usize, usize))> = None;
    loop {
        near.visit(done, reach, |i, j| {
            visited += 1;
            #[cfg(test)]
            TESTED.with(|t| t.set(t.get() + 1));
            let c = contact_placed(&pa[i], &pb[j]);
            let better =
                best.is_none_or(|(b, at)| c.depth > b.depth || (c.depth == b.depth && (i, j) < at));
            if better {
                best = Some((c, (i, j)));
            }
        });
        // A pair left out is more than `reach` apart: its depth is below `margin - reach`.
        let settled = best.is_some_and(|(b, _)| b.depth >= margin - reach);
        if settled || visited >= total || !reach.is_finite() {
            break;
        }
        done = reach;
        reach = match best {
            Some((b, _)) => (margin - b.depth).max(reach * 2.0),
            None => reach * 2.0,
        };
    }
    best.map(|(c, _)| c)
}

/// Whether any part of `a` overlaps any part of `b`.
pub(crate) fn any_overlap(a: Side<'_>, b: Side<'_>) -> bool {
    if a.parts.len() * b.parts.len() <= ALL_PAIRS {
        return a.parts.iter().any(|pa| {
            let pa = a.place(pa);
            b.parts.iter().any(|pb| overlaps_placed(&pa, &b.place(pb)))
        });
    }
    let ((pa, ba), (pb, bb)) = (a.placed(), b.placed());
    let mut found = false;
    Near::new(&ba, &bb).visit(f64::NEG_INFINITY, margin(&ba, &bb), |i, j| {
        found = found || overlaps_placed(&pa[i], &pb[j]);
    });
    found
}

/// A distance far above the rounding of any bounds or depth in this frame (which is about
/// 1e-16 of the largest coordinate), far below any gap that matters.
pub(crate) fn margin(a: &[Bounds], b: &[Bounds]) -> f64 {
    let scale = a
        .iter()
        .chain(b)
        .map(|b| b.min.abs().max(b.max.abs()).max_element())
        .fold(0.0, f64::max);
    1e-9 * (1.0 + scale)
}

/// Calls `f(i, j)` for every box `a[i]` and box `b[j]` at most `upto` apart along each axis.
pub(crate) fn near_pairs(a: &[Bounds], b: &[Bounds], upto: f64, f: impl FnMut(usize, usize)) {
    if !a.is_empty() && !b.is_empty() {
        Near::new(a, b).visit(f64::NEG_INFINITY, upto, f);
    }
}

/// The gap between two boxes along the axis where they are furthest apart (negative when
/// they overlap): the true distance between their shapes is at least this.
fn gap(a: &Bounds, b: &Bounds) -> f64 {
    let x = (b.min.x - a.max.x).max(a.min.x - b.max.x);
    let y = (b.min.y - a.max.y).max(a.min.y - b.max.y);
    x.max(y)
}

/// Pairs of boxes near each other: `b`'s boxes sorted by their low edge along the axis the
/// boxes spread over most, so that the boxes within reach of one of `a`'s are a slice found
/// by binary search.
struct Near<'a> {
    a: &'a [Bounds],
    b: &'a [Bounds],
    /// 0 for x, 1 for y.
    axis: usize,
    /// `b`'s indices by low edge.
    order: Vec<usize>,
    /// `b`'s low edges, in that order.
    low: Vec<f64>,
    /// The widest of `b`'s boxes along the axis.
    widest: f64,
}

impl<'a> Near<'a> {
    fn new(a: &'a [Bounds], b: &'a [Bounds]) -> Near<'a> {
        let all = a.iter().chain(b).fold(a[0], |u, b| u.union(*b));
        let spread = all.max - all.min;
        let axis = usize::from(spread.y > spread.x);
        let mut order: Vec<usize> = (0..b.len()).collect();
        order.sort_by(|&i, &j| b[i].min[axis].total_cmp(&b[j].min[axis]).then(i.cmp(&j)));
        let low = order.iter().map(|&i| b[i].min[axis]).collect();
        let widest = b
            .iter()
            .map(|b| b.max[axis] - b.min[axis])
            .fold(0.0, f64::max);
        Near {
            a,
            b,
            axis,
            order,
            low,
            widest,
        }
    }

    /// Calls `f(i, j)` for every pair whose gap is in `(after, upto]`.
    fn visit(&self, after: f64, upto: f64, mut f: impl FnMut(usize, usize)) {
        let axis = self.axis;
        for (i, a) in self.a.iter().enumerate() {
            // A box of `b` within `upto` of `a` starts after `a.min - upto - widest` and
            // before `a.max + upto` along the axis.
            let from = self
                .low
                .partition_point(|&l| l < a.min[axis] - upto - self.widest);
            let to = self.low.partition_point(|&l| l <= a.max[axis] + upto);
            for &j in &self.order[from..to.max(from)] {
                let g = gap(a, &self.b[j]);
                if g > after && g <= upto {
                    f(i, j);
                }
            }
        }
    }
}

#[cfg(test)]
thread_local! {
    /// Part pairs [`deepest`] tested, on this thread: what the culling saves, counted.
    static TESTED: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{MAX_COMPOUND_PARTS, Pose, Shape, contact};

    /// 32 x 32 unit circles, 3 apart: the largest compound there may be.
    fn grid() -> Shape {
        let parts = (0..MAX_COMPOUND_PARTS)
            .map(|k| {
                let (i, j) = ((k % 32) as f64, (k / 32) as f64);
                Primitive::circle(Vec2::new(3.0 * i, 3.0 * j), 1.0).unwrap()
            })
            .collect();
        Shape::compound(parts).unwrap()
    }

    fn tested(a: &Shape, pa: &Pose, b: &Shape, pb: &Pose) -> (Contact, usize) {
        TESTED.with(|t| t.set(0));
        let c = contact(a, pa, b, pb);
        (c, TESTED.with(std::cell::Cell::get))
    }

    #[test]
    fn two_largest_compounds_touching_at_a_corner_test_a_handful_of_part_pairs() {
        // Every pair tested was 1024 x 1024 = 1,048,576 contacts; the corner parts overlap
        // by 0.5 and only the pairs whose bounds touch are tested.
        let g = grid();
        let (c, n) = tested(&g, &Pose::at(0.0, 0.0), &g, &Pose::at(94.5, 93.0));
        assert_eq!(c.depth, 0.5);
        assert_eq!(c.normal, Vec2::X);
        assert!(n <= 4, "{n} part pairs tested");
    }

    #[test]
    fn two_largest_compounds_apart_test_a_thousandth_of_the_part_pairs() {
        // 10 apart along x, rows aligned: the 32 facing pairs are the nearest (all at 8).
        // The reach doubles until a pair is within it (up to 16, twice the nearest gap), so
        // the pairs tested are those within 16: about 3 x 32 x 11, not 1024 x 1024.
        let g = grid();
        let (c, n) = tested(&g, &Pose::at(0.0, 0.0), &g, &Pose::at(103.0, 0.0));
        assert_eq!(c.depth, -8.0);
        // The first pair in part order among the 32 equals: a's part 31 with b's part 0, surfaces at 94 and 102.
        assert_eq!(c.point, Vec2::new(98.0, 0.0));
        assert!(n <= 1_100, "{n} part pairs tested");
    }
}
