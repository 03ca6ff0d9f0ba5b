//! The layer filter: which layers' bodies may pair.

/// Which layers' bodies may pair: a symmetric matrix over `u8` layer ids.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Interactions {
    n: usize,
    matrix: Vec<bool>,
}

impl Interactions {
    /// Every pair of the first `n_layers` layers interacts (at most 256).
    #[must_use]
    pub fn all(n_layers: usize) -> Interactions {
        Interactions::from_fn(n_layers, |_, _| true)
    }

    /// Layers `a` and `b` (both below `n_layers`, at most 256) interact when `f(a, b)` or
    /// `f(b, a)`. Layers from `n_layers` on interact with nothing.
    #[must_use]
    pub fn from_fn(n_layers: usize, f: impl Fn(u8, u8) -> bool) -> Interactions {
        assert!(n_layers <= 256, "layer ids are u8");
        let mut matrix = vec![false; n_layers * n_layers];
        for a in 0..n_layers {
            for b in 0..n_layers {
                // In range: both are below 256.
                let (la, lb) = (a as u8, b as u8);
                matrix[a * n_layers + b] = f(la, lb) || f(lb, la);
            }
        }
        Interactions {
            n: n_layers,
            matrix,
        }
    }

    /// Whether bodies of layers `a` and `b` may pair.
    #[must_use]
    #[inline]
    pub fn interacts(&self, a: u8, b: u8) -> bool {
        let (a, b) = (usize::from(a), usize::from(b));
        a < self.n && b < self.n && self.matrix[a * self.n + b]
    }
}
