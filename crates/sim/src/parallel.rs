//! The threads a simulation may use, and the one way its stages use them: [`Workers::map`],
//! a pure function computed for every index of a range, results gathered in index order.
//!
//! Determinism by construction: a parallel stage only computes values that are pure
//! functions of state nobody writes meanwhile, each into its own slot, and the sequential
//! code that follows reads them in the same order it would have computed them. So the
//! thread count changes the time, never a bit of state or of a log (tested with 1 and 2
//! threads on every shipped scenario, `tests/threads.rs`).
//!
//! Which stages are parallel: `detect`'s narrow phase (`stages/detect.rs`), each candidate
//! pair's exact contact at the poses the pass starts from. A pair whose body was pushed by an
//! earlier pair of the same pass is tested again, in order, where it is met, exactly as
//! with one thread.

use std::sync::Arc;

/// Below this many items a map runs on the calling thread: handing work to a pool costs a
/// few microseconds.
const MIN_PARALLEL: usize = 256;

/// A pool of worker threads (none with one thread), shared by clones of a simulation.
#[derive(Clone, Debug, Default)]
pub(crate) struct Workers {
    pool: Option<Arc<rayon::ThreadPool>>,
}

impl Workers {
    /// `threads` threads in all, the calling one included (0 counts as 1). Without a pool
    /// (one thread, or a pool the system refuses) every map runs on the calling thread.
    pub(crate) fn new(threads: usize) -> Workers {
        let pool = (threads > 1)
            .then(|| {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .thread_name(|k| format!("ricochet-worker-{k}"))
                    .build()
                    .ok()
            })
            .flatten()
            .map(Arc::new);
        Workers { pool }
    }

    /// How many threads a map uses.
    pub(crate) fn threads(&self) -> usize {
        self.pool.as_ref().map_or(1, |p| p.current_num_threads())
    }

    /// `out` (cleared first) becomes `[f(0), f(1), ..., f(n - 1)]`, computed on the pool's
    /// threads when there are enough items.
    pub(crate) fn map<T, F>(&self, n: usize, f: F, out: &mut Vec<T>)
    where
        T: Send,
        F: Fn(usize) -> T + Sync + Send,
    {
        out.clear();
        match &self.pool {
            Some(pool) if n >= MIN_PARALLEL => {
                use rayon::prelude::*;
                pool.install(|| (0..n).into_par_iter().map(f).collect_into_vec(out));
            }
            _ => out.extend((0..n).map(f)),
        }
    }
}
