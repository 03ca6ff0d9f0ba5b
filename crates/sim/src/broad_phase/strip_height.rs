//! `Strips`' strip height `H` (`strips.rs`): the least power of two at least as tall as
//! every body, kept from call to call while it fits, and the extent of the bodies it is
//! chosen from.

use ricochet_geom::{Bounds, Vec2};

/// `1 / H` for bodies at most `height` tall with coordinates up to `max_abs`: `H` the least
/// power of two at least `height * (1 + 1e-9)` (and `max_abs / 2^30`, so strips stay well
/// inside `i32`), between `2^-1000` and `2^1000`; 0 (one strip) when there is no such `H`.
pub(super) fn inv_strip_height(height: f64, max_abs: f64) -> f64 {
    /// `2^e` for `-1022 <= e <= 1023`, exactly.
    fn pow2(e: i64) -> f64 {
        f64::from_bits(((1023 + e) as u64) << 52)
    }
    let need = (height * (1.0 + 1e-9)).max(max_abs * pow2(-30));
    if need.is_nan() || need > pow2(1000) {
        return 0.0; // NaN, infinite or too tall
    }
    let need = need.max(pow2(-1000));
    // The power of two at or below `need` (its exponent bits), doubled if below.
    let mut h = f64::from_bits(need.to_bits() & 0x7ff0_0000_0000_0000);
    if h < need {
        h *= 2.0;
    }
    1.0 / h
}

/// Whether `inv_h` should be replaced by `want` (a strip height that fits this call's
/// bodies): when it is too small for them, or more than 8 times taller than they need.
pub(super) fn restrip(inv_h: f64, want: f64) -> bool {
    inv_h.to_bits() != want.to_bits() && (inv_h > want || want > 8.0 * inv_h || inv_h == 0.0)
}

/// The tallest finite `max.y - min.y` of `bounds` (NaN and inverted boxes ignored; an
/// infinite one gives infinity), and the largest finite `|coordinate|`: [`Extent`] over them.
pub(super) fn extent<'a>(bounds: impl Iterator<Item = &'a Bounds>) -> (f64, f64) {
    let mut e = Extent::default();
    for b in bounds {
        e.add(b);
    }
    e.get()
}

/// The running maxima of [`extent`], for a caller that sees the boxes one at a time (the
/// moving bodies' entries as `World::mover_entries` makes them). Maxima, so any order
/// of the boxes gives the same; written as comparisons without branches (`maxsd`, a NaN
/// never taken), each lane of a vector one coordinate.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Extent {
    height: f64,
    lanes: Vec2,
}

impl Extent {
    /// Takes `b` in.
    #[inline]
    pub(crate) fn add(&mut self, b: &Bounds) {
        /// `|v|` per lane, 0 where it is infinite or NaN.
        #[inline]
        fn finite_abs(v: Vec2) -> Vec2 {
            let a = v.abs();
            let keep = |x: f64| if x < f64::INFINITY { x } else { 0.0 };
            Vec2::new(keep(a.x), keep(a.y))
        }
        self.height = larger(self.height, b.max.y - b.min.y);
        let (lo, hi) = (finite_abs(b.min), finite_abs(b.max));
        self.lanes = Vec2::new(
            larger(larger(self.lanes.x, lo.x), hi.x),
            larger(larger(self.lanes.y, lo.y), hi.y),
        );
    }

    /// Takes in the boxes `other` took in.
    #[inline]
    pub(crate) fn merge(&mut self, other: Extent) {
        self.height = larger(self.height, other.height);
        self.lanes = Vec2::new(
            larger(self.lanes.x, other.lanes.x),
            larger(self.lanes.y, other.lanes.y),
        );
    }

    /// The tallest height and the largest coordinate of the boxes taken in.
    pub(crate) fn get(self) -> (f64, f64) {
        (self.height, larger(self.lanes.x, self.lanes.y))
    }
}

#[inline]
fn larger(a: f64, b: f64) -> f64 {
    if b > a { b } else { a }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;
    use ricochet_geom::{Bounds, Vec2};

    use super::extent;

    /// A coordinate: ordinary, huge, tiny, signed zero, infinite or NaN.
    fn coordinate() -> impl Strategy<Value = f64> {
        prop_oneof![
            6 => -1e3..1e3f64,
            1 => -1e300..1e300f64,
            1 => prop_oneof![
                Just(0.0),
                Just(-0.0),
                Just(f64::INFINITY),
                Just(f64::NEG_INFINITY),
                Just(f64::NAN),
                Just(f64::MIN_POSITIVE),
            ],
        ]
    }

    proptest! {
        /// The tallest height and the largest finite coordinate, as a loop over each value
        /// with its own test finds them (NaN ignored, infinite heights kept, infinite
        /// coordinates left out), bit for bit.
        #[test]
        fn extent_is_the_plain_maxima(
            boxes in proptest::collection::vec(
                (coordinate(), coordinate(), coordinate(), coordinate()), 0..40)
        ) {
            let bounds: Vec<Bounds> = boxes
                .iter()
                .map(|&(a, b, c, d)| Bounds { min: Vec2::new(a, b), max: Vec2::new(c, d) })
                .collect();
            let (mut height, mut max_abs): (f64, f64) = (0.0, 0.0);
            for b in &bounds {
                let h = b.max.y - b.min.y;
                if h > height {
                    height = h;
                }
                for v in [b.min.x, b.min.y, b.max.x, b.max.y] {
                    if v.abs() > max_abs && v.abs().is_finite() {
                        max_abs = v.abs();
                    }
                }
            }
            let (h, a) = extent(bounds.iter());
            prop_assert_eq!(h.to_bits(), height.to_bits());
            prop_assert_eq!(a.to_bits(), max_abs.to_bits());
        }
    }
}
