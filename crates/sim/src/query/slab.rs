//! The ray walk's slab test (`tree.rs`): where a segment enters a box, set up once a walk
//! (the direction inverted, each axis' near face picked by the direction's sign, one
//! rounding margin), and the same for a node's four children at once.

use ricochet_geom::{Bounds, Vec2};

use super::tree::{MAX_X, MAX_Y, MIN_X, MIN_Y, Quad};

/// A segment's slab test, set up once a walk.
pub(super) struct Slab {
    origin: Vec2,
    /// `1 / dir` per axis (infinite along an axis the segment is parallel to).
    inv: Vec2,
    /// Whether the segment is parallel to the faces of either axis.
    flat: bool,
    /// Per axis, whether the segment runs towards smaller coordinates (it meets a box's
    /// `max` face first).
    back: [bool; 2],
    /// One rounding margin for the whole walk: the root's, which is at least any box's.
    pad: Vec2,
    /// `origin + pad` and `origin - pad`: `min - pad - origin` is `min - from_min`.
    from_min: Vec2,
    from_max: Vec2,
    /// Per axis, the [`Quad`] row of the face the segment meets first, and of the other.
    near: [usize; 2],
    far: [usize; 2],
    /// Per axis, the origin as padded against the near face and against the far face.
    near_from: Vec2,
    far_from: Vec2,
}

impl Slab {
    pub(super) fn new(origin: Vec2, dir: Vec2, root: &Bounds) -> Slab {
        let inv = Vec2::new(1.0 / dir.x, 1.0 / dir.y);
        let pad = root.max.abs().max(root.min.abs()).max(origin.abs()) * 1e-12;
        let back = [dir.x < 0.0, dir.y < 0.0];
        let (from_min, from_max) = (origin + pad, origin - pad);
        // The near face is padded against the origin by the one the direction meets first
        // (`from_min` for a min face), as `enter` pads each face.
        let pick = |axis: usize, b: bool| if b { from_max[axis] } else { from_min[axis] };
        Slab {
            origin,
            inv,
            flat: inv.x.is_infinite() || inv.y.is_infinite(),
            back,
            pad,
            from_min,
            from_max,
            near: [
                if back[0] { MAX_X } else { MIN_X },
                if back[1] { MAX_Y } else { MIN_Y },
            ],
            far: [
                if back[0] { MIN_X } else { MAX_X },
                if back[1] { MIN_Y } else { MAX_Y },
            ],
            near_from: Vec2::new(pick(0, back[0]), pick(1, back[1])),
            far_from: Vec2::new(pick(0, !back[0]), pick(1, !back[1])),
        }
    }

    /// Where the segment, `t` in `[0, max]`, enters `b` widened by the margin (touching
    /// counts), or `None` if it misses. The margin covers rounding, so a segment that only
    /// grazes a box is never lost (the exact test follows).
    #[inline]
    pub(super) fn enter(&self, b: &Bounds, max: f64) -> Option<f64> {
        if self.flat {
            return self.enter_flat(b, max);
        }
        let to_min = (b.min - self.from_min) * self.inv;
        let to_max = (b.max - self.from_max) * self.inv;
        let (near_x, far_x) = if self.back[0] {
            (to_max.x, to_min.x)
        } else {
            (to_min.x, to_max.x)
        };
        let (near_y, far_y) = if self.back[1] {
            (to_max.y, to_min.y)
        } else {
            (to_min.y, to_max.y)
        };
        let enter = near_x.max(near_y).max(0.0);
        let exit = far_x.min(far_y).min(max);
        (enter <= exit).then_some(enter)
    }

    /// [`Slab::enter`] of the four lanes of `q` at once: each lane's entry distance, and
    /// bit `j` set when lane `j` is met.
    #[inline(always)]
    pub(super) fn enter4(&self, q: &Quad, max: f64) -> ([f64; 4], u32) {
        if self.flat {
            return self.enter4_flat(q, max);
        }
        let mut t = [0.0; 4];
        let mut mask = 0;
        // Rows 0 to 3 (`& 3`: no bounds check).
        let (near_x, near_y) = (&q.c[self.near[0] & 3], &q.c[self.near[1] & 3]);
        let (far_x, far_y) = (&q.c[self.far[0] & 3], &q.c[self.far[1] & 3]);
        let (nx, ny) = (self.near_from.x, self.near_from.y);
        let (fx, fy) = (self.far_from.x, self.far_from.y);
        for j in 0..4 {
            // `f64::max` and `min` without their NaN care (a compare and a select each): a
            // lane is NaN only for a member whose pose is not finite, which no ray hits.
            let enter = larger(
                larger((near_x[j] - nx) * self.inv.x, (near_y[j] - ny) * self.inv.y),
                0.0,
            );
            let exit = smaller(
                smaller((far_x[j] - fx) * self.inv.x, (far_y[j] - fy) * self.inv.y),
                max,
            );
            t[j] = enter;
            mask |= u32::from(enter <= exit) << j;
        }
        (t, mask)
    }

    /// [`Slab::enter4`] for a segment parallel to an axis' faces.
    #[cold]
    #[inline(never)]
    fn enter4_flat(&self, q: &Quad, max: f64) -> ([f64; 4], u32) {
        let mut t = [0.0; 4];
        let mut mask = 0;
        for (j, tj) in t.iter_mut().enumerate() {
            if let Some(e) = self.enter_flat(&q.lane(j), max) {
                *tj = e;
                mask |= 1 << j;
            }
        }
        (t, mask)
    }

    /// [`Slab::enter`] for a segment parallel to an axis' faces (`inv` infinite there).
    #[cold]
    fn enter_flat(&self, b: &Bounds, max: f64) -> Option<f64> {
        let (lo, hi) = (b.min - self.pad, b.max + self.pad);
        let (mut enter, mut exit) = (0.0_f64, max);
        for axis in 0..2 {
            let (o, inv) = (self.origin[axis], self.inv[axis]);
            if inv.is_infinite() {
                // Inside the slab or never.
                if o < lo[axis] || o > hi[axis] {
                    return None;
                }
                continue;
            }
            let t1 = (lo[axis] - o) * inv;
            let t2 = (hi[axis] - o) * inv;
            let (near, far) = if t1 < t2 { (t1, t2) } else { (t2, t1) };
            enter = enter.max(near);
            exit = exit.min(far);
        }
        (enter <= exit).then_some(enter)
    }
}

/// The larger of `a` and `b` (`b` if either is NaN).
#[inline]
pub(super) fn larger(a: f64, b: f64) -> f64 {
    if a > b { a } else { b }
}

/// The smaller of `a` and `b` (`b` if either is NaN).
#[inline]
pub(super) fn smaller(a: f64, b: f64) -> f64 {
    if a < b { a } else { b }
}
