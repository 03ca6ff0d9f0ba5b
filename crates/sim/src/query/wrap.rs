//! Queries in a wrap world: every image of a body is seen, and a ray (or a cast shape's
//! path) that leaves one edge goes on from the opposite one.
//!
//! A query is brought into the world first (its origin, point or pose wrapped by whole
//! world sizes into `[min, max)`), then split into **segments** that each stay inside the
//! world: a segment ends where the path crosses an edge, and the next starts on the
//! opposite edge, its distance along the path accumulated. Each segment is asked of the
//! trees nine times, translated by minus each of [`WorldBounds::image_offsets`]: the body
//! images within one world size, which hold every image a body inside the world (or
//! sticking out of it by less than half its size, as the wrap seam keeps them) can have.
//! A point found in an image is reported in world coordinates, where the image is.
//!
//! A path crosses at most [`MAX_SEGMENTS`] edges: a ray hundreds of world sizes long (or
//! one running along an edge forever) stops there. In a world without wrap a query is one
//! segment, the direct image only.

use ricochet_geom::{Bounds, Vec2};

use crate::def::WorldBounds;

/// The most segments a wrapped path is split into.
pub(crate) const MAX_SEGMENTS: usize = 1024;

/// The world sizes the wrap applies, if the world wraps.
pub(crate) fn wrapping(bounds: Option<&WorldBounds>) -> Option<&WorldBounds> {
    bounds.filter(|b| b.wrap)
}

/// The image offsets a query must look at: all nine in a wrap world, else the direct one
/// (the array, and how many of it are used; no allocation per query).
pub(crate) fn offsets(wrap: Option<&WorldBounds>) -> ([Vec2; 9], usize) {
    match wrap {
        Some(b) => (b.image_offsets(), 9),
        None => ([Vec2::ZERO; 9], 1),
    }
}

/// The images of the bodies a query looks at: which of [`offsets`]' nine (a bit each, in
/// that order), with no array built or copied a query.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Images {
    size: Vec2,
    mask: u16,
}

/// Each of [`WorldBounds::image_offsets`]' nine, as world sizes per axis, in its order.
const STEPS: [(f64, f64); 9] = [
    (0.0, 0.0),
    (-1.0, -1.0),
    (-1.0, 0.0),
    (-1.0, 1.0),
    (0.0, -1.0),
    (0.0, 1.0),
    (1.0, -1.0),
    (1.0, 0.0),
    (1.0, 1.0),
];

impl Images {
    /// The offsets of the images looked at, in [`offsets`]' order (the same arithmetic,
    /// so the same bits, as [`WorldBounds::image_offsets`]).
    pub(crate) fn iter(self) -> impl Iterator<Item = Vec2> {
        // The set bits, lowest first: one step for the usual query, the direct image only.
        let mut mask = self.mask;
        std::iter::from_fn(move || {
            if mask == 0 {
                return None;
            }
            let k = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            let (sx, sy) = STEPS[k];
            Some(Vec2::new(sx * self.size.x, sy * self.size.y))
        })
    }
}

/// The images among [`offsets`]' at which the query box `q`, moved by `shift - offset`,
/// meets `hull` (touching counts; the box around every member, [`super::index::hull`]);
/// every image when `q` is `None` (an endless ray). The same arithmetic, axis by axis, as
/// [`Bounds::translated`] and [`Bounds::overlaps`] in the per-set test that follows, so no
/// image that test would walk is dropped: a query well inside the world looks at the
/// direct image only, for six comparisons per axis instead of nine box tests per set.
/// Inline: passed through memory, the caller's hull was stored in one split and read back
/// in another, which stalled the loads.
#[inline(always)]
pub(crate) fn images(
    wrap: Option<&WorldBounds>,
    q: Option<&Bounds>,
    shift: Vec2,
    hull: Option<Bounds>,
) -> Images {
    let size = wrap.map_or(Vec2::ZERO, WorldBounds::size);
    let all = if wrap.is_some() { 0x1ff } else { 1 };
    let Some(hull) = hull else {
        return Images { size, mask: 0 };
    };
    let Some(q) = q else {
        return Images { size, mask: all };
    };
    // Whether the query meets the hull with the bodies moved by `s` world sizes, on one
    // axis (each axis's fields named, not indexed: an index is a match a comparison).
    let meets = |(q0, q1, h0, h1, shift, size): (f64, f64, f64, f64, f64, f64), s: f64| {
        let d = shift - s * size;
        (q0 + d <= h1) & (h0 <= q1 + d)
    };
    let ax = (q.min.x, q.max.x, hull.min.x, hull.max.x, shift.x, size.x);
    let ay = (q.min.y, q.max.y, hull.min.y, hull.max.y, shift.y, size.y);
    if wrap.is_none() {
        return Images {
            size,
            mask: u16::from(meets(ax, 0.0) & meets(ay, 0.0)),
        };
    }
    let x = [meets(ax, -1.0), meets(ax, 0.0), meets(ax, 1.0)];
    let y = [meets(ay, -1.0), meets(ay, 0.0), meets(ay, 1.0)];
    if x == [false, true, false] && y == [false, true, false] {
        // Well inside the world: the direct image only.
        return Images { size, mask: 1 };
    }
    let mut mask = 0;
    for (k, &(sx, sy)) in STEPS.iter().enumerate() {
        // `s + 1`: the lane of -1, 0 or +1 world sizes.
        let (i, j) = ((sx + 1.0) as usize, (sy + 1.0) as usize);
        mask |= u16::from(x[i] & y[j]) << k;
    }
    Images { size, mask }
}

/// `p` moved by whole world sizes into `[min, max)` on each axis.
pub(crate) fn wrap_point(b: &WorldBounds, p: Vec2) -> Vec2 {
    let axis = |v: f64, min: f64, s: f64| {
        if v >= min && v < min + s {
            v
        } else {
            let w = min + (v - min).rem_euclid(s);
            // Rounding can land on `min + s`.
            if w >= min + s { min } else { w }
        }
    };
    let size = b.size();
    Vec2::new(axis(p.x, b.min.x, size.x), axis(p.y, b.min.y, size.y))
}

/// Calls `f(start, travelled, length)` for each segment of the path from `origin` along
/// the unit `dir` for `max` (see the module docs), in order, while `f` returns `true`.
/// `origin` is inside the world (wrapped first).
pub(crate) fn segments(
    wrap: Option<&WorldBounds>,
    origin: Vec2,
    dir: Vec2,
    max: f64,
    f: &mut impl FnMut(Vec2, f64, f64) -> bool,
) {
    let Some(b) = wrap else {
        f(origin, 0.0, max);
        return;
    };
    let (mut p, mut travelled) = (origin, 0.0);
    for _ in 0..MAX_SEGMENTS {
        // The distance to the edge the path leaves by, per axis.
        let exit = |axis: usize| -> f64 {
            let d = dir[axis];
            if d > 0.0 {
                (b.max[axis] - p[axis]) / d
            } else if d < 0.0 {
                (b.min[axis] - p[axis]) / d
            } else {
                f64::INFINITY
            }
        };
        let (tx, ty) = (exit(0).max(0.0), exit(1).max(0.0));
        let t = tx.min(ty);
        let left = max - travelled;
        if t >= left {
            f(p, travelled, left);
            return;
        }
        if !f(p, travelled, t) {
            return;
        }
        travelled += t;
        let mut next = p + dir * t;
        for (axis, ta) in [(0, tx), (1, ty)] {
            if ta == t {
                // Onto the opposite edge, exactly.
                next[axis] = if dir[axis] > 0.0 {
                    b.min[axis]
                } else {
                    b.max[axis]
                };
            } else {
                next[axis] = next[axis].clamp(b.min[axis], b.max[axis]);
            }
        }
        p = next;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The images the per-set test would walk: every one of the nine whose moved query box
    /// meets the hull, by `Bounds::overlaps`.
    fn brute(b: &WorldBounds, q: &Bounds, shift: Vec2, hull: &Bounds) -> Vec<Vec2> {
        b.image_offsets()
            .into_iter()
            .filter(|&o| q.translated(shift - o).overlaps(hull))
            .collect()
    }

    #[test]
    fn the_images_kept_are_those_whose_query_box_meets_the_hull_in_order() {
        let b = WorldBounds {
            min: Vec2::new(-10.0, 0.0),
            max: Vec2::new(30.0, 20.0),
            wrap: true,
        };
        // The hull sticks out of the world by 1.5 on the left and 0.5 at the top.
        let hull = Bounds {
            min: Vec2::new(-11.5, 0.0),
            max: Vec2::new(30.0, 20.5),
        };
        let mut cases = 0;
        let mut several = 0;
        // Boxes along both axes across the world and past its edges, some touching the
        // hull's images exactly (the grid's steps of 0.5 land on its faces).
        for ix in -4..=84 {
            for iy in -4..=44 {
                let c = Vec2::new(-10.0 + f64::from(ix) * 0.5, f64::from(iy) * 0.5);
                for h in [Vec2::new(0.25, 0.5), Vec2::new(1.0, 0.25), Vec2::splat(6.0)] {
                    let q = Bounds::around(c, h);
                    let shift = wrap_point(&b, c) - c;
                    let got: Vec<Vec2> = images(Some(&b), Some(&q), shift, Some(hull))
                        .iter()
                        .collect();
                    let want = brute(&b, &q, shift, &hull);
                    assert_eq!(got, want, "{q:?}");
                    cases += 1;
                    several += usize::from(want.len() > 1);
                }
            }
        }
        assert!(
            several > cases / 20,
            "{several} of {cases}: too few near the edges"
        );
        // No hull: nothing; an endless ray: all nine; no wrap: the direct image if met.
        let q = Bounds::around(Vec2::new(5.0, 5.0), Vec2::ONE);
        assert_eq!(
            images(Some(&b), Some(&q), Vec2::ZERO, None).iter().count(),
            0
        );
        assert_eq!(
            images(Some(&b), None, Vec2::ZERO, Some(hull))
                .iter()
                .count(),
            9
        );
        let far = Bounds::around(Vec2::new(500.0, 5.0), Vec2::ONE);
        assert_eq!(
            images(None, Some(&q), Vec2::ZERO, Some(hull))
                .iter()
                .count(),
            1
        );
        assert_eq!(
            images(None, Some(&far), Vec2::ZERO, Some(hull))
                .iter()
                .count(),
            0
        );
    }
}
