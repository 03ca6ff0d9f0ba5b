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
//!
//! Without the `parallel` feature (on by default) there is no pool and no `rayon`: every map
//! runs on the calling thread, which is what a pool of one thread does anyway, so the results
//! are the same bits. That is the build for targets without threads (wasm32), which the
//! determinism gate (`scripts/determinism-gate.sh`) checks against the threaded one.

#[cfg(feature = "parallel")]
use std::sync::Arc;

/// Below this many items a map runs on the calling thread: handing work to a pool costs a
/// few microseconds.
#[cfg(feature = "parallel")]
const MIN_PARALLEL: usize = 256;

/// A pool of worker threads besides the calling one (none with one thread in all), shared
/// by clones of a simulation.
#[derive(Clone, Debug, Default)]
pub(crate) struct Workers {
    #[cfg(feature = "parallel")]
    pool: Option<Arc<rayon::ThreadPool>>,
}

impl Workers {
    /// `threads` threads in all, the calling one included (0 counts as 1). Without a pool
    /// (one thread, or a pool the system refuses) every map runs on the calling thread.
    #[cfg(feature = "parallel")]
    pub(crate) fn new(threads: usize) -> Workers {
        let pool = (threads > 1)
            .then(|| {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(threads - 1)
                    .thread_name(|k| format!("ricochet-worker-{k}"))
                    .build()
                    .ok()
            })
            .flatten()
            .map(Arc::new);
        Workers { pool }
    }

    /// Without the `parallel` feature there are no workers: `threads` is ignored.
    #[cfg(not(feature = "parallel"))]
    pub(crate) fn new(_threads: usize) -> Workers {
        Workers {}
    }

    /// How many threads a map uses, the calling one included.
    #[cfg(feature = "parallel")]
    pub(crate) fn threads(&self) -> usize {
        self.pool
            .as_ref()
            .map_or(1, |p| p.current_num_threads() + 1)
    }

    /// How many threads a map uses: the calling one only, without the `parallel` feature.
    #[cfg(not(feature = "parallel"))]
    pub(crate) fn threads(&self) -> usize {
        1
    }

    /// How many items of a map of `n` each thread computes, as one contiguous chunk (the
    /// last may be shorter): `n` when the map runs on the calling thread alone. A caller
    /// that orders its items for speed orders them within these chunks, so that each
    /// thread's share of the work stays what it was (`stages/narrow_groups.rs`).
    #[cfg(feature = "parallel")]
    pub(crate) fn chunk(&self, n: usize) -> usize {
        match self.pool.as_ref().filter(|_| n >= MIN_PARALLEL) {
            Some(pool) => n.div_ceil(pool.current_num_threads() + 1),
            None => n,
        }
    }

    /// Every map runs on the calling thread without the `parallel` feature: one chunk.
    #[cfg(not(feature = "parallel"))]
    pub(crate) fn chunk(&self, n: usize) -> usize {
        n
    }

    /// `out` (cleared first) becomes `[f(0), f(1), ..., f(n - 1)]`, computed on the pool's
    /// threads when there are enough items: one contiguous chunk per thread
    /// ([`Workers::chunk`]), the calling thread computing the first while the workers
    /// compute the others, gathered in order.
    #[cfg(feature = "parallel")]
    pub(crate) fn map<T, F>(&self, n: usize, f: F, out: &mut Vec<T>)
    where
        T: Send,
        F: Fn(usize) -> T + Sync + Send,
    {
        out.clear();
        let chunk = self.chunk(n);
        let Some(pool) = self.pool.as_ref().filter(|_| chunk < n) else {
            out.extend((0..n).map(f));
            return;
        };
        let threads = pool.current_num_threads() + 1;
        let mut rest: Vec<Vec<T>> = (1..threads).map(|_| Vec::new()).collect();
        let f = &f;
        pool.in_place_scope(|scope| {
            for (k, part) in rest.iter_mut().enumerate() {
                let range = ((k + 1) * chunk).min(n)..((k + 2) * chunk).min(n);
                scope.spawn(move |_| part.extend(range.map(f)));
            }
            out.extend((0..chunk.min(n)).map(f));
        });
        for part in &mut rest {
            out.append(part);
        }
    }

    /// `out` (cleared first) becomes `[f(0), f(1), ..., f(n - 1)]`, on the calling thread:
    /// the build without the `parallel` feature.
    #[cfg(not(feature = "parallel"))]
    pub(crate) fn map<T, F>(&self, n: usize, f: F, out: &mut Vec<T>)
    where
        F: Fn(usize) -> T,
    {
        out.clear();
        out.extend((0..n).map(f));
    }
}
