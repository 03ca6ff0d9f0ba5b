//! Broad phases: which pairs of bodies have overlapping bounds and are worth a narrow-phase
//! test.
//!
//! Given each body's [`Bounds`], layer and [`BodyKind`], a [`BroadPhase`] writes the candidate
//! pairs `(i, j)`, `i < j`, as dense indices (the order of the bodies, which is key order),
//! sorted and without duplicates: exactly the pairs whose bounds overlap (touching counts, as
//! [`Bounds::overlaps`]) and that pass two filters applied *inside* the broad phase, so the
//! pairs are never produced:
//! - **at least one body is dynamic**: static and kinematic bodies never pair with each other;
//! - **their layers interact** ([`Interactions`]). A layer that does not interact with itself
//!   is never swept against itself: its bodies are only ever tested against the layers it
//!   interacts with (10,000 asteroids that ignore each other cost no asteroid–asteroid test).
//!
//! # Algorithms ([`BroadPhaseKind`])
//! All three produce the same pairs; they differ only in speed.
//! - `BruteForce`: every pair, `O(n²)`. The reference, and the fastest below a few dozen
//!   bodies.
//! - `SortAndSweep`: per layer, the moving bodies sorted by `min.x`, kept from the previous
//!   call and re-sorted by insertion sort (nearly sorted: about `O(n)`; bodies that appeared
//!   are sorted apart and merged in, and a sort that moves more than `8n` places falls back
//!   to a full sort). A self-interacting layer is swept against itself. Two interacting
//!   layers never look at pairs within one layer: each body of the smaller layer finds its
//!   candidates in the larger one's order by binary search (`[min.x - widest, max.x]`), or,
//!   when that would visit more than the larger layer holds, the two orders are swept
//!   together. Static bodies go into a packed tree per layer (sort-tile-recursive: sorted
//!   once by x into slices, each slice by y, leaves of 8, a binary tree of boxes above),
//!   which each dynamic body queries in `O(log n + k)`.
//! - `Grid`: a uniform grid per layer: `(cell, body)` entries counting-sorted into a table
//!   that is dense (one bucket per cell of the occupied rectangle, row by row) when that
//!   rectangle has at most four cells per entry, as in a tile map, and otherwise hashed by
//!   a fixed multiplicative hash of the cell (no `HashMap`: the layout depends only on the
//!   input, and every lookup checks the cell itself). The cell is twice the median of the
//!   layer's body extents (`max(width, height)`), widened if needed so cell coordinates stay
//!   within `±2^30` (bodies at 1e6 with 1e-7 extents), and clamped to `i32` besides, which
//!   is monotone and so still correct. A body covering more than 16 cells, or with inverted
//!   or NaN bounds, is kept in a per-layer list tested against everything instead, and a
//!   query covering more cells than the grid has bodies tests them all. A pair seen in
//!   several cells is reported only in the cell holding the lower-left corner of the two
//!   boxes' intersection, so nothing needs deduplicating. Two interacting layers: the grid
//!   of the larger is queried with the bodies of the smaller. Static bodies have their own
//!   grid per layer, with its own cell size, their entries ordered by cell so that a cell's
//!   bodies are neighbours in memory.
//!
//! **Static bodies are inserted once.** The structures above for static bodies are built
//! when the static set changes, never per call; per call, only moving (dynamic and
//! kinematic) bodies are re-sorted or re-hashed, and only dynamic ones query the static
//! structures, so the per-call cost follows the moving bodies. [`BroadPhase::pairs`] takes
//! every body and notices a change by comparing the static bodies with the stored ones (a
//! linear scan, no rebuild); [`BroadPhase::pairs_split`] takes the static bodies apart with a
//! generation number the caller bumps when they change, and does not look at them otherwise:
//! with a million static tiles it costs what the moving bodies cost.
//!
//! # `Auto`
//! Decided on every call from two counts only (deterministic, no timing):
//! - at most 32 bodies in all: `BruteForce` (at most 496 tests, no structure to keep);
//! - at least as many static as moving bodies: `Grid` (tile maps: a static cell lookup is
//!   `O(1)` where the static tree is `O(log n)`, and the static grid is built once);
//! - otherwise `SortAndSweep` (moving crowds: the coherent sort costs about one pass over the
//!   moving bodies, and unlike a grid it does not care how much body sizes vary).
//!
//! Each kind keeps its own structures, so a switch costs one build and nothing else.
//!
//! # Determinism
//! Sorting uses `f64::total_cmp` with the body's key as the tie-break, so every order is a
//! function of the current input; the output is sorted. No hashed collection, no clock.

use std::cmp::Ordering;

use ricochet_geom::{Bounds, Vec2};

use crate::def::BodyKind;

/// Which algorithm finds the pairs. All of them find the same pairs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BroadPhaseKind {
    /// Every pair is tested: `O(n²)`.
    BruteForce,
    /// Sort and sweep along x, re-sorting the previous call's order.
    SortAndSweep,
    /// A uniform grid, hashed deterministically.
    Grid,
    /// Chosen per call from the number of moving and static bodies (see the module docs).
    #[default]
    Auto,
}

impl BroadPhaseKind {
    /// The name scenario files and `/stats` use: `brute-force`, `sort-and-sweep`, `grid`,
    /// `auto`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            BroadPhaseKind::BruteForce => "brute-force",
            BroadPhaseKind::SortAndSweep => "sort-and-sweep",
            BroadPhaseKind::Grid => "grid",
            BroadPhaseKind::Auto => "auto",
        }
    }
}

/// One body, as the broad phase sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyEntry {
    /// A stable id (e.g. the entity): strictly increasing along the slice, as dense order is
    /// id order. It is how the broad phase recognises a body from one call to the next.
    pub key: u64,
    /// The body's bounds (with `min <= max`; other bounds are handled, but slowly).
    pub bounds: Bounds,
    /// The body's layer, for [`Interactions`].
    pub layer: u8,
    /// Static bodies are indexed once; static and kinematic bodies never pair with each
    /// other.
    pub kind: BodyKind,
}

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

/// What one call did. Every counter is a function of the input (and, for `static_rebuilds`,
/// of the calls before), never of time.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BroadPhaseStats {
    /// The algorithm that ran (what `Auto` chose).
    pub kind: BroadPhaseKind,
    /// Pairs produced.
    pub pairs: u64,
    /// Body–body bounds tests made (candidates the structure could not rule out).
    pub tested: u64,
    /// Moving (dynamic or kinematic) bodies.
    pub movers: u64,
    /// Static bodies.
    pub statics: u64,
    /// How many times a static structure was built since the [`BroadPhase`] was made: stays
    /// put while the static bodies do.
    pub static_rebuilds: u64,
    /// Layer combinations present in the scene (moving–moving, including a layer with
    /// itself, and moving–static) that were never looked at because they do not interact.
    pub layer_pairs_skipped: u64,
    /// `SortAndSweep`: how many places bodies moved in the re-sort.
    pub resorted: u64,
}

/// The broad phase, keeping its structures (and buffers) from one call to the next.
#[derive(Debug)]
pub struct BroadPhase {
    kind: BroadPhaseKind,
    chosen: BroadPhaseKind,
    /// Calls made, to know which per-layer structures are current.
    frame: u64,
    statics: StaticSet,
    static_rebuilds: u64,
    /// Moving bodies (indices into the caller's slice) grouped by layer, key order within.
    movers: Vec<u32>,
    /// `movers[layer_start[l]..layer_start[l + 1]]` are layer `l`'s.
    layer_start: Vec<u32>,
    /// Dynamic bodies per layer.
    dynamic: Vec<u32>,
    mover_layers: Vec<u8>,
    /// This call's runs of moving bodies: `(first index, count, layer)`; more than
    /// [`MAX_RUNS`] means too many to use.
    runs: Vec<(u32, u32, u8)>,
    sweeps: Vec<SweepList>,
    grids: Vec<HashGrid>,
    scratch: Scratch,
}

/// Buffers reused across calls.
#[derive(Debug, Default)]
struct Scratch {
    remap: Vec<u32>,
    fresh: Vec<Slot>,
    merged: Vec<Slot>,
    extents: Vec<f64>,
    stack: Vec<(u32, u32)>,
    ranges: Vec<(u32, u32)>,
    all: Vec<(Member, u8)>,
}

/// A body inside a structure: its bounds, its handle (an index into the caller's slice for a
/// moving body, or a static index with [`STATIC_BIT`]), and whether it is dynamic.
#[derive(Clone, Copy, Debug)]
struct Member {
    bounds: Bounds,
    handle: u32,
    dynamic: bool,
}

const STATIC_BIT: u32 = 1 << 31;
const NONE: u32 = u32::MAX;
const LAYERS: usize = 256;

impl BroadPhase {
    /// A broad phase using `kind`.
    #[must_use]
    pub fn new(kind: BroadPhaseKind) -> BroadPhase {
        BroadPhase {
            kind,
            chosen: kind,
            frame: 0,
            statics: StaticSet::default(),
            static_rebuilds: 0,
            movers: Vec::new(),
            layer_start: vec![0; LAYERS + 1],
            dynamic: vec![0; LAYERS],
            mover_layers: Vec::new(),
            runs: Vec::new(),
            sweeps: (0..LAYERS).map(|_| SweepList::default()).collect(),
            grids: (0..LAYERS).map(|_| HashGrid::default()).collect(),
            scratch: Scratch::default(),
        }
    }

    /// The algorithm the last call ran (what `Auto` picked); before any call, the one asked
    /// for.
    #[must_use]
    pub fn chosen(&self) -> BroadPhaseKind {
        self.chosen
    }

    /// Writes into `out` (cleared first) the candidate pairs among `bodies` (keys strictly
    /// increasing): dense indices `(i, j)`, `i < j`, sorted.
    ///
    /// The static bodies are compared with the previous call's (a linear scan); the static
    /// structures are rebuilt only when they differ.
    ///
    /// # Panics
    /// With `2^31` bodies or more.
    pub fn pairs(
        &mut self,
        bodies: &[BodyEntry],
        interactions: &Interactions,
        out: &mut Vec<(u32, u32)>,
    ) -> BroadPhaseStats {
        assert!(bodies.len() < STATIC_BIT as usize, "fewer than 2^31 bodies");
        debug_assert!(
            bodies.windows(2).all(|w| w[0].key < w[1].key),
            "keys increase"
        );
        // One pass: compare the static bodies with the stored ones, count the moving ones.
        let st = &mut self.statics;
        let mut same = st.generation.is_none() && st.loaded;
        st.dense.clear();
        let mut tally = Tally::new(&mut self.layer_start, &mut self.dynamic, &mut self.runs);
        let mut s = 0;
        for (i, b) in bodies.iter().enumerate() {
            if b.kind == BodyKind::Static {
                same = same && st.same(s, b);
                s += 1;
                st.dense.push(i as u32);
            } else {
                tally.add(b, i as u32);
            }
        }
        tally.flush();
        if !(same && s == st.keys.len()) {
            st.load(bodies.iter().filter(|b| b.kind == BodyKind::Static), None);
        }
        self.group_movers(bodies, |b| b.kind != BodyKind::Static);
        self.run(bodies, true, interactions, out)
    }

    /// Like [`BroadPhase::pairs`], with the static bodies apart: `statics` is read only when
    /// `static_generation` differs from the previous call's (or on the first call), so the
    /// caller bumps it whenever a static body is added, removed or changed. `movers` are the
    /// dynamic and kinematic bodies. Keys are strictly increasing in each slice and unique
    /// across both; dense indices are positions in the key order of both together.
    ///
    /// # Panics
    /// With `2^31` bodies or more.
    pub fn pairs_split(
        &mut self,
        statics: &[BodyEntry],
        static_generation: u64,
        movers: &[BodyEntry],
        interactions: &Interactions,
        out: &mut Vec<(u32, u32)>,
    ) -> BroadPhaseStats {
        debug_assert!(
            movers.windows(2).all(|w| w[0].key < w[1].key),
            "keys increase"
        );
        if self.statics.generation != Some(static_generation) || !self.statics.loaded {
            debug_assert!(
                statics.windows(2).all(|w| w[0].key < w[1].key),
                "keys increase"
            );
            self.statics.load(statics.iter(), Some(static_generation));
        }
        assert!(
            self.statics.keys.len() + movers.len() < STATIC_BIT as usize,
            "fewer than 2^31 bodies"
        );
        let mut tally = Tally::new(&mut self.layer_start, &mut self.dynamic, &mut self.runs);
        for (i, b) in movers.iter().enumerate() {
            tally.add(b, i as u32);
        }
        tally.flush();
        self.group_movers(movers, |_| true);
        self.run(movers, false, interactions, out)
    }

    /// Groups the moving bodies by layer (a counting sort, so key order is kept within),
    /// once `layer_start[l + 1]` holds layer `l`'s count.
    fn group_movers(&mut self, bodies: &[BodyEntry], moving: impl Fn(&BodyEntry) -> bool) {
        let counts = &mut self.layer_start;
        self.mover_layers.clear();
        for l in 0..LAYERS {
            if counts[l + 1] > 0 {
                self.mover_layers.push(l as u8);
            }
            counts[l + 1] += counts[l];
        }
        self.movers.clear();
        self.movers.resize(counts[LAYERS] as usize, 0);
        let mut next: [u32; LAYERS] = [0; LAYERS];
        next.copy_from_slice(&counts[..LAYERS]);
        if self.runs.len() <= MAX_RUNS {
            // Bodies of a layer usually come in a few runs of consecutive indices.
            for &(start, len, layer) in &self.runs {
                let at = &mut next[usize::from(layer)];
                let dst = &mut self.movers[*at as usize..(*at + len) as usize];
                for (d, i) in dst.iter_mut().zip(start..) {
                    *d = i;
                }
                *at += len;
            }
            return;
        }
        // Too many runs: scatter body by body, the current layer's cursor in a register.
        let (mut layer, mut at) = (0, next[0]);
        for (i, b) in bodies.iter().enumerate() {
            if !moving(b) {
                continue;
            }
            let l = usize::from(b.layer);
            if l != layer {
                next[layer] = at;
                layer = l;
                at = next[l];
            }
            self.movers[at as usize] = i as u32;
            at += 1;
        }
    }

    fn layer_movers(&self, layer: u8) -> &[u32] {
        let l = usize::from(layer);
        &self.movers[self.layer_start[l] as usize..self.layer_start[l + 1] as usize]
    }

    fn run(
        &mut self,
        bodies: &[BodyEntry],
        all_given: bool,
        interactions: &Interactions,
        out: &mut Vec<(u32, u32)>,
    ) -> BroadPhaseStats {
        self.frame += 1;
        out.clear();
        let n_movers = self.movers.len();
        let n_statics = self.statics.keys.len();
        let kind = match self.kind {
            BroadPhaseKind::Auto if n_movers + n_statics <= 32 => BroadPhaseKind::BruteForce,
            BroadPhaseKind::Auto if n_statics >= n_movers => BroadPhaseKind::Grid,
            BroadPhaseKind::Auto => BroadPhaseKind::SortAndSweep,
            k => k,
        };
        self.chosen = kind;
        let mut stats = BroadPhaseStats {
            kind,
            movers: n_movers as u64,
            statics: n_statics as u64,
            ..BroadPhaseStats::default()
        };
        if kind == BroadPhaseKind::BruteForce {
            self.brute_force(bodies, interactions, out, &mut stats);
        } else {
            self.by_layers(kind, bodies, interactions, out, &mut stats);
        }
        self.resolve(bodies, all_given, out);
        stats.pairs = out.len() as u64;
        stats.static_rebuilds = self.static_rebuilds;
        stats
    }

    /// Every pair, filters first.
    fn brute_force(
        &mut self,
        bodies: &[BodyEntry],
        interactions: &Interactions,
        out: &mut Vec<(u32, u32)>,
        stats: &mut BroadPhaseStats,
    ) {
        let all = &mut self.scratch.all;
        all.clear();
        all.extend(self.movers.iter().map(|&h| {
            let b = &bodies[h as usize];
            (member(b, h), b.layer)
        }));
        let st = &self.statics;
        all.extend(st.entries.iter().enumerate().map(|(s, &(bounds, layer))| {
            let m = Member {
                bounds,
                handle: s as u32 | STATIC_BIT,
                dynamic: false,
            };
            (m, layer)
        }));
        // The same count `by_layers` keeps: layer combinations present that never interact.
        for (k, &a) in self.mover_layers.iter().enumerate() {
            let with_statics = if self.dynamic[usize::from(a)] > 0 {
                &self.statics.layers[..]
            } else {
                &[]
            };
            for &b in self.mover_layers[k..].iter().chain(with_statics) {
                if !interactions.interacts(a, b) {
                    stats.layer_pairs_skipped += 1;
                }
            }
        }
        for (k, (a, la)) in all.iter().enumerate() {
            for (b, lb) in &all[k + 1..] {
                if (a.dynamic || b.dynamic) && interactions.interacts(*la, *lb) {
                    stats.tested += 1;
                    if a.bounds.overlaps(&b.bounds) {
                        out.push((a.handle, b.handle));
                    }
                }
            }
        }
    }

    /// Per pair of interacting layers: moving–moving through the per-call structures,
    /// dynamic–static through the static ones.
    fn by_layers(
        &mut self,
        kind: BroadPhaseKind,
        bodies: &[BodyEntry],
        interactions: &Interactions,
        out: &mut Vec<(u32, u32)>,
        stats: &mut BroadPhaseStats,
    ) {
        let built = match kind {
            BroadPhaseKind::SortAndSweep => &mut self.statics.built_trees,
            _ => &mut self.statics.built_grids,
        };
        if !*built {
            *built = true;
            self.statics.build(kind, &mut self.scratch);
            self.static_rebuilds += 1;
        }
        let layers = std::mem::take(&mut self.mover_layers);
        for (k, &a) in layers.iter().enumerate() {
            for &b in &layers[k..] {
                if !interactions.interacts(a, b) {
                    stats.layer_pairs_skipped += 1;
                    continue;
                }
                let (da, db) = (self.dynamic[usize::from(a)], self.dynamic[usize::from(b)]);
                if da == 0 && db == 0 {
                    continue;
                }
                if kind == BroadPhaseKind::SortAndSweep {
                    stats.resorted += self.ensure_sweep(a, bodies);
                    stats.resorted += self.ensure_sweep(b, bodies);
                    let mut ranges = std::mem::take(&mut self.scratch.ranges);
                    let view = |l: u8| SweepView {
                        list: &self.sweeps[usize::from(l)],
                        handles: self.layer_movers(l),
                        bodies,
                    };
                    if a == b {
                        stats.tested += sweep_self(view(a), out);
                    } else {
                        stats.tested += sweep_cross(view(a), view(b), &mut ranges, out);
                    }
                    self.scratch.ranges = ranges;
                } else if a == b {
                    self.ensure_grid(a, bodies);
                    stats.tested += self.grids[usize::from(a)].self_pairs(out);
                } else {
                    // Query the larger layer's grid with the smaller's bodies.
                    let (na, nb) = (self.layer_movers(a).len(), self.layer_movers(b).len());
                    let (grid, query) = if na > nb { (a, b) } else { (b, a) };
                    self.ensure_grid(grid, bodies);
                    let g = &self.grids[usize::from(grid)];
                    for &h in self.layer_movers(query) {
                        let q = member(&bodies[h as usize], h);
                        stats.tested += g.query(&q.bounds, |m| {
                            if q.dynamic || m.dynamic {
                                out.push((q.handle, m.handle));
                            }
                        });
                    }
                }
            }
            if self.dynamic[usize::from(a)] == 0 {
                continue;
            }
            for &b in &self.statics.layers {
                if !interactions.interacts(a, b) {
                    stats.layer_pairs_skipped += 1;
                    continue;
                }
                let l = usize::from(a);
                for k in self.layer_start[l] as usize..self.layer_start[l + 1] as usize {
                    let h = self.movers[k];
                    let q = &bodies[h as usize];
                    if q.kind != BodyKind::Dynamic {
                        continue;
                    }
                    let mut emit = |m: &Member| out.push((h, m.handle));
                    stats.tested += if kind == BroadPhaseKind::SortAndSweep {
                        let tree = &self.statics.trees[usize::from(b)];
                        tree.query(&q.bounds, &mut self.scratch.stack, &mut emit)
                    } else {
                        self.statics.grids[usize::from(b)].query(&q.bounds, &mut emit)
                    };
                }
            }
        }
        self.mover_layers = layers;
    }

    /// Brings layer `l`'s sorted list up to this call, once per call. Returns the re-sort's
    /// moves.
    fn ensure_sweep(&mut self, l: u8, bodies: &[BodyEntry]) -> u64 {
        let list = &mut self.sweeps[usize::from(l)];
        if list.frame == self.frame {
            return 0;
        }
        list.frame = self.frame;
        let (lo, hi) = (
            self.layer_start[usize::from(l)] as usize,
            self.layer_start[usize::from(l) + 1] as usize,
        );
        list.update(&self.movers[lo..hi], bodies, &mut self.scratch)
    }

    /// Builds layer `l`'s grid of moving bodies, once per call.
    fn ensure_grid(&mut self, l: u8, bodies: &[BodyEntry]) {
        let (lo, hi) = (
            self.layer_start[usize::from(l)] as usize,
            self.layer_start[usize::from(l) + 1] as usize,
        );
        let grid = &mut self.grids[usize::from(l)];
        if grid.frame == self.frame {
            return;
        }
        grid.frame = self.frame;
        grid.members.clear();
        grid.members.extend(
            self.movers[lo..hi]
                .iter()
                .map(|&h| member(&bodies[h as usize], h)),
        );
        grid.build(&mut self.scratch.extents, false);
    }

    /// Turns handles into dense indices, orders each pair and sorts them.
    fn resolve(&self, bodies: &[BodyEntry], all_given: bool, out: &mut [(u32, u32)]) {
        let st = &self.statics;
        let dense = |h: u32| -> u32 {
            match (h & STATIC_BIT != 0, all_given) {
                (false, true) => h,
                (true, true) => st.dense[(h & !STATIC_BIT) as usize],
                // Ranks in the other slice; the first two checks spare a binary search (and
                // its cache misses) when every static body comes before every moving one.
                (false, false) => {
                    let key = bodies[h as usize].key;
                    let rank = match st.keys.last() {
                        Some(&last) if last > key => st.keys.partition_point(|&k| k < key),
                        _ => st.keys.len(),
                    };
                    h + rank as u32
                }
                (true, false) => {
                    let s = h & !STATIC_BIT;
                    let key = st.keys[s as usize];
                    let rank = match bodies.first() {
                        Some(first) if first.key < key => bodies.partition_point(|b| b.key < key),
                        _ => 0,
                    };
                    s + rank as u32
                }
            }
        };
        for p in out.iter_mut() {
            let (i, j) = (dense(p.0), dense(p.1));
            *p = (i.min(j), i.max(j));
        }
        // One integer comparison per step.
        out.sort_unstable_by_key(|&(i, j)| (u64::from(i) << 32) | u64::from(j));
        debug_assert!(out.windows(2).all(|w| w[0] < w[1]), "each pair once");
    }
}

/// Counts moving bodies per layer (into `counts[layer + 1]`) and dynamic ones (into
/// `dynamic[layer]`), a run of one layer in registers, and notes the runs of consecutive
/// indices (up to [`MAX_RUNS`], and one more to say there were more).
struct Tally<'a> {
    counts: &'a mut [u32],
    dynamic: &'a mut [u32],
    runs: &'a mut Vec<(u32, u32, u8)>,
    layer: usize,
    start: u32,
    n: u32,
    d: u32,
}

const MAX_RUNS: usize = 64;

impl<'a> Tally<'a> {
    fn new(
        counts: &'a mut [u32],
        dynamic: &'a mut [u32],
        runs: &'a mut Vec<(u32, u32, u8)>,
    ) -> Tally<'a> {
        counts.fill(0);
        dynamic.fill(0);
        runs.clear();
        Tally {
            counts,
            dynamic,
            runs,
            layer: 0,
            start: 0,
            n: 0,
            d: 0,
        }
    }

    #[inline]
    fn add(&mut self, b: &BodyEntry, i: u32) {
        let l = usize::from(b.layer);
        if l != self.layer || i != self.start + self.n {
            self.flush();
            (self.layer, self.start) = (l, i);
        }
        self.n += 1;
        self.d += u32::from(b.kind == BodyKind::Dynamic);
    }

    fn flush(&mut self) {
        if self.n == 0 {
            return;
        }
        self.counts[self.layer + 1] += self.n;
        self.dynamic[self.layer] += self.d;
        if self.runs.len() <= MAX_RUNS {
            self.runs.push((self.start, self.n, self.layer as u8));
        }
        (self.n, self.d) = (0, 0);
    }
}

fn member(b: &BodyEntry, handle: u32) -> Member {
    Member {
        bounds: b.bounds,
        handle,
        dynamic: b.kind == BodyKind::Dynamic,
    }
}

/// The static bodies, sorted by key, and their structures.
#[derive(Debug, Default)]
struct StaticSet {
    loaded: bool,
    /// The caller's generation (`pairs_split`), or `None` when loaded by content (`pairs`).
    generation: Option<u64>,
    keys: Vec<u64>,
    entries: Vec<(Bounds, u8)>,
    /// `pairs`: this call's dense index of each static body.
    dense: Vec<u32>,
    /// Layers with static bodies, ascending.
    layers: Vec<u8>,
    /// Whether `trees` (`SortAndSweep`) and `grids` (`Grid`) hold the current set.
    built_trees: bool,
    built_grids: bool,
    trees: Vec<StaticTree>,
    grids: Vec<HashGrid>,
}

impl StaticSet {
    fn same(&self, s: usize, b: &BodyEntry) -> bool {
        self.keys.get(s).is_some_and(|&k| k == b.key) && {
            let (bounds, layer) = &self.entries[s];
            let bits = |b: &Bounds| [b.min.x, b.min.y, b.max.x, b.max.y].map(f64::to_bits);
            *layer == b.layer && bits(bounds) == bits(&b.bounds)
        }
    }

    fn load<'a>(&mut self, statics: impl Iterator<Item = &'a BodyEntry>, generation: Option<u64>) {
        self.loaded = true;
        self.generation = generation;
        self.keys.clear();
        self.entries.clear();
        for b in statics {
            self.keys.push(b.key);
            self.entries.push((b.bounds, b.layer));
        }
        let mut present = [false; LAYERS];
        for (_, l) in &self.entries {
            present[usize::from(*l)] = true;
        }
        self.layers = (0..LAYERS)
            .filter(|&l| present[l])
            .map(|l| l as u8)
            .collect();
        self.built_trees = false;
        self.built_grids = false;
        // Free the old structures now: a million tiles' worth should not linger.
        self.trees = Vec::new();
        self.grids = Vec::new();
    }

    fn build(&mut self, kind: BroadPhaseKind, scratch: &mut Scratch) {
        let mut by_layer: Vec<Vec<Member>> = (0..LAYERS).map(|_| Vec::new()).collect();
        for (s, &(bounds, layer)) in self.entries.iter().enumerate() {
            by_layer[usize::from(layer)].push(Member {
                bounds,
                handle: s as u32 | STATIC_BIT,
                dynamic: false,
            });
        }
        if kind == BroadPhaseKind::SortAndSweep {
            self.trees = by_layer.into_iter().map(StaticTree::new).collect();
        } else {
            self.grids = by_layer
                .into_iter()
                .map(|members| {
                    let mut g = HashGrid {
                        members,
                        ..HashGrid::default()
                    };
                    g.build(&mut scratch.extents, true);
                    g
                })
                .collect();
        }
    }
}

/// `SortAndSweep`: one layer's moving bodies, kept across calls.
#[derive(Debug, Default)]
struct SweepList {
    frame: u64,
    /// The bodies, sorted by `(min.x, local)`: small, so the re-sort moves little.
    order: Vec<Slot>,
    /// The keys of the layer's bodies at the last update, in key order (`local` indexes it,
    /// as it does the layer's handles).
    keys: Vec<u64>,
    /// `order[pos[local]].local == local`, so an update reads the caller's bodies in order.
    pos: Vec<u32>,
    /// The widest body's `max.x - min.x` (at least 0; NaN ignored).
    width: f64,
}

/// A body's place in a [`SweepList`]'s order.
#[derive(Clone, Copy, Debug)]
struct Slot {
    /// `min.x` as [`order_key`].
    min: u64,
    /// `max.x` as [`order_key`] of `max.x + 0.0`: `min <= max` exactly when `min.x <= max.x`
    /// (besides NaN, which overlaps nothing anyway).
    max: u64,
    local: u32,
}

impl Slot {
    #[inline]
    fn new(b: &Bounds, local: u32) -> Slot {
        Slot {
            min: order_key(b.min.x),
            max: order_key(b.max.x + 0.0),
            local,
        }
    }
}

/// `f64::total_cmp` as an integer: `order_key(a) < order_key(b)` exactly when `a` comes
/// first. `-0.0` comes before `+0.0`, so a query bound is normalised with `+ 0.0` first.
#[inline]
fn order_key(x: f64) -> u64 {
    let bits = x.to_bits();
    bits ^ (((bits as i64 >> 63) as u64) | (1 << 63))
}

/// The key order as tie-break, so the order is a function of the input, never of the calls
/// before.
#[inline]
fn sweep_order(a: &Slot, b: &Slot) -> Ordering {
    a.min.cmp(&b.min).then(a.local.cmp(&b.local))
}

/// A [`SweepList`] with this call's bodies of its layer.
#[derive(Clone, Copy)]
struct SweepView<'a> {
    list: &'a SweepList,
    handles: &'a [u32],
    bodies: &'a [BodyEntry],
}

impl SweepView<'_> {
    #[inline]
    fn member(&self, local: u32) -> Member {
        let h = self.handles[local as usize];
        member(&self.bodies[h as usize], h)
    }
}

impl SweepList {
    /// Reconciles the list with this call's bodies of the layer (`handles`, key order):
    /// bodies gone are dropped, bodies kept get their new bounds, new bodies are sorted and
    /// merged in. Returns the insertion sort's moves.
    fn update(&mut self, handles: &[u32], bodies: &[BodyEntry], scratch: &mut Scratch) -> u64 {
        // The usual case: the same bodies as last time. One pass in the caller's order.
        if self.keys.len() == handles.len() {
            let mut width: f64 = 0.0;
            let mut same = true;
            for (local, &h) in handles.iter().enumerate() {
                let b = &bodies[h as usize];
                if b.key != self.keys[local] {
                    same = false;
                    break;
                }
                self.order[self.pos[local] as usize] = Slot::new(&b.bounds, local as u32);
                // A branch, not `f64::max`: rarely taken, and no dependency chain.
                let w = b.bounds.max.x - b.bounds.min.x;
                if w > width {
                    width = w;
                }
            }
            if same {
                self.width = width;
                return insertion_sort(&mut self.order, &mut self.pos);
            }
        }
        // Merge the old keys with the new ones (both ascending).
        let (remap, fresh) = (&mut scratch.remap, &mut scratch.fresh);
        remap.clear();
        remap.resize(self.keys.len(), NONE);
        fresh.clear();
        let mut i = 0;
        for (j, &h) in handles.iter().enumerate() {
            let b = &bodies[h as usize];
            while i < self.keys.len() && self.keys[i] < b.key {
                i += 1;
            }
            if i < self.keys.len() && self.keys[i] == b.key {
                remap[i] = j as u32;
                i += 1;
            } else {
                fresh.push(Slot::new(&b.bounds, j as u32));
            }
        }
        self.keys.clear();
        self.keys
            .extend(handles.iter().map(|&h| bodies[h as usize].key));
        self.order.retain_mut(|s| {
            let j = remap[s.local as usize];
            if j != NONE {
                *s = Slot::new(&bodies[handles[j as usize] as usize].bounds, j);
            }
            j != NONE
        });
        self.pos.resize(handles.len(), 0);
        let moved = insertion_sort(&mut self.order, &mut self.pos);
        if !fresh.is_empty() {
            fresh.sort_unstable_by(sweep_order);
            let merged = &mut scratch.merged;
            merged.clear();
            merged.reserve(self.order.len() + fresh.len());
            let (mut i, mut j) = (0, 0);
            while i < self.order.len() && j < fresh.len() {
                if sweep_order(&self.order[i], &fresh[j]) == Ordering::Less {
                    merged.push(self.order[i]);
                    i += 1;
                } else {
                    merged.push(fresh[j]);
                    j += 1;
                }
            }
            merged.extend_from_slice(&self.order[i..]);
            merged.extend_from_slice(&fresh[j..]);
            std::mem::swap(&mut self.order, merged);
        }
        for (p, s) in self.order.iter().enumerate() {
            self.pos[s.local as usize] = p as u32;
        }
        self.width = 0.0;
        for &h in handles {
            let b = &bodies[h as usize].bounds;
            self.width = self.width.max(b.max.x - b.min.x);
        }
        moved
    }
}

/// Insertion sort for a nearly sorted list, keeping `pos` up to date; past `8n + 64` moves
/// it gives up and sorts.
fn insertion_sort(order: &mut [Slot], pos: &mut [u32]) -> u64 {
    let budget = 8 * order.len() as u64 + 64;
    let mut moved = 0;
    for i in 1..order.len() {
        if sweep_order(&order[i - 1], &order[i]) != Ordering::Greater {
            continue;
        }
        let x = order[i];
        let mut j = i;
        while j > 0 && sweep_order(&x, &order[j - 1]) == Ordering::Less {
            order[j] = order[j - 1];
            pos[order[j].local as usize] = j as u32;
            j -= 1;
        }
        order[j] = x;
        pos[x.local as usize] = j as u32;
        moved += (i - j) as u64;
        if moved > budget {
            order.sort_unstable_by(sweep_order);
            for (p, s) in order.iter().enumerate() {
                pos[s.local as usize] = p as u32;
            }
            break;
        }
    }
    moved
}

/// Tests `p` (whose `max.x` key is `max`) against the bodies of `others` (sorted) ahead of
/// it, until one starts past its end along x. Returns the tests.
#[inline]
fn scan(p: &Member, max: u64, others: &[Slot], v: SweepView, out: &mut Vec<(u32, u32)>) -> u64 {
    let mut tested = 0;
    for s in others {
        if s.min > max {
            break;
        }
        let q = v.member(s.local);
        if p.dynamic || q.dynamic {
            tested += 1;
            if p.bounds.overlaps(&q.bounds) {
                out.push((p.handle, q.handle));
            }
        }
    }
    tested
}

/// All overlapping pairs within one list with a dynamic body. Returns the tests.
fn sweep_self(v: SweepView, out: &mut Vec<(u32, u32)>) -> u64 {
    let mut tested = 0;
    let order = &v.list.order;
    for (k, s) in order.iter().enumerate() {
        let rest = &order[k + 1..];
        // Most bodies overlap nothing ahead: look at the body only when something starts
        // before its end.
        if rest.first().is_some_and(|next| next.min <= s.max) {
            tested += scan(&v.member(s.local), s.max, rest, v, out);
        }
    }
    tested
}

/// All overlapping pairs with one body from each list (and a dynamic one). When the smaller
/// list's bodies find few candidates by binary search in the larger (a hundred bullets among
/// ten thousand asteroids), that is all; otherwise the two lists are walked in merged order,
/// each body scanning only the other list ahead of it.
fn sweep_cross(
    x: SweepView,
    y: SweepView,
    ranges: &mut Vec<(u32, u32)>,
    out: &mut Vec<(u32, u32)>,
) -> u64 {
    let (small, large) = if x.handles.len() <= y.handles.len() {
        (x, y)
    } else {
        (y, x)
    };
    ranges.clear();
    let mut candidates = 0;
    for &h in small.handles {
        let (lo, hi) = x_range(&large.list.order, large.list.width, &x.bodies[h as usize]);
        candidates += hi - lo;
        if candidates > large.handles.len() {
            return sweep_merged(x, y, out);
        }
        ranges.push((lo as u32, hi as u32));
    }
    let mut tested = 0;
    for (&h, &(lo, hi)) in small.handles.iter().zip(ranges.iter()) {
        let q = member(&x.bodies[h as usize], h);
        for s in &large.list.order[lo as usize..hi as usize] {
            let m = large.member(s.local);
            if q.dynamic || m.dynamic {
                tested += 1;
                if q.bounds.overlaps(&m.bounds) {
                    out.push((q.handle, m.handle));
                }
            }
        }
    }
    tested
}

/// The slots of `order` (sorted, none wider than `width`) that can overlap `q` along x:
/// `order[lo..hi]`. Conservative by a relative margin far above rounding error.
fn x_range(order: &[Slot], width: f64, q: &BodyEntry) -> (usize, usize) {
    let q = &q.bounds;
    if [q.min.x, q.min.y, q.max.x, q.max.y]
        .iter()
        .any(|v| v.is_nan())
    {
        return (0, 0); // overlaps nothing
    }
    // Bodies starting before `lower` end before `q.min.x`.
    let mut lower = q.min.x - width * (1.0 + 1e-12);
    lower -= lower.abs() * 1e-12 + f64::MIN_POSITIVE;
    let (lower, upper) = (order_key(lower), order_key(q.max.x + 0.0));
    let lo = order.partition_point(|s| s.min < lower);
    let hi = order.partition_point(|s| s.min <= upper);
    (lo, hi.max(lo))
}

/// The merged walk of [`sweep_cross`].
fn sweep_merged(x: SweepView, y: SweepView, out: &mut Vec<(u32, u32)>) -> u64 {
    let mut tested = 0;
    let (xs, ys) = (&x.list.order, &y.list.order);
    let (mut i, mut j) = (0, 0);
    while i < xs.len() && j < ys.len() {
        if xs[i].min <= ys[j].min {
            if ys[j].min <= xs[i].max {
                tested += scan(&x.member(xs[i].local), xs[i].max, &ys[j..], y, out);
            }
            i += 1;
        } else {
            if xs[i].min <= ys[j].max {
                tested += scan(&y.member(ys[j].local), ys[j].max, &xs[i..], x, out);
            }
            j += 1;
        }
    }
    tested
}

/// `SortAndSweep`'s static structure: a packed tree (sort-tile-recursive), built once.
#[derive(Debug, Default)]
struct StaticTree {
    /// Leaves of [`LEAF`] consecutive members.
    items: Vec<Member>,
    /// `levels[0][i]` bounds leaf `i`; `levels[k + 1][i]` bounds `levels[k][2i..2i + 2]`.
    levels: Vec<Vec<Bounds>>,
}

const LEAF: usize = 8;

impl StaticTree {
    fn new(mut items: Vec<Member>) -> StaticTree {
        if items.is_empty() {
            return StaticTree::default();
        }
        let center = |m: &Member| m.bounds.center();
        items.sort_unstable_by(|a, b| {
            center(a)
                .x
                .total_cmp(&center(b).x)
                .then(a.handle.cmp(&b.handle))
        });
        let leaves = items.len().div_ceil(LEAF);
        let slices = (leaves as f64).sqrt().ceil().max(1.0) as usize;
        let per_slice = leaves.div_ceil(slices) * LEAF;
        for slice in items.chunks_mut(per_slice) {
            slice.sort_unstable_by(|a, b| {
                center(a)
                    .y
                    .total_cmp(&center(b).y)
                    .then(a.handle.cmp(&b.handle))
            });
        }
        let leaves: Vec<Bounds> = items
            .chunks(LEAF)
            .map(|c| c[1..].iter().fold(c[0].bounds, |u, m| hull(u, m.bounds)))
            .collect();
        let mut levels = vec![leaves];
        while levels[levels.len() - 1].len() > 1 {
            let next = levels[levels.len() - 1]
                .chunks(2)
                .map(|c| c[1..].iter().fold(c[0], |u, b| hull(u, *b)))
                .collect();
            levels.push(next);
        }
        StaticTree { items, levels }
    }

    /// Calls `f` on every member overlapping `q`. Returns the body tests.
    fn query(&self, q: &Bounds, stack: &mut Vec<(u32, u32)>, f: &mut impl FnMut(&Member)) -> u64 {
        if self.items.is_empty() {
            return 0;
        }
        let mut tested = 0;
        stack.clear();
        stack.push(((self.levels.len() - 1) as u32, 0));
        while let Some((level, i)) = stack.pop() {
            let (level, i) = (level as usize, i as usize);
            if !self.levels[level][i].overlaps(q) {
                continue;
            }
            if level == 0 {
                let end = (i * LEAF + LEAF).min(self.items.len());
                for m in &self.items[i * LEAF..end] {
                    tested += 1;
                    if m.bounds.overlaps(q) {
                        f(m);
                    }
                }
            } else {
                let below = self.levels[level - 1].len();
                for c in [2 * i + 1, 2 * i] {
                    if c < below {
                        stack.push(((level - 1) as u32, c as u32));
                    }
                }
            }
        }
        tested
    }
}

/// The smallest box holding both, ignoring NaN coordinates (`f64::min` and `max` do; a NaN
/// box overlaps nothing, so nothing is lost). Inverted boxes are fine: a member overlapping
/// `q` makes every box holding its `min` and `max` overlap `q` too.
fn hull(a: Bounds, b: Bounds) -> Bounds {
    Bounds {
        min: Vec2::new(a.min.x.min(b.min.x), a.min.y.min(b.min.y)),
        max: Vec2::new(a.max.x.max(b.max.x), a.max.y.max(b.max.y)),
    }
}

/// A uniform grid: `(cell, member)` entries counting-sorted by cell, into a dense table over
/// the occupied cells or a table indexed by a fixed hash of the cell.
#[derive(Debug, Default)]
struct HashGrid {
    frame: u64,
    cells: Cells,
    /// Bucket `b` is `entries[starts[b]..starts[b + 1]]`.
    starts: Vec<u32>,
    /// `(cell x, cell y, member)`.
    entries: Vec<(i32, i32, u32)>,
    members: Vec<Member>,
    /// Members in no cell (covering too many, or with inverted or NaN bounds): tested
    /// against everything.
    big: Vec<u32>,
    is_big: Vec<bool>,
    /// Build buffer: each member in cells, with the cells it covers.
    ranges: Vec<(CellRange, u32)>,
}

/// A body covering more cells goes to the grid's `big` list.
const MAX_CELLS: u64 = 16;

/// A grid over boxes that never move, built once (the per-axis stages' static boxes): which
/// of them overlap a query box. Laid out as the broad phase's grids ([`Cells`]), but each
/// cell's entries hold the boxes' bounds themselves, so a lookup in a million tiles reads a
/// few cache lines (the cell's bucket start and its entries) and never the bodies. A box
/// covering more than [`MAX_CELLS`] cells (or with irregular bounds) is kept in a list every
/// lookup scans.
#[derive(Debug, Default)]
pub(crate) struct FixedGrid {
    cells: Cells,
    starts: Vec<u32>,
    entries: Vec<FixedEntry>,
    big: Vec<(Bounds, u32)>,
}

#[derive(Clone, Copy, Debug)]
struct FixedEntry {
    cell: (i32, i32),
    handle: u32,
    bounds: Bounds,
}

impl FixedGrid {
    /// Indexes `boxes`, each with a handle reported by [`FixedGrid::query`].
    pub(crate) fn new(boxes: impl Iterator<Item = (Bounds, u32)>) -> FixedGrid {
        let boxes: Vec<(Bounds, u32)> = boxes.collect();
        let mut g = FixedGrid {
            cells: Cells::sized_for(boxes.iter().map(|(b, _)| b), &mut Vec::new()),
            ..FixedGrid::default()
        };
        let mut placed: Vec<(CellRange, (Bounds, u32))> = Vec::with_capacity(boxes.len());
        for &(b, h) in &boxes {
            match g.cells.range(&b) {
                Some(r) if r.count() <= MAX_CELLS => placed.push((r, (b, h))),
                _ => g.big.push((b, h)),
            }
        }
        let blank = FixedEntry {
            cell: (0, 0),
            handle: 0,
            bounds: Bounds::around(Vec2::ZERO, Vec2::ZERO),
        };
        let entry = |cell, (bounds, handle)| FixedEntry {
            cell,
            handle,
            bounds,
        };
        g.cells
            .fill(&placed, blank, entry, &mut g.starts, &mut g.entries);
        g
    }

    /// Calls `f` once with the handle and bounds of every box overlapping `q` (touching
    /// counts). Returns the box tests made.
    pub(crate) fn query(&self, q: &Bounds, mut f: impl FnMut(u32, &Bounds)) -> u64 {
        let mut tested = 0;
        for (b, h) in &self.big {
            tested += 1;
            if b.overlaps(q) {
                f(*h, b);
            }
        }
        let Some(r) = self.cells.range(q).map(|r| self.cells.clip(r)) else {
            return tested;
        };
        if r.count() > self.entries.len() as u64 {
            // Larger than everything: each box once, from its entry in its own first cell
            // (the lower-left one it covers).
            for e in &self.entries {
                let first = (
                    self.cells.coord(e.bounds.min.x),
                    self.cells.coord(e.bounds.min.y),
                );
                if e.cell == first {
                    tested += 1;
                    if e.bounds.overlaps(q) {
                        f(e.handle, &e.bounds);
                    }
                }
            }
            return tested;
        }
        for c in r.cells() {
            let Some(k) = self.cells.bucket(c) else {
                continue;
            };
            for e in &self.entries[self.starts[k] as usize..self.starts[k + 1] as usize] {
                if e.cell != c {
                    continue;
                }
                tested += 1;
                // Reported once: in the cell holding the lower-left corner of the overlap.
                if e.bounds.overlaps(q) && self.cells.owns(&e.bounds, q, c) {
                    f(e.handle, &e.bounds);
                }
            }
        }
        tested
    }
}

/// How a grid maps space to buckets: the cell size, and either a dense table over the
/// occupied rectangle of cells (row by row: neighbours are neighbours in memory, as in a tile
/// map) or a table indexed by a fixed multiplicative hash of the cell. Shared by
/// [`HashGrid`] and [`FixedGrid`].
#[derive(Clone, Copy, Debug, Default)]
struct Cells {
    inv_cell: f64,
    /// Hashed: the table has `1 << bits` buckets.
    bits: u32,
    /// Dense: one bucket per cell of the `span` cells from `origin`, row by row.
    dense: bool,
    origin: (i32, i32),
    span: (u32, u32),
}

impl Cells {
    /// Cells twice the median extent of `boxes` (`max(width, height)`), widened if needed so
    /// that cell coordinates stay within `±2^30`. `extents` is a buffer.
    fn sized_for<'a>(boxes: impl Iterator<Item = &'a Bounds>, extents: &mut Vec<f64>) -> Cells {
        extents.clear();
        let mut max_abs: f64 = 0.0;
        for b in boxes {
            if b.min.x <= b.max.x && b.min.y <= b.max.y {
                let e = (b.max.x - b.min.x).max(b.max.y - b.min.y);
                if e.is_finite() {
                    extents.push(e);
                }
                for v in [b.min.x, b.min.y, b.max.x, b.max.y] {
                    if v.is_finite() {
                        max_abs = max_abs.max(v.abs());
                    }
                }
            }
        }
        let mut cell = if extents.is_empty() {
            1.0
        } else {
            let mid = extents.len() / 2;
            let (_, median, _) = extents.select_nth_unstable_by(mid, f64::total_cmp);
            2.0 * *median
        };
        if !(cell.is_finite() && cell > 0.0) {
            cell = 1.0;
        }
        cell = cell.max(max_abs / CELL_RANGE);
        if !(1.0 / cell).is_normal() {
            cell = 1.0f64.max(max_abs / CELL_RANGE);
        }
        Cells {
            inv_cell: 1.0 / cell,
            ..Cells::default()
        }
    }

    /// Chooses the table for `items` (each with the cells it covers; an empty range for one
    /// kept out of the cells) and counting-sorts `entry(cell, item)` into `entries`, bucket
    /// `b` being `entries[starts[b]..starts[b + 1]]`, each bucket in input order. Dense
    /// unless the occupied rectangle has more than four cells per entry.
    fn fill<T: Copy, E: Copy>(
        &mut self,
        items: &[(CellRange, T)],
        blank: E,
        entry: impl Fn((i32, i32), T) -> E,
        starts: &mut Vec<u32>,
        entries: &mut Vec<E>,
    ) {
        let (mut lo, mut hi) = ((i32::MAX, i32::MAX), (i32::MIN, i32::MIN));
        let mut total = 0u64;
        for (r, _) in items {
            if r.count() > 0 {
                lo = (lo.0.min(r.x.0), lo.1.min(r.y.0));
                hi = (hi.0.max(r.x.1), hi.1.max(r.y.1));
                total += r.count();
            }
        }
        let span = |a: i32, b: i32| (i64::from(b) - i64::from(a) + 1).max(0) as u64;
        let cells = span(lo.0, hi.0).saturating_mul(span(lo.1, hi.1));
        self.dense = total > 0 && cells <= 4 * total + 64;
        let size = if self.dense {
            self.origin = lo;
            self.span = (span(lo.0, hi.0) as u32, span(lo.1, hi.1) as u32);
            cells as usize
        } else {
            (total as usize).max(16).next_power_of_two()
        };
        self.bits = size.trailing_zeros();
        starts.clear();
        starts.resize(size + 1, 0);
        for (r, _) in items {
            for c in r.cells() {
                if let Some(k) = self.bucket(c) {
                    starts[k] += 1;
                }
            }
        }
        // Each bucket's end, then fill backwards: `starts[b]` ends at the bucket's start.
        let mut sum = 0;
        for st in starts.iter_mut() {
            sum += *st;
            *st = sum;
        }
        entries.clear();
        entries.resize(total as usize, blank);
        for &(r, item) in items.iter().rev() {
            for c in r.cells() {
                if let Some(k) = self.bucket(c) {
                    starts[k] -= 1;
                    entries[starts[k] as usize] = entry(c, item);
                }
            }
        }
    }

    /// The cell coordinate of `v`: monotone in `v`, so overlapping boxes share a cell.
    #[inline]
    fn coord(&self, v: f64) -> i32 {
        cell_coord(v, self.inv_cell)
    }

    /// The cells `b` covers, or `None` for inverted or NaN bounds.
    #[inline]
    fn range(&self, b: &Bounds) -> Option<CellRange> {
        if !(b.min.x <= b.max.x && b.min.y <= b.max.y) {
            return None;
        }
        Some(CellRange {
            x: (self.coord(b.min.x), self.coord(b.max.x)),
            y: (self.coord(b.min.y), self.coord(b.max.y)),
        })
    }

    /// Whether cell `c` is where the pair `(a, b)` is reported: the one holding the lower
    /// left corner of their intersection, a cell both cover.
    #[inline]
    fn owns(&self, a: &Bounds, b: &Bounds, c: (i32, i32)) -> bool {
        self.coord(a.min.x.max(b.min.x)) == c.0 && self.coord(a.min.y.max(b.min.y)) == c.1
    }

    #[inline]
    fn bucket(&self, (cx, cy): (i32, i32)) -> Option<usize> {
        if self.dense {
            let x = i64::from(cx) - i64::from(self.origin.0);
            let y = i64::from(cy) - i64::from(self.origin.1);
            let (w, h) = (i64::from(self.span.0), i64::from(self.span.1));
            return (0 <= x && x < w && 0 <= y && y < h).then_some((x + y * w) as usize);
        }
        let packed = u64::from(cx as u32) | (u64::from(cy as u32) << 32);
        Some((packed.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> (64 - self.bits)) as usize)
    }

    /// `r` cut to the occupied cells when the table is dense.
    fn clip(&self, r: CellRange) -> CellRange {
        if !self.dense {
            return r;
        }
        let last = |o: i32, n: u32| (i64::from(o) + i64::from(n) - 1) as i32;
        CellRange {
            x: (
                r.x.0.max(self.origin.0),
                r.x.1.min(last(self.origin.0, self.span.0)),
            ),
            y: (
                r.y.0.max(self.origin.1),
                r.y.1.min(last(self.origin.1, self.span.1)),
            ),
        }
    }
}

/// Cell coordinates stay within `±2^30` of the origin for finite bounds.
const CELL_RANGE: f64 = (1u64 << 30) as f64;

#[derive(Clone, Copy, Debug)]
struct CellRange {
    x: (i32, i32),
    y: (i32, i32),
}

impl CellRange {
    fn count(self) -> u64 {
        let span = |(lo, hi): (i32, i32)| (i64::from(hi) - i64::from(lo) + 1).max(0) as u64;
        span(self.x).saturating_mul(span(self.y))
    }

    fn cells(self) -> impl Iterator<Item = (i32, i32)> {
        (self.y.0..=self.y.1).flat_map(move |cy| (self.x.0..=self.x.1).map(move |cx| (cx, cy)))
    }
}

/// `floor(v * inv_cell)`, clamped to `i32`: monotone in `v`.
#[inline]
pub(crate) fn cell_coord(v: f64, inv_cell: f64) -> i32 {
    // Clamped, then floored by hand (`f64::floor` is a call on baseline x86-64): the cast
    // truncates toward zero, a negative fraction steps down. NaN becomes 0; only regular
    // bounds get here.
    let x = (v * inv_cell).clamp(f64::from(i32::MIN), f64::from(i32::MAX));
    let t = x as i32;
    t - i32::from(f64::from(t) > x)
}

impl HashGrid {
    fn bucket_entries(&self, b: usize) -> &[(i32, i32, u32)] {
        &self.entries[self.starts[b] as usize..self.starts[b + 1] as usize]
    }

    /// The entries of cell `c` (and, hashed, of the cells sharing its bucket).
    #[inline]
    fn cell_entries(&self, c: (i32, i32)) -> &[(i32, i32, u32)] {
        self.cells.bucket(c).map_or(&[], |b| self.bucket_entries(b))
    }

    /// Chooses the cell from `members` and indexes them.
    /// With `reorder` (static grids, built once), the members are first sorted by the row
    /// and column of their lower-left cell, so a cell's members sit together in memory.
    fn build(&mut self, extents: &mut Vec<f64>, reorder: bool) {
        self.cells = Cells::sized_for(self.members.iter().map(|m| &m.bounds), extents);
        if reorder {
            let cells = self.cells;
            self.members.sort_by_cached_key(|m| {
                let b = &m.bounds;
                (cells.coord(b.min.y), cells.coord(b.min.x), m.handle)
            });
        }
        self.big.clear();
        self.is_big.clear();
        self.is_big.resize(self.members.len(), false);
        let mut ranges = std::mem::take(&mut self.ranges);
        ranges.clear();
        for (i, m) in self.members.iter().enumerate() {
            match self.cells.range(&m.bounds) {
                Some(r) if r.count() <= MAX_CELLS => ranges.push((r, i as u32)),
                _ => {
                    self.is_big[i] = true;
                    self.big.push(i as u32);
                }
            }
        }
        let entry = |(cx, cy), i| (cx, cy, i);
        self.cells.fill(
            &ranges,
            (0, 0, 0),
            entry,
            &mut self.starts,
            &mut self.entries,
        );
        self.ranges = ranges;
    }

    /// Calls `f` once on every member overlapping `q`. Returns the body tests.
    fn query(&self, q: &Bounds, mut f: impl FnMut(&Member)) -> u64 {
        let mut tested = 0;
        let range = self
            .cells
            .range(q)
            .map(|r| self.cells.clip(r))
            .filter(|r| r.count() <= (self.members.len() as u64).max(MAX_CELLS));
        let Some(range) = range else {
            // Too big (or irregular) to look up cell by cell: test everything.
            for m in &self.members {
                tested += 1;
                if m.bounds.overlaps(q) {
                    f(m);
                }
            }
            return tested;
        };
        if self.members.len() > self.big.len() {
            for c in range.cells() {
                for &(cx, cy, i) in self.cell_entries(c) {
                    if (cx, cy) != c {
                        continue;
                    }
                    let m = &self.members[i as usize];
                    tested += 1;
                    if m.bounds.overlaps(q) && self.cells.owns(q, &m.bounds, c) {
                        f(m);
                    }
                }
            }
        }
        for &i in &self.big {
            let m = &self.members[i as usize];
            tested += 1;
            if m.bounds.overlaps(q) {
                f(m);
            }
        }
        tested
    }

    /// Every overlapping pair of members with a dynamic body. Returns the body tests.
    fn self_pairs(&self, out: &mut Vec<(u32, u32)>) -> u64 {
        let mut tested = 0;
        for b in 0..self.starts.len() - 1 {
            let es = self.bucket_entries(b);
            for (k, &(cx, cy, i)) in es.iter().enumerate() {
                let p = &self.members[i as usize];
                for &(dx, dy, j) in &es[k + 1..] {
                    let q = &self.members[j as usize];
                    if (dx, dy) != (cx, cy) || !(p.dynamic || q.dynamic) {
                        continue;
                    }
                    tested += 1;
                    if p.bounds.overlaps(&q.bounds)
                        && self.cells.owns(&p.bounds, &q.bounds, (cx, cy))
                    {
                        out.push((p.handle, q.handle));
                    }
                }
            }
        }
        for &o in &self.big {
            let p = &self.members[o as usize];
            for (i, q) in self.members.iter().enumerate() {
                if i as u32 == o || (self.is_big[i] && (i as u32) < o) {
                    continue;
                }
                if p.dynamic || q.dynamic {
                    tested += 1;
                    if p.bounds.overlaps(&q.bounds) {
                        out.push((p.handle, q.handle));
                    }
                }
            }
        }
        tested
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    fn boxes() -> impl Strategy<Value = Vec<Bounds>> {
        // Tiles and odd sizes, around the origin and at 1e6, a few huge.
        let b = (
            prop_oneof![Just(0.0), Just(1e6)],
            -20.0..20.0f64,
            -20.0..20.0f64,
            prop_oneof![3 => 0.5..1.5f64, 1 => 1e-3..0.1f64, 1 => 5.0..60.0f64],
            0.1..2.0f64,
        )
            .prop_map(|(o, x, y, w, h)| Bounds {
                min: Vec2::new(o + x, y),
                max: Vec2::new(o + x + w, y + h),
            });
        proptest::collection::vec(b, 0..200)
    }

    proptest! {
        #[test]
        fn fixed_grid_finds_exactly_the_overlapping_boxes_once(
            fixed in boxes(),
            queries in boxes(),
        ) {
            let grid = FixedGrid::new(fixed.iter().enumerate().map(|(i, b)| (*b, i as u32)));
            for q in &queries {
                let mut found = Vec::new();
                grid.query(q, |h, b| {
                    assert_eq!(*b, fixed[h as usize]);
                    found.push(h);
                });
                found.sort_unstable();
                let expected: Vec<u32> = (0..fixed.len() as u32)
                    .filter(|&i| fixed[i as usize].overlaps(q))
                    .collect();
                prop_assert_eq!(found, expected);
            }
        }
    }

    #[test]
    fn fixed_grid_handles_empty_nan_and_everything_queries() {
        let tiles: Vec<(Bounds, u32)> = (0..100)
            .map(|i| {
                let p = Vec2::new(f64::from(i % 10), f64::from(i / 10));
                (Bounds::around(p, Vec2::splat(0.5)), i)
            })
            .collect();
        let grid = FixedGrid::new(tiles.iter().copied());
        let count = |q: Bounds| {
            let mut n = 0;
            grid.query(&q, |_, _| n += 1);
            n
        };
        assert_eq!(
            count(Bounds::around(Vec2::splat(4.5), Vec2::splat(1e9))),
            100
        );
        assert_eq!(count(Bounds::around(Vec2::splat(f64::NAN), Vec2::ONE)), 0);
        assert_eq!(
            count(Bounds::around(Vec2::new(0.0, 0.0), Vec2::splat(0.1))),
            1
        );
        let empty = FixedGrid::new(std::iter::empty());
        let mut n = 0;
        empty.query(&Bounds::around(Vec2::ZERO, Vec2::ONE), |_, _| n += 1);
        assert_eq!(n, 0);
    }
}
