//! Timesteps as exact fractions of a second, and how the frames of two runs with different
//! timesteps line up. A scenario counts time in frames (`frames`, a script event's `frame`,
//! `lifetime`, `sleep_after`), so a run at another `dt` has those counts rescaled to keep
//! their time in seconds, and two runs are compared only at the simulation times both reach.

/// The largest denominator a timestep may have: 1/1,000,000 s is finer than any game steps.
const MAX_DEN: u64 = 1_000_000;

/// A positive fraction `num / den` in lowest terms (seconds, for a timestep).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Ratio {
    /// Numerator, ≥ 1.
    pub num: u64,
    /// Denominator, ≥ 1.
    pub den: u64,
}

fn gcd(mut a: u128, mut b: u128) -> u128 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

impl Ratio {
    /// `num / den` reduced; `None` when either is 0 or it does not fit.
    #[must_use]
    pub fn new(num: u128, den: u128) -> Option<Ratio> {
        if num == 0 || den == 0 {
            return None;
        }
        let g = gcd(num, den);
        Some(Ratio {
            num: u64::try_from(num / g).ok()?,
            den: u64::try_from(den / g).ok()?,
        })
    }

    /// The simplest fraction (denominator at most 1,000,000) whose `num as f64 / den as f64`
    /// is exactly `x`: what a timestep written as `1/60`, `0.02` or `hz = 60` means. `None`
    /// when there is none (continued-fraction convergents of `x`).
    #[must_use]
    pub fn of(x: f64) -> Option<Ratio> {
        if !(x.is_finite() && x > 0.0) {
            return None;
        }
        let (mut h0, mut h1, mut k0, mut k1) = (0u64, 1u64, 1u64, 0u64);
        let mut r = x;
        for _ in 0..64 {
            let a = r.floor();
            if a >= 1e15 {
                return None;
            }
            let a = a as u64;
            let h2 = a.checked_mul(h1)?.checked_add(h0)?;
            let k2 = a.checked_mul(k1)?.checked_add(k0)?;
            if k2 > MAX_DEN {
                return None;
            }
            if h2 > 0 && h2 as f64 / k2 as f64 == x {
                return Ratio::new(u128::from(h2), u128::from(k2));
            }
            (h0, h1, k0, k1) = (h1, h2, k1, k2);
            let f = r - a as f64;
            if f <= 0.0 {
                return None;
            }
            r = 1.0 / f;
        }
        None
    }

    /// The value as a float: what the loader computes from `dt` or `hz`.
    #[must_use]
    pub fn seconds(self) -> f64 {
        self.num as f64 / self.den as f64
    }

    /// `self / other`, reduced.
    #[must_use]
    pub fn over(self, other: Ratio) -> Ratio {
        // Both numerators and denominators are below 2^64, so the products fit in u128 and
        // the reduced quotient of two timesteps with denominators ≤ 1e6 fits in u64.
        Ratio::new(
            u128::from(self.num) * u128::from(other.den),
            u128::from(self.den) * u128::from(other.num),
        )
        .unwrap_or(Ratio { num: 1, den: 1 })
    }

    /// `n · self` rounded to the nearest whole number (halves up), and whether that was
    /// exact.
    #[must_use]
    pub fn scale(self, n: u64) -> (u64, bool) {
        let p = u128::from(n) * u128::from(self.num);
        let d = u128::from(self.den);
        let rounded = (2 * p + d) / (2 * d);
        (u64::try_from(rounded).unwrap_or(u64::MAX), p % d == 0)
    }
}

impl std::fmt::Display for Ratio {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.den == 1 {
            write!(f, "{}", self.num)
        } else {
            write!(f, "{}/{}", self.num, self.den)
        }
    }
}

/// How a run's frames line up with the reference's. A run at `dt` and a reference at
/// `dt_ref` with `dt / dt_ref = a / b` (lowest terms) both reach the time `t` only at the
/// run's frames `k = b·m`, which are the reference's frames `a·m`: with `dt_ref` dividing
/// `dt` (`b = 1`), every frame of the run matches. Frame `k` holds the state at `k · dt`
/// (frame 0 is the initial state).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameMap {
    a: u64,
    b: u64,
}

impl FrameMap {
    /// The map from a run at `dt` onto a reference at `dt_ref`.
    #[must_use]
    pub fn new(dt: Ratio, dt_ref: Ratio) -> FrameMap {
        let r = dt.over(dt_ref);
        FrameMap { a: r.num, b: r.den }
    }

    /// The reference frame at the same time as the run's frame `k`, if there is one.
    #[must_use]
    pub fn reference_frame(self, k: u64) -> Option<u64> {
        k.is_multiple_of(self.b)
            .then(|| (k / self.b).checked_mul(self.a))
            .flatten()
    }

    /// Whether the reference's frame `j` is at a time the run reaches.
    #[must_use]
    pub fn is_common_reference_frame(self, j: u64) -> bool {
        j.is_multiple_of(self.a)
    }

    /// The run's frame whose step covers the reference's frame `j`: the first `k` with
    /// `k · dt ≥ j · dt_ref`, `ceil(j·b / a)`. An event the reference has at frame `j`
    /// "moves" when the run has it at any other frame.
    #[must_use]
    pub fn covering_frame(self, j: u64) -> u64 {
        let n = u128::from(j) * u128::from(self.b);
        u64::try_from(n.div_ceil(u128::from(self.a))).unwrap_or(u64::MAX)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timesteps_are_read_as_the_fractions_they_were_written_as() {
        assert_eq!(Ratio::of(1.0 / 60.0), Some(Ratio { num: 1, den: 60 }));
        assert_eq!(Ratio::of(0.02), Some(Ratio { num: 1, den: 50 }));
        assert_eq!(Ratio::of(1.0 / 960.0), Some(Ratio { num: 1, den: 960 }));
        assert_eq!(Ratio::of(0.5), Some(Ratio { num: 1, den: 2 }));
        assert_eq!(Ratio::of(3.0), Some(Ratio { num: 3, den: 1 }));
        assert_eq!(Ratio::of(0.0), None);
        assert_eq!(Ratio::of(f64::NAN), None);
        assert_eq!(Ratio::of(std::f64::consts::PI * 1e-3), None);
    }

    #[test]
    fn frames_meet_at_common_times() {
        let r = |n, d| Ratio { num: n, den: d };
        // 1/30 against 1/120: every run frame k is reference frame 4k.
        let m = FrameMap::new(r(1, 30), r(1, 120));
        assert_eq!(m.reference_frame(3), Some(12));
        assert_eq!(m.covering_frame(12), 3);
        assert_eq!(m.covering_frame(13), 4);
        // 1/50 against 1/60: they meet every 0.1 s, run frame 5 = reference frame 6.
        let m = FrameMap::new(r(1, 50), r(1, 60));
        assert_eq!(m.reference_frame(4), None);
        assert_eq!(m.reference_frame(5), Some(6));
        // Frame counts keep their time: 345 frames at 1/60 are 172.5 at 1/30, rounded up.
        assert_eq!(r(1, 2).scale(345), (173, false));
        assert_eq!(r(1, 2).scale(344), (172, true));
    }
}
