//! Numbers in messages: an error that quotes a value must stay readable whatever the value.

use std::fmt;

/// An `f64` as an error message shows it: Rust's shortest digits that read back as the same
/// number (`0.1`, `-2`, `1.5`), in scientific notation when `|x| >= 1e16` or
/// `0 < |x| < 1e-5` (`1e308`, `-5e29`, `2.5e-7`), where plain `{}` writes every digit (309
/// for 1e308); `NaN`, `inf` and `-inf` as Rust writes them. So a quoted number is at most
/// 24 characters, and reads back exactly.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Number(pub f64);

impl fmt::Display for Number {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        let a = x.abs();
        if x.is_finite() && a != 0.0 && !(1e-5..1e16).contains(&a) {
            write!(f, "{x:e}")
        } else {
            write!(f, "{x}")
        }
    }
}

/// `[x, y]` of two [`Number`]s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Numbers(pub [f64; 2]);

impl fmt::Display for Numbers {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "[{}, {}]", Number(self.0[0]), Number(self.0[1]))
    }
}

#[cfg(test)]
mod tests {
    use super::{Number, Numbers};

    /// Each form, and that every one reads back as the same number.
    #[test]
    fn numbers_are_short_and_read_back_exactly() {
        let cases = [
            (1e308, "1e308"),
            (-5e29, "-5e29"),
            (f64::MAX, "1.7976931348623157e308"),
            (1e16, "1e16"),
            (9_999_999_999_999_998.0, "9999999999999998"),
            (0.1, "0.1"),
            (-2.0, "-2"),
            (1e-5, "0.00001"),
            (2.5e-7, "2.5e-7"),
            (5e-324, "5e-324"),
            (0.0, "0"),
            (f64::NAN, "NaN"),
            (f64::NEG_INFINITY, "-inf"),
        ];
        for (x, want) in cases {
            let s = Number(x).to_string();
            assert_eq!(s, want);
            assert!(s.len() <= 24, "{s}");
            if x.is_finite() {
                assert_eq!(s.parse::<f64>().unwrap(), x, "{s}");
            }
        }
        assert_eq!(Numbers([1e300, 0.5]).to_string(), "[1e300, 0.5]");
    }
}
