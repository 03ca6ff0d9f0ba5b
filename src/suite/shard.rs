//! `--shard K/N`: the K-th (from 0) of N deterministic slices of the sorted list of
//! scenarios, so N machines (a Slurm job array, a Kubernetes Indexed Job) run one suite
//! between them with the same command.

use std::fmt;
use std::str::FromStr;

/// One slice of a suite: items `K, K+N, K+2N, ...` of the sorted list. Dealt round-robin
/// rather than cut in runs, so neighbouring scenarios (often alike in cost) spread over
/// the machines.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// Which slice, from 0.
    pub index: usize,
    /// How many slices.
    pub count: usize,
}

/// Why a `--shard` value is not `K/N` with `0 <= K < N`.
#[derive(Debug)]
pub struct BadShard {
    given: String,
    problem: &'static str,
}

impl fmt::Display for BadShard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "--shard {:?}: {}; expected K/N with 0 <= K < N, e.g. 0/4",
            self.given, self.problem
        )
    }
}

impl std::error::Error for BadShard {}

impl FromStr for Shard {
    type Err = BadShard;

    fn from_str(s: &str) -> Result<Shard, BadShard> {
        let bad = |problem| BadShard {
            given: s.to_owned(),
            problem,
        };
        let (k, n) = s.split_once('/').ok_or_else(|| bad("no `/`"))?;
        let index: usize = k
            .trim()
            .parse()
            .map_err(|_| bad("K is not a whole number"))?;
        let count: usize = n
            .trim()
            .parse()
            .map_err(|_| bad("N is not a whole number"))?;
        if count == 0 {
            return Err(bad("N is 0"));
        }
        if index >= count {
            return Err(bad("K is not below N (K counts from 0)"));
        }
        Ok(Shard { index, count })
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl Shard {
    /// This shard's items of a sorted list, in order.
    pub fn select<T>(self, items: Vec<T>) -> Vec<T> {
        items
            .into_iter()
            .enumerate()
            .filter(|(i, _)| i % self.count == self.index)
            .map(|(_, t)| t)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_deal_every_item_to_exactly_one_slice() {
        let items: Vec<u32> = (0..10).collect();
        let mut seen: Vec<u32> = (0..3)
            .flat_map(|k| Shard { index: k, count: 3 }.select(items.clone()))
            .collect();
        seen.sort_unstable();
        assert_eq!(seen, items);
        assert_eq!(Shard { index: 1, count: 3 }.select(items), [1, 4, 7]);
    }

    #[test]
    fn a_bad_shard_is_named() {
        for bad in ["3/3", "1", "a/2", "0/0", "-1/2"] {
            let e = bad.parse::<Shard>().unwrap_err().to_string();
            assert!(e.starts_with(&format!("--shard {bad:?}")), "{e}");
        }
        assert_eq!(
            "2/5".parse::<Shard>().unwrap(),
            Shard { index: 2, count: 5 }
        );
    }
}
