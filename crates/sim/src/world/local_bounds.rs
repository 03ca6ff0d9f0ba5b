//! Each moving body's bounds relative to its position, kept from frame to frame
//! ([`LocalBounds`]), and their column ([`LocalBoundsColumn`]): the bounds of a body that has
//! turned are the square around the disc that holds its shape at every angle, so turning
//! never costs a rotation, and bounds good at every angle and symmetric about the body's
//! origin (that square, a centred circle or box) are also kept as their half extents, the
//! 16 bytes the broad phase's pass reads of each body every frame instead of 48.

use ricochet_geom::{Bounds, Pose, Shape, Vec2};

use super::bounds::placed;

/// A body's bounds relative to its position, kept from one frame to the next.
#[derive(Clone, Copy, Debug)]
pub(super) struct LocalBounds {
    /// The angle they were computed at.
    angle: f64,
    /// Good at every angle (a shape that turning does not change, or a body that has turned
    /// and is bounded by the disc that holds it at every angle).
    any_angle: bool,
    /// `turning_keeps_bounds` of the shape they were computed for, kept so that a snapshot
    /// asks it of 10,000 bodies without looking a shape up (it fits in the padding).
    keeps: bool,
    bounds: Bounds,
}

impl LocalBounds {
    /// Makes these the bounds of a body of `shape` at `angle`: the any-angle square once it
    /// turned (once per body: a body that turned keeps them).
    fn refresh(&mut self, shape: &Shape, angle: f64) {
        if !self.any_angle && self.angle.to_bits() != angle.to_bits() {
            *self = LocalBounds::turned(shape, angle);
        }
    }

    /// The bounds of a body of `shape` that has turned: the square around the disc that
    /// holds the shape at every angle.
    pub(super) fn turned(shape: &Shape, angle: f64) -> LocalBounds {
        // The farthest corner of the angle-0 box is as far as any point of the shape.
        let b = shape.bounds(&Pose::default());
        let r = b.min.abs().max(b.max.abs()).length();
        // A rotated point may round one ulp past the exact radius.
        let r = r + r * 1e-12;
        LocalBounds {
            angle,
            any_angle: true,
            keeps: turning_keeps_bounds(shape),
            bounds: Bounds {
                min: Vec2::splat(-r),
                max: Vec2::splat(r),
            },
        }
    }

    /// Whether the bounds of the body, at `angle`, are (or, at their next use,
    /// become) the any-angle square of [`LocalBounds::turned`]: the body turned since they
    /// were computed exactly. False for a shape that turning does not change. A snapshot
    /// keeps this bit: the broad phase's candidates, counted in `Stats`, depend on it.
    pub(super) fn has_turned(&self, angle: f64) -> bool {
        (self.any_angle || self.angle.to_bits() != angle.to_bits()) && !self.keeps
    }

    /// Bounds that [`LocalBounds::has_turned`] tells `turned` of, for `shape` at `angle`.
    pub(super) fn restored(shape: &Shape, angle: f64, turned: bool) -> LocalBounds {
        if turned {
            LocalBounds::turned(shape, angle)
        } else {
            LocalBounds::new(shape, angle)
        }
    }

    pub(super) fn new(shape: &Shape, angle: f64) -> LocalBounds {
        let keeps = turning_keeps_bounds(shape);
        LocalBounds {
            angle,
            any_angle: keeps,
            keeps,
            bounds: shape.bounds(&Pose::new(Vec2::ZERO, angle)),
        }
    }
}

/// Whether a shape's bounds are the same at every angle: circles and AABBs (which ignore
/// rotation) centred on the body origin.
fn turning_keeps_bounds(shape: &Shape) -> bool {
    !shape.primitives().iter().any(|p| p.turns_with_body())
}

/// Each row's [`LocalBounds`], with their half extents where they are symmetric and good at
/// every angle. Written only through its methods, which keep the two in step.
#[derive(Clone, Debug, Default)]
pub(super) struct LocalBoundsColumn {
    kept: Vec<LocalBounds>,
    /// [`half_extents`] of each row's bounds.
    half: Vec<Vec2>,
}

/// The half extents `h` of bounds that are `[-h, h]` exactly and good at every angle (placed
/// at a position, they need neither the angle nor the rest of [`LocalBounds`]), else NaN.
fn half_extents(b: &LocalBounds) -> Vec2 {
    let (min, max) = (b.bounds.min, b.bounds.max);
    let symmetric = (-max).x.to_bits() == min.x.to_bits()
        && (-max).y.to_bits() == min.y.to_bits()
        && max.x >= 0.0
        && max.y >= 0.0;
    if b.any_angle && symmetric {
        max
    } else {
        Vec2::splat(f64::NAN)
    }
}

impl LocalBoundsColumn {
    pub(super) fn push(&mut self, b: LocalBounds) {
        self.half.push(half_extents(&b));
        self.kept.push(b);
    }

    pub(super) fn swap_remove(&mut self, r: usize) {
        self.kept.swap_remove(r);
        self.half.swap_remove(r);
    }

    pub(super) fn len(&self) -> usize {
        self.kept.len()
    }

    /// Row `r`'s bounds.
    pub(super) fn get(&self, r: usize) -> &LocalBounds {
        &self.kept[r]
    }

    /// Gives row `r` bounds `b`.
    pub(super) fn set(&mut self, r: usize, b: LocalBounds) {
        self.half[r] = half_extents(&b);
        self.kept[r] = b;
    }

    pub(super) fn heap_bytes(&self) -> usize {
        self.kept.capacity() * size_of::<LocalBounds>() + self.half.capacity() * size_of::<Vec2>()
    }

    /// The bounds of row `r`, of `shape` at `angle`, at position `p`.
    pub(super) fn at(&mut self, r: usize, shape: &Shape, angle: f64, p: Vec2) -> Bounds {
        self.rows(r, 1).placed(0, || shape, || angle, p)
    }

    /// The `len` rows from `r`, indexed from 0.
    #[inline(always)]
    pub(super) fn rows(&mut self, r: usize, len: usize) -> LocalBoundsRows<'_> {
        LocalBoundsRows {
            kept: &mut self.kept[r..][..len],
            half: &mut self.half[r..][..len],
        }
    }
}

/// Some rows of a [`LocalBoundsColumn`].
pub(super) struct LocalBoundsRows<'a> {
    kept: &'a mut [LocalBounds],
    half: &'a mut [Vec2],
}

impl LocalBoundsRows<'_> {
    /// Row `r`'s bounds placed at `p` ([`placed`]), for a body of `shape` at `angle` (each
    /// asked only when the bounds must be recomputed): from the half extents when it has
    /// some, else from all it keeps ([`refresh`]).
    #[inline(always)]
    pub(super) fn placed<'s>(
        &mut self,
        r: usize,
        shape: impl FnOnce() -> &'s Shape,
        angle: impl FnOnce() -> f64,
        p: Vec2,
    ) -> Bounds {
        let h = self.half[r];
        // Not NaN: the same bounds as `kept[r]`'s, bit for bit.
        if !h.x.is_nan() {
            return placed_half(h, p);
        }
        let (kept, half) = (&mut self.kept[r], &mut self.half[r]);
        // The shape is looked up only for a body that has not turned yet.
        if !kept.any_angle {
            refresh(kept, half, shape(), angle());
        }
        placed(kept.bounds, p)
    }

    /// The `len` rows from `r` of these, indexed from 0.
    #[inline(always)]
    pub(super) fn rows(&mut self, r: usize, len: usize) -> LocalBoundsRows<'_> {
        LocalBoundsRows {
            kept: &mut self.kept[r..][..len],
            half: &mut self.half[r..][..len],
        }
    }
}

/// [`placed`] of the bounds `[-h, h]`, bit for bit, in fewer steps: `-h + p` is `p - h`,
/// and the larger of `|-h|` and `|h|` is `|h|`.
#[inline(always)]
fn placed_half(h: Vec2, p: Vec2) -> Bounds {
    let pad = (p.abs() + h.abs()) * 1e-15;
    Bounds {
        min: p - h - pad,
        max: h + p + pad,
    }
}

/// [`LocalBounds::refresh`] of bounds without half extents (a body that has not turned,
/// or a shape off its origin), which then get theirs if they become the any-angle square.
/// Out of line, given no column: a loop that calls it keeps its own columns in registers.
#[cold]
#[inline(never)]
fn refresh(kept: &mut LocalBounds, half: &mut Vec2, shape: &Shape, angle: f64) {
    kept.refresh(shape, angle);
    *half = half_extents(kept);
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;
    use ricochet_geom::{Bounds, Vec2};

    use super::{placed, placed_half};

    /// Any `f64`, with the signed zeros, infinities and NaN the arithmetic treats apart.
    fn float() -> impl Strategy<Value = f64> {
        prop_oneof![
            any::<f64>(),
            Just(0.0),
            Just(-0.0),
            Just(f64::INFINITY),
            Just(f64::NAN),
            -1e3..1e3f64,
        ]
    }

    proptest! {
        #[test]
        fn placing_half_extents_is_placing_their_bounds(
            hx in float(), hy in float(), px in float(), py in float(),
        ) {
            let (h, p) = (Vec2::new(hx.abs(), hy.abs()), Vec2::new(px, py));
            let bits = |b: Bounds| [b.min.x, b.min.y, b.max.x, b.max.y].map(f64::to_bits);
            let exact = placed(Bounds { min: -h, max: h }, p);
            prop_assert_eq!(bits(placed_half(h, p)), bits(exact));
        }
    }
}
