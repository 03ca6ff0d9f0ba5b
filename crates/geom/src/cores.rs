//! The general algorithm: every primitive is a convex *core* (a point, a segment or a convex
//! polygon) swept by a radius. A circle is a point plus a radius, a capsule a segment plus a
//! radius, a box or polygon a polygon with radius zero.
//!
//! For two cores `A` and `B` with radii `ra` and `rb`, the Minkowski difference `B - A` is a
//! convex polygon `M` (possibly degenerate), and the pair overlaps when the origin is within
//! `ra + rb` of `M`:
//! - **Cores apart.** Some axis separates them. The distance between two disjoint convex cores
//!   is reached between a vertex of one and an edge of the other, so checking every
//!   vertex–edge pair gives it exactly: `depth = ra + rb - distance`.
//! - **Cores intersecting.** The origin is inside `M`, and its distance to `M`'s boundary is
//!   the smallest support value `h_M(u)` over unit directions `u`, reached at an edge normal
//!   of `M`. `M`'s edges are the edges of `A` and `B`, so the separating-axis overlaps over
//!   both shapes' edge normals give it exactly: `depth = min overlap + ra + rb`. Extra axes
//!   (a segment's direction, say) can't lower the minimum below the truth, because every
//!   direction's overlap is at least the distance to the boundary.
//!
//! At most 8 + 8 vertices, so the quadratic vertex–edge scan is a few hundred flops: cheaper
//! and far simpler than GJK + EPA, and exact rather than iterative.

use crate::contact::Contact;
use crate::math::{Vec2, cross, right_perp};
use crate::shape::MAX_POLYGON_VERTICES;

/// A convex core swept by a radius. `count` is 1 (a point), 2 (a segment) or 3 and more (a
/// counter-clockwise polygon whose outward unit edge normals are in `normals`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Core {
    pub(crate) points: [Vec2; MAX_POLYGON_VERTICES],
    pub(crate) normals: [Vec2; MAX_POLYGON_VERTICES],
    pub(crate) count: usize,
    pub(crate) radius: f64,
}

impl Core {
    pub(crate) fn point(p: Vec2, radius: f64) -> Core {
        let mut points = [Vec2::ZERO; MAX_POLYGON_VERTICES];
        points[0] = p;
        Core {
            points,
            normals: [Vec2::ZERO; MAX_POLYGON_VERTICES],
            count: 1,
            radius,
        }
    }

    /// A segment; a zero-length one is a point.
    pub(crate) fn segment(a: Vec2, b: Vec2, radius: f64) -> Core {
        let mut core = Core::point(a, radius);
        if a != b {
            core.points[1] = b;
            core.count = 2;
        }
        core
    }

    /// A box with unit axes `ux`, `uy` (`uy` is `ux` turned a quarter counter-clockwise).
    pub(crate) fn quad(center: Vec2, ux: Vec2, uy: Vec2, half: Vec2) -> Core {
        let x = ux * half.x;
        let y = uy * half.y;
        let mut points = [Vec2::ZERO; MAX_POLYGON_VERTICES];
        points[..4].copy_from_slice(&[
            center - x - y,
            center + x - y,
            center + x + y,
            center - x + y,
        ]);
        let mut normals = [Vec2::ZERO; MAX_POLYGON_VERTICES];
        normals[..4].copy_from_slice(&[-uy, ux, uy, -ux]);
        Core {
            points,
            normals,
            count: 4,
            radius: 0.0,
        }
    }

    fn points(&self) -> &[Vec2] {
        &self.points[..self.count]
    }

    /// Smallest and largest projection of the core's points on `u`: the first of equal
    /// ones, NaN ignored (NaN when every projection is).
    ///
    /// Plain comparisons, not `f64::min` and `max`: those test for NaN at every point, about
    /// half of the loop, to give the same answer. Starting from the infinities, a first
    /// point that is NaN is passed over as `min` passes it; the first point's value is kept
    /// on a tie as `min` keeps it on x86-64, so the answer is the same bits (signed zeros
    /// included).
    #[inline]
    fn project(&self, u: Vec2) -> (f64, f64) {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for p in &self.points[..self.count] {
            let d = p.dot(u);
            if d < lo {
                lo = d;
            }
            if d > hi {
                hi = d;
            }
        }
        if lo > hi {
            // Every projection NaN (a non-empty list of numbers has `lo <= hi`).
            return (f64::NAN, f64::NAN);
        }
        (lo, hi)
    }

    /// Edge `i` as its two ends. A point has one degenerate edge, a segment one edge.
    #[inline]
    fn edge(&self, i: usize) -> (Vec2, Vec2) {
        match self.count {
            1 => (self.points[0], self.points[0]),
            2 => (self.points[0], self.points[1]),
            n => (self.points[i], self.points[(i + 1) % n]),
        }
    }

    fn edge_count(&self) -> usize {
        if self.count <= 2 { 1 } else { self.count }
    }

    /// This core's candidate axes: polygon edge normals, or a segment's normal and direction
    /// (its end caps), written to `segment`; none for a point.
    fn axes<'a>(&'a self, segment: &'a mut [Vec2; 2]) -> &'a [Vec2] {
        match self.count {
            1 => &[],
            2 => {
                let d = (self.points[1] - self.points[0]).normalize();
                *segment = [right_perp(d), d];
                segment
            }
            n => &self.normals[..n],
        }
    }
}

/// Calls `f` on the candidate axes of a pair in order (`a`'s, `b`'s, and for two points the
/// direction between them; a non-finite one, from a degenerate edge, left out) until it
/// returns `Some`, and returns that. Read in place: nothing is copied. Plain loops, always
/// inlined: through chained iterators, [`min_overlap`] took about 8% more instructions.
#[inline(always)]
fn each_axis<T>(a: &Core, b: &Core, mut f: impl FnMut(Vec2) -> Option<T>) -> Option<T> {
    let (mut sa, mut sb) = ([Vec2::ZERO; 2], [Vec2::ZERO; 2]);
    // Two points have no axes of their own, only the direction between them. Listed with
    // the others, so that `f` is called from one place (and inlined there: called from two,
    // it was a call an axis).
    let mut between = [Vec2::ZERO];
    let between: &[Vec2] = if a.count == 1 && b.count == 1 && a.points[0] != b.points[0] {
        between[0] = (b.points[0] - a.points[0]).normalize();
        &between
    } else {
        &[]
    };
    for axes in [a.axes(&mut sa), b.axes(&mut sb), between] {
        for &u in axes {
            if u.is_finite()
                && let Some(t) = f(u)
            {
                return Some(t);
            }
        }
    }
    None
}

/// The smallest separating-axis overlap of two cores (radii not included) and the direction
/// (from `a` to `b`) it is reached in; or, as soon as an axis's overlap is below `stop`, that
/// axis's (the search stops there: the cores are at least that far apart). `None` when there
/// is no axis at all: two coincident points.
fn min_overlap(a: &Core, b: &Core, stop: f64) -> Option<(f64, Vec2)> {
    let mut best: Option<(f64, Vec2)> = None;
    each_axis(a, b, |u| overlap_along(a, b, u, stop, &mut best)).or(best)
}

/// One axis of [`min_overlap`]: its overlap if below `stop`, else `None` with `best` (the
/// smallest so far, the first among equals) brought up to date.
#[inline(always)]
fn overlap_along(
    a: &Core,
    b: &Core,
    u: Vec2,
    stop: f64,
    best: &mut Option<(f64, Vec2)>,
) -> Option<(f64, Vec2)> {
    let (amin, amax) = a.project(u);
    let (bmin, bmax) = b.project(u);
    // Moving b along +u by (amax - bmin) separates the cores; along -u by (bmax - amin).
    let (plus, minus) = (amax - bmin, bmax - amin);
    if plus < stop {
        return Some((plus, u));
    }
    if minus < stop {
        return Some((minus, -u));
    }
    for (overlap, dir) in [(plus, u), (minus, -u)] {
        if best.is_none_or(|(o, _)| overlap < o) {
            *best = Some((overlap, dir));
        }
    }
    None
}

/// A length far above the rounding of any projection or distance between these cores and of
/// `threshold - ra - rb` (about 1e-16 of the largest of their coordinates and the threshold),
/// far below any gap that matters; NaN or infinite when any of those is, so that nothing is
/// ruled out then.
fn margin(a: &Core, b: &Core, threshold: f64) -> f64 {
    let size = |c: &Core| {
        c.points()
            .iter()
            .fold(c.radius, |s, p| s + p.x.abs() + p.y.abs())
    };
    1e-9 * (1.0 + threshold.abs() + size(a) + size(b))
}

/// The closest points of two cores that do not intersect: `(distance, on_a, on_b, normal)`,
/// with the normal from `a` to `b` taken from the edge's own normal when the closest point is
/// inside an edge (exact even when the gap is tiny), and from the two points otherwise.
fn closest(a: &Core, b: &Core) -> (f64, Vec2, Vec2, Vec2) {
    let mut best = (f64::INFINITY, Vec2::ZERO, Vec2::ZERO, Vec2::ZERO);
    // Vertices of `a` against edges of `b`: the normal found points from b's edge to the
    // vertex, so it is reversed to point from a to b.
    for &p in a.points() {
        for i in 0..b.edge_count() {
            let (s0, s1) = b.edge(i);
            let (d, q, n) = point_segment(p, s0, s1);
            if d < best.0 {
                best = (d, p, q, -n);
            }
        }
    }
    if a.count == 1 && b.count == 1 {
        return best;
    }
    for &q in b.points() {
        for i in 0..a.edge_count() {
            let (s0, s1) = a.edge(i);
            let (d, p, n) = point_segment(q, s0, s1);
            if d < best.0 {
                best = (d, p, q, n);
            }
        }
    }
    best
}

/// Distance from `p` to the segment `s0`–`s1`, the closest point on it, and the unit direction
/// from that point to `p` (zero when `p` is on the segment's end point).
#[inline]
fn point_segment(p: Vec2, s0: Vec2, s1: Vec2) -> (f64, Vec2, Vec2) {
    let e = s1 - s0;
    let ee = e.dot(e);
    let w = p - s0;
    let t = if ee > 0.0 { w.dot(e) / ee } else { 0.0 };
    if t > 0.0 && t < 1.0 {
        // Inside the edge: measure along the edge normal, which is exact however small the gap.
        let len = ee.sqrt();
        let side = cross(e, w) / len; // > 0 when p is to the left of s0 -> s1
        let left = Vec2::new(-e.y, e.x) / len;
        let n = if side >= 0.0 { left } else { -left };
        return (side.abs(), s0 + e * t, n);
    }
    let q = if t <= 0.0 { s0 } else { s1 };
    let d = p - q;
    let len = d.length();
    let n = if len > 0.0 { d / len } else { Vec2::ZERO };
    (len, q, n)
}

/// The one or two points of `core` furthest along `dir`, as their range along `tangent`, and
/// the furthest value along `dir`.
fn feature(core: &Core, dir: Vec2, tangent: Vec2) -> (f64, f64, f64) {
    let pts = core.points();
    // The two maxima in one pass: each the same fold, in the same order.
    let (mut top, mut scale) = (f64::NEG_INFINITY, 0.0);
    for p in pts {
        top = f64::max(top, p.dot(dir));
        scale = f64::max(scale, p.abs().max_element());
    }
    let eps = 1e-12 * scale.max(f64::MIN_POSITIVE);
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for p in pts {
        // Picked by bits, not branched on: whether a point is on the feature is a coin toss
        // from pair to pair (the compiler made an `if` of a plain `if` select).
        let on = p.dot(dir) >= top - eps;
        let t = p.dot(tangent);
        lo = pick(on, lo.min(t), lo);
        hi = pick(on, hi.max(t), hi);
    }
    (lo, hi, top)
}

/// `a` when `on`, else `b`, the same bits, by a mask: no branch however the compiler sees it.
#[inline(always)]
fn pick(on: bool, a: f64, b: f64) -> f64 {
    let mask = u64::from(on).wrapping_neg();
    f64::from_bits((a.to_bits() & mask) | (b.to_bits() & !mask))
}

/// The contact point of intersecting cores along `normal` (a to b): midway between the two
/// surfaces, in the middle of the overlap of the touching features.
fn penetration_point(a: &Core, b: &Core, normal: Vec2) -> Vec2 {
    let tangent = Vec2::new(-normal.y, normal.x);
    let (alo, ahi, atop) = feature(a, normal, tangent);
    let (blo, bhi, bneg) = feature(b, -normal, tangent);
    let (lo, hi) = (alo.max(blo), ahi.min(bhi));
    let along = if lo <= hi {
        0.5 * (lo + hi)
    } else {
        0.5 * (blo + bhi)
    };
    let across = 0.5 * ((atop + a.radius) + (-bneg - b.radius));
    tangent * along + normal * across
}

/// The contact of two cores in one frame. See the module docs for why it is exact.
#[must_use]
pub fn collide_cores(a: &Core, b: &Core) -> Contact {
    finish(a, b, min_overlap(a, b, f64::NEG_INFINITY))
}

/// `collide_cores(a, b)`, with the same bits; or `None` when an axis alone shows that its
/// depth is at most `threshold` (then the rest of the axes and the closest-point scan, the
/// costly part for a pair apart, are skipped).
///
/// The depth of two cores is at most `ra + rb` plus the overlap along any one axis (the gap
/// along an axis is at most the distance), so an axis whose overlap is below
/// `threshold - ra - rb` by more than a margin rules the pair out. The margin, far above the
/// rounding of either computation, keeps the verdict the exact algorithm's.
pub(crate) fn collide_cores_unless(a: &Core, b: &Core, threshold: f64) -> Option<Contact> {
    let stop = threshold - (a.radius + b.radius) - margin(a, b, threshold);
    // The direction between the cores' centres first: for a pair apart it is usually close
    // to the best separating axis, and one projection rules most such pairs out. Projected
    // on `d` as it is, not made unit (a square root and a division on the pair's critical
    // path): the overlap along it is `(amax - bmin) / |d|`, compared with `stop` squared.
    let d = centre(b) - centre(a);
    let dd = d.dot(d);
    // A length far from underflow and overflow, so that the squares stay exact to rounding.
    if dd.is_finite() && dd >= 1e-150 {
        let ((_, amax), (bmin, _)) = (a.project(d), b.project(d));
        if below(amax - bmin, stop, dd) {
            return None;
        }
    }
    let least = min_overlap(a, b, stop);
    if least.is_some_and(|(overlap, _)| overlap < stop) {
        return None;
    }
    Some(finish(a, b, least))
}

/// Whether `x / sqrt(dd) < stop` (`dd > 0`), without the square root: both sides'
/// squares, once their signs are known. False when any is NaN. Rounding moves the answer
/// only for an `x` within a few units in the last place of the bound, far inside the margin
/// [`collide_cores_unless`] leaves.
#[inline]
fn below(x: f64, stop: f64, dd: f64) -> bool {
    // `&` and `|`, not `&&` and `||`: whether `x` is negative is a coin toss from pair to
    // pair, and the products cost less than its mispredicted branch.
    if stop < 0.0 {
        (x < 0.0) & (x * x > stop * stop * dd)
    } else if stop >= 0.0 {
        (x < 0.0) | (x * x < stop * stop * dd)
    } else {
        false
    }
}

/// The mean of a core's points.
fn centre(c: &Core) -> Vec2 {
    c.points().iter().fold(Vec2::ZERO, |s, p| s + *p) / c.count as f64
}

/// [`collide_cores`] after the separating-axis pass found `least` (its smallest overlap).
fn finish(a: &Core, b: &Core, least: Option<(f64, Vec2)>) -> Contact {
    let r = a.radius + b.radius;
    let Some((overlap, dir)) = least else {
        // Two coincident points (concentric circles): every direction is equally short.
        // Pick +y, so a body spawned inside another pops up, as a platformer expects.
        return Contact {
            depth: r,
            normal: Vec2::Y,
            point: a.points[0],
        };
    };
    if overlap >= 0.0 {
        return Contact {
            depth: overlap + r,
            normal: dir,
            point: penetration_point(a, b, dir),
        };
    }
    let (distance, pa, pb, mut normal) = closest(a, b);
    if normal == Vec2::ZERO {
        // The scan says the cores touch at a vertex although an axis separated them by a
        // rounding error: the separating axis is the better direction.
        normal = dir;
    }
    let sa = pa + normal * a.radius;
    let sb = pb - normal * b.radius;
    Contact {
        depth: r - distance,
        normal,
        point: 0.5 * (sa + sb),
    }
}

/// Whether two cores overlap (`collide_cores(a, b).depth > 0`), stopping at the first axis
/// that separates them by at least the sum of the radii.
#[must_use]
pub fn overlaps_cores(a: &Core, b: &Core) -> bool {
    let r = a.radius + b.radius;
    let (mut any, mut least) = (false, f64::INFINITY);
    let apart = each_axis(a, b, |u| {
        any = true;
        let (amin, amax) = a.project(u);
        let (bmin, bmax) = b.project(u);
        let overlap = (amax - bmin).min(bmax - amin);
        if overlap + r <= 0.0 {
            return Some(());
        }
        least = least.min(overlap);
        None
    });
    if apart.is_some() {
        return false;
    }
    if !any {
        return r > 0.0;
    }
    if least >= 0.0 {
        return least + r > 0.0;
    }
    r - closest(a, b).0 > 0.0
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    /// A coordinate: mostly ordinary, sometimes a signed zero, an infinity or NaN.
    fn coordinate() -> impl Strategy<Value = f64> {
        prop_oneof![
            6 => -4.0..4.0f64,
            1 => Just(0.0),
            1 => Just(-0.0),
            1 => Just(f64::INFINITY),
            1 => Just(f64::NAN),
        ]
    }

    proptest! {
        /// `below` answers `x / sqrt(dd) < stop` wherever the two sides are apart by more
        /// than rounding, whatever the signs; and false with a NaN.
        #[test]
        fn below_is_the_quotient_compared(
            x in -1e6..1e6f64,
            stop in prop_oneof![-1e3..1e3f64, Just(0.0), Just(-0.0)],
            dd in 1e-150..1e12f64,
        ) {
            let q = x / dd.sqrt();
            if (q - stop).abs() > 1e-12 * (q.abs() + stop.abs()) {
                prop_assert_eq!(below(x, stop, dd), q < stop, "{} against {}", q, stop);
            }
            prop_assert!(!below(f64::NAN, stop, dd));
            prop_assert!(!below(x, f64::NAN, dd));
        }

        /// `pick` is `if on { a } else { b }`, to the bit (NaN payloads and signed zeros).
        #[test]
        fn a_pick_is_the_choice(on: bool, a in coordinate(), b in coordinate(), bits: u64) {
            let c = f64::from_bits(bits);
            for (x, y) in [(a, b), (c, b), (a, c)] {
                let want = if on { x } else { y };
                prop_assert_eq!(pick(on, x, y).to_bits(), want.to_bits());
            }
        }

        /// `project` is the first smallest and the first largest of the projections, NaN
        /// ignored (NaN when all are), to the bit: ties between `0.0` and `-0.0` keep the
        /// first, as `f64::min` and `max` did here on x86-64.
        #[test]
        fn a_projection_is_the_first_extreme_of_the_numbers(
            xy in prop::collection::vec((coordinate(), coordinate()), 1..=MAX_POLYGON_VERTICES),
            u in (coordinate(), coordinate()),
        ) {
            let mut core = Core::point(Vec2::ZERO, 0.0);
            for (k, &(x, y)) in xy.iter().enumerate() {
                core.points[k] = Vec2::new(x, y);
            }
            core.count = xy.len();
            let u = Vec2::new(u.0, u.1);
            let numbers: Vec<f64> =
                core.points().iter().map(|p| p.dot(u)).filter(|d| !d.is_nan()).collect();
            let first = |better: fn(f64, f64) -> bool| {
                numbers.iter().copied().reduce(|m, d| if better(d, m) { d } else { m })
            };
            let want = first(|d, m| d < m).zip(first(|d, m| d > m));
            let (lo, hi) = core.project(u);
            match want {
                Some((want_lo, want_hi)) => {
                    prop_assert_eq!(lo.to_bits(), want_lo.to_bits());
                    prop_assert_eq!(hi.to_bits(), want_hi.to_bits());
                }
                None => prop_assert!(lo.is_nan() && hi.is_nan()),
            }
        }
    }

    #[test]
    fn point_on_segment_interior_uses_the_edge_normal() {
        let (d, q, n) = point_segment(Vec2::new(0.5, 1e-300), Vec2::ZERO, Vec2::X);
        assert_eq!(d, 1e-300);
        assert_eq!(q, Vec2::new(0.5, 0.0));
        assert_eq!(n, Vec2::Y);
    }

    #[test]
    fn coincident_points_give_a_finite_unit_normal() {
        let c = collide_cores(&Core::point(Vec2::ONE, 1.0), &Core::point(Vec2::ONE, 2.0));
        assert_eq!(c.depth, 3.0);
        assert_eq!(c.normal.length(), 1.0);
    }
}
