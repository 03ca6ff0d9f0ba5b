//! Broad phases: which pairs of bodies have overlapping bounds and are worth a narrow-phase
//! test.
//!
//! Given each body's [`Bounds`], layer and [`BodyKind`], a [`BroadPhase`] writes the candidate
//! pairs `(i, j)`, `i < j`, as dense indices (the order of the bodies, which is key order),
//! sorted and without duplicates: exactly the pairs whose bounds overlap (touching counts, as
//! [`Bounds::overlaps`]) and that pass two filters applied *inside* the broad phase, so the
//! pairs are never produced:
//! - **at least one body is dynamic**: static and kinematic bodies never pair with each other;
//! - **their layers interact** ([`Interactions`], in `interactions.rs`). A layer that does not
//!   interact with itself is never swept against itself: its bodies are only ever tested
//!   against the layers it interacts with (10,000 asteroids that ignore each other cost no
//!   asteroid–asteroid test).
//!
//! This file holds the public types and the entry points: the moving bodies are counted and
//! grouped by layer (`tally.rs`), then the call chooses its algorithm, each pair of
//! interacting layers goes to that algorithm's structures, and the pairs found, named by
//! handles, are turned into dense indices and sorted (`call.rs`).
//!
//! # Algorithms ([`BroadPhaseKind`])
//! All six produce the same pairs; they differ only in speed.
//! - `BruteForce` (`brute_force.rs`): every pair, `O(n²)`. The reference, and the fastest
//!   below a few dozen bodies.
//! - `SortAndSweep` (`sort_and_sweep.rs`): per layer, the moving bodies sorted by `min.x`,
//!   kept from the previous call and re-sorted by insertion sort (nearly sorted: about
//!   `O(n)`). A self-interacting layer is swept against itself; two interacting layers never
//!   look at pairs within one layer. Static bodies go into a packed tree per layer
//!   (`static_tree.rs`), which each dynamic body queries in `O(log n + k)`. A layer of at
//!   least 1,024 moving bodies that does not meet itself, met only by layers with a
//!   sixteenth of its bodies or fewer (asteroids met by bullets), is not kept sorted: the
//!   small layers mark a 256 × 256 bitmap of cells over their union box (on its inner
//!   cells: whatever lies outside that box falls on the border, never marked), and a big
//!   body is tested only when the cell of its lower-left corner is marked
//!   (`cell_filter.rs`). A caller that counts its moving bodies itself may leave such a
//!   layer out of the entries but for the bodies on a marked cell (`left_out.rs`).
//! - `Grid` (`hash_grid.rs`): a uniform grid per layer, dense over the occupied cells or
//!   hashed; two interacting layers: the grid of the larger is queried with the bodies of the
//!   smaller. Static bodies have their own grid per layer, with its own cell size. What every
//!   grid shares (cell coordinates and size, the bucket hash, the limit on the cells a body
//!   may cover, the counting-sorted table) is in `grid.rs`, also used by the per-axis stages'
//!   grids (`fixed_grid.rs`, `mover_grid.rs`).
//! - `Strips` (`strips.rs`): sort and sweep within horizontal strips as tall as the tallest
//!   body (one strip height per call, a power of two, for every list): each layer's moving
//!   bodies filed in the one or two strips they reach and sorted by `(strip, min.x)`, kept
//!   and re-sorted like `SortAndSweep`, swept within each strip; static bodies in lists of
//!   their own, sorted once. Overlapping boxes share a strip, so a crowd sharing one x
//!   range (rain) costs what its neighbours in y cost, not the whole column.
//! - `Quadtree` (`quadtree.rs`): a loose quadtree per layer, rebuilt every call for the
//!   moving bodies (one pass of stable partitions, `O(n log n)`), built once for the static
//!   ones. A body sits in the one node its centre and size choose, so a few huge bodies
//!   stay near the root and cost the small ones one test each, where they make a uniform
//!   grid's cells huge or cover thousands of them. Each node keeps the exact hull of its
//!   subtree, which is all a query looks at.
//! - `Tree` (`dynamic_tree.rs`, `kept_tree.rs`): Box2D's dynamic tree. Per layer, a
//!   bounding-volume tree of the moving bodies' *fat* boxes (bounds grown by a quarter of
//!   their size), kept across calls: a body still inside its fat box costs one containment
//!   test; one that left it gets a new fat box in place, its ancestors grown; new bodies
//!   are inserted by the surface-area heuristic (ancestors refitted and rotated). The tree
//!   is rebuilt top-down once as many leaves were re-boxed as it holds, or when most of a
//!   layer is new. The static bodies get a tree of their exact boxes, built once. Meant
//!   for a crowd that only meets other layers (asteroids and bullets): it keeps its boxes,
//!   and each body of the small layer queries them in `O(log n)`.
//!
//! Two interacting layers, with `Grid`, `Quadtree` or `Tree`: the structure of the larger
//! layer is queried with the bodies of the smaller, and only that structure is brought up
//! to date.
//!
//! **Static bodies are inserted once** (`static_set.rs`). The structures above for static
//! bodies are built when the static set changes, never per call; per call, only moving
//! (dynamic and kinematic) bodies are re-sorted or re-hashed, and only dynamic ones query the
//! static structures, so the per-call cost follows the moving bodies. [`BroadPhase::pairs`]
//! takes every body and notices a change by comparing the static bodies with the stored ones
//! (a linear scan, no rebuild); [`BroadPhase::pairs_split`] takes the static bodies apart
//! with a generation number the caller bumps when they change, and does not look at them
//! otherwise: with a million static tiles it costs what the moving bodies cost.
//!
//! # `Auto`
//! Decided on every call (`auto.rs`) from this call's counts, layer table and moving
//! bodies' widths alone: deterministic, no timing, and no memory of earlier calls, so a
//! simulation restored from a snapshot (its broad phase built anew) picks what the
//! original did. Only *indexed*
//! static bodies count: the inert ones a caller keeps out (`set_inert_statics`, a tile map
//! that only the per-axis stages meet) cost no algorithm anything, though the stats still
//! count them.
//! - at most 32 bodies given in all: `BruteForce` (at most 496 tests, no structure to keep);
//! - at least as many indexed static as moving bodies: `Grid` (a static cell lookup is
//!   `O(1)` where the static tree is `O(log n)`, and the static grid is built once); but
//!   `Strips` for a band along the world's edge (the wrap seam's, `BroadPhase::for_band`:
//!   few bodies over every row of the world, whose own grid, hashed anew each call, cost
//!   more than filing them in strips);
//! - a layer of at least [`CROWD`] moving bodies that interact with each other, on which
//!   sort and sweep would test each body against at least [`STRIPS_ENTER`] others along x:
//!   `Strips`. The estimate is `n w / X` for the layer's `n` bodies of mean width `w` over
//!   an x span `X` (the bodies whose `min.x` falls within a body's x extent, for an even
//!   spread), from 64 bodies evenly spaced in key order. Sort and sweep's cost grows with
//!   it (each x-overlap is a test, reading the other body's bounds); strips test only the
//!   neighbours in y, at a higher cost per body (bounds kept in the slots, two sort keys).
//! - otherwise `SortAndSweep` (moving crowds that only meet other layers, like asteroids
//!   and bullets, and crowds spread thin along x, like a long level's actors: the coherent
//!   sort costs about one pass over the moving bodies, and unlike a grid it does not care
//!   how much body sizes vary).
//!
//! Figures behind the threshold (`ricochet bench --broad-phases`, broad phase alone, ms a
//! frame, idle machine; estimate in brackets): the platformer's 1,000 actors along a long
//! level, `platformer-1000000-1000` (0.28) sort and sweep 0.015 against strips 0.051, and
//! `platformer-10000-1000` (2.9) 0.020 against 0.023; `sparse-10000` (7.5) strips 0.394
//! against sort and sweep 0.694, `rain-10000` (16) 0.632 against 3.000. On a loaded machine,
//! more sizes put the crossing between 3.4 (`sparse-2000`, `platformer-7000-1000`: level)
//! and 4.3 (`sparse-3000`, `platformer-5000-1000`: strips ahead), and strips ahead from 5
//! (`platformer-3000-1000`, `platformer-10000-3000`, `crowded-300` and up). The estimate
//! assumes an even spread along x: a crowd in a few tight clusters far apart is
//! underestimated, and one in a corridor one strip tall gains nothing from strips.
//!
//! Neither `Quadtree` nor `Tree` is ever `Auto`'s pick: in the study of BENCHMARKS.md
//! ("Broad phases: the study") neither was the fastest on any scene.
//!
//! Each kind keeps its own structures, so a switch costs one build and nothing else.
//!
//! # Determinism
//! Sorting uses `f64::total_cmp` with the body's key as the tie-break, so every order is a
//! function of the current input; the output is sorted. No hashed collection, no clock.

/// Moving bodies of one layer that interact with each other, from which `Auto` estimates
/// whether `Strips` pays (see the module docs).
pub const CROWD: usize = 256;

/// Sort and sweep's estimated x-overlaps per body of a crowd layer from which `Auto` takes
/// `Strips` (see the module docs).
pub const STRIPS_ENTER: f64 = 4.0;

mod auto;
mod brute_force;
mod by_layers;
mod call;
mod cell_filter;
mod dynamic_tree;
mod fixed_grid;
mod grid;
mod hash_grid;
mod interactions;
mod kept_tree;
mod left_out;
mod mover_grid;
mod quadtree;
mod sort_and_sweep;
mod sorted;
mod static_set;
pub(crate) mod static_tree;
mod strip_height;
mod strip_list;
mod strip_reach;
mod strip_slot;
mod strips;
mod tally;
mod tile_map;

use ricochet_geom::Bounds;

use crate::def::BodyKind;
use cell_filter::CellFilter;

pub(crate) use fixed_grid::FixedGrid;
use hash_grid::HashGrid;
pub use interactions::Interactions;
use kept_tree::KeptTree;
pub(crate) use left_out::{BigPass, Marking};
pub(crate) use mover_grid::MoverGrid;
use quadtree::Quadtree;
use sort_and_sweep::{Slot, SweepList};
use static_set::StaticSet;
use static_tree::StaticTree;
pub(crate) use strip_height::Extent;
use strip_list::StripList;
pub(crate) use tally::Tally;
pub(crate) use tile_map::{StaticBox, TileMap};

pub use crate::def::BroadPhaseKind;

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
    /// `SortAndSweep` and `Strips`: how many places bodies moved in the re-sort (for
    /// `Strips`, its insertion sort, the fresh slots' moves included).
    pub resorted: u64,
}

/// The broad phase, keeping its structures (and buffers) from one call to the next.
#[derive(Debug, Clone)]
pub struct BroadPhase {
    kind: BroadPhaseKind,
    chosen: BroadPhaseKind,
    /// `Auto`'s last estimate of sort and sweep's x-overlaps per body (`auto.rs`).
    overlaps: f64,
    /// The moving bodies given are a band around the world's edge (the wrap seam's,
    /// [`BroadPhase::for_band`]): `Auto` takes `Strips` where it would take `Grid`.
    band: bool,
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
    /// [`MAX_RUNS`](tally::MAX_RUNS) means too many to use.
    runs: Vec<(u32, u32, u8)>,
    sweeps: Vec<SweepList>,
    grids: Vec<HashGrid>,
    /// `Quadtree`: each layer's, rebuilt per call.
    quadtrees: Vec<Quadtree>,
    /// `Tree`: each layer's, kept across calls.
    trees: Vec<KeptTree>,
    /// `Strips`: each layer's moving list, each layer's static list, the strip height
    /// (`1 / H`) they share, and the static bodies' tallest height and largest coordinate.
    strips: Vec<StripList>,
    static_strips: Vec<StripList>,
    inv_h: f64,
    static_extent: (f64, f64),
    /// The moving bodies' [`Extent`] as the caller measured it for the next call
    /// ([`BroadPhase::give_extent`]), taken by that call.
    given_extent: Option<Extent>,
    scratch: Scratch,
    /// Sort and sweep's filter of a big layer met only by far smaller ones (`cell_filter.rs`).
    filter: CellFilter,
}

/// Buffers reused across calls.
#[derive(Debug, Default, Clone)]
struct Scratch {
    remap: Vec<u32>,
    fresh: Vec<Slot>,
    merged: Vec<Slot>,
    extents: Vec<f64>,
    stack: Vec<(u32, u32)>,
    ranges: Vec<(u32, u32)>,
    all: Vec<(Member, u8)>,
    /// The trees' walks.
    nodes: Vec<u32>,
}

/// A body inside a structure: its bounds, its handle (an index into the caller's slice for a
/// moving body, or a static index with [`STATIC_BIT`]), and whether it is dynamic.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Member {
    pub(crate) bounds: Bounds,
    pub(crate) handle: u32,
    pub(crate) dynamic: bool,
}

/// Marks a handle as a static body's index (in the [`StaticSet`]).
pub(crate) const STATIC_BIT: u32 = 1 << 31;
/// Layer ids are `u8`.
const LAYERS: usize = 256;

impl BroadPhase {
    /// A broad phase using `kind`.
    #[must_use]
    pub fn new(kind: BroadPhaseKind) -> BroadPhase {
        BroadPhase {
            kind,
            chosen: kind,
            overlaps: 0.0,
            band: false,
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
            quadtrees: (0..LAYERS).map(|_| Quadtree::default()).collect(),
            trees: (0..LAYERS).map(|_| KeptTree::default()).collect(),
            strips: (0..LAYERS).map(|_| StripList::default()).collect(),
            static_strips: Vec::new(),
            inv_h: 0.0,
            static_extent: (0.0, 0.0),
            given_extent: None,
            scratch: Scratch::default(),
            filter: CellFilter::default(),
        }
    }

    /// A broad phase using `kind` for the moving bodies of a band along the world's edge and
    /// their images across it (the wrap seam's): with more indexed static bodies than
    /// moving ones, `Auto` takes `Strips`, not `Grid` (see `auto.rs`).
    pub(crate) fn for_band(kind: BroadPhaseKind) -> BroadPhase {
        BroadPhase {
            band: true,
            ..BroadPhase::new(kind)
        }
    }

    /// The algorithm the last call ran (what `Auto` picked); before any call, the one asked
    /// for.
    #[must_use]
    pub fn chosen(&self) -> BroadPhaseKind {
        self.chosen
    }

    /// `Auto`'s estimate, in the last call, of the x-overlaps per body sort and sweep would
    /// test in the most crowded layer of at least [`CROWD`] moving bodies that interact with
    /// each other: the figure it compares with [`STRIPS_ENTER`]. 0 when it did not estimate
    /// (another rule decided first, no such layer, or not `Auto`).
    #[must_use]
    pub fn sweep_overlaps(&self) -> f64 {
        self.overlaps
    }

    /// The heap bytes held by the structures of `kind` (moving and static, the stored static
    /// bodies included), or `None` for `Auto`. For the broad-phase study (`ricochet bench
    /// --broad-phases`); capacities, so buffers kept for reuse count.
    #[must_use]
    pub fn heap_bytes(&self, kind: BroadPhaseKind) -> Option<usize> {
        let st = &self.statics;
        let statics = st.keys.capacity() * 8 + st.entries.capacity() * size_of::<(Bounds, u8)>();
        let structures = match kind {
            BroadPhaseKind::BruteForce => self.scratch.all.capacity() * size_of::<(Member, u8)>(),
            BroadPhaseKind::Grid => {
                let g = |v: &[HashGrid]| v.iter().map(HashGrid::heap_bytes).sum::<usize>();
                g(&self.grids) + g(&st.grids)
            }
            BroadPhaseKind::Quadtree => {
                let q = |v: &[Quadtree]| v.iter().map(Quadtree::heap_bytes).sum::<usize>();
                q(&self.quadtrees) + q(&st.quadtrees)
            }
            BroadPhaseKind::Tree => {
                self.trees.iter().map(KeptTree::heap_bytes).sum::<usize>()
                    + st.dynamic_trees
                        .iter()
                        .map(|t| t.heap_bytes())
                        .sum::<usize>()
            }
            BroadPhaseKind::SortAndSweep => {
                let sc = &self.scratch;
                self.sweeps.iter().map(SweepList::heap_bytes).sum::<usize>()
                    + st.trees.iter().map(StaticTree::heap_bytes).sum::<usize>()
                    + (sc.fresh.capacity() + sc.merged.capacity()) * size_of::<Slot>()
                    + sc.remap.capacity() * 4
                    + (sc.ranges.capacity() + sc.stack.capacity()) * 8
            }
            BroadPhaseKind::Strips => {
                let s = |v: &[StripList]| v.iter().map(StripList::heap_bytes).sum::<usize>();
                s(&self.strips) + s(&self.static_strips)
            }
            BroadPhaseKind::Auto => return None,
        };
        Some(statics + structures)
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
        self.choose(bodies, interactions);
        self.execute(bodies, (true, true), interactions, out)
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
        self.split(statics, static_generation, movers, interactions, true, out)
    }

    /// Static bodies the caller keeps out of [`BroadPhase::pairs_split_handles`] because
    /// their layers pair with no layer at all (a tile map that only the per-axis stages
    /// meet): `count` of them in `layers`. They count as static bodies for `Auto`'s choice
    /// and the stats, and their layers as layer pairs skipped, exactly as if they had been
    /// given, but cost nothing to keep. Takes effect with the next change of static
    /// generation.
    pub(crate) fn set_inert_statics(&mut self, count: usize, layers: &[u8]) {
        self.statics.inert = count;
        self.statics.inert_layers.clear();
        self.statics.inert_layers.extend_from_slice(layers);
    }

    /// Like [`BroadPhase::pairs_split`], but each pair is left as the two handles the
    /// algorithm met it by, in no particular order: an index into `movers`, or
    /// [`STATIC_BIT`] with an index into `statics`. For a caller that maps its entries back
    /// to bodies itself (the wrap seam's images).
    pub(crate) fn pairs_split_handles(
        &mut self,
        statics: &[BodyEntry],
        static_generation: u64,
        movers: &[BodyEntry],
        interactions: &Interactions,
        out: &mut Vec<(u32, u32)>,
    ) -> BroadPhaseStats {
        self.split(statics, static_generation, movers, interactions, false, out)
    }

    /// [`BroadPhase::pairs_split`], resolved to dense indices or not.
    fn split(
        &mut self,
        statics: &[BodyEntry],
        static_generation: u64,
        movers: &[BodyEntry],
        interactions: &Interactions,
        dense: bool,
        out: &mut Vec<(u32, u32)>,
    ) -> BroadPhaseStats {
        debug_assert!(
            movers.windows(2).all(|w| w[0].key < w[1].key),
            "keys increase"
        );
        self.load_statics(statics, static_generation);
        Tally::new(&mut self.layer_start, &mut self.dynamic, &mut self.runs).count(movers);
        self.group_movers(movers, |_| true);
        self.choose(movers, interactions);
        self.execute(movers, (false, dense), interactions, out)
    }

    /// Loads `statics` when `static_generation` differs from the loaded one's (or nothing
    /// is loaded).
    pub(crate) fn load_statics(&mut self, statics: &[BodyEntry], static_generation: u64) {
        if self.statics.generation != Some(static_generation) || !self.statics.loaded {
            debug_assert!(
                statics.windows(2).all(|w| w[0].key < w[1].key),
                "keys increase"
            );
            self.statics.load(statics.iter(), Some(static_generation));
        }
    }

    /// This call's moving bodies of `layer`, in key order.
    fn layer_movers(&self, layer: u8) -> &[u32] {
        of_layer(&self.movers, &self.layer_start, layer)
    }
}

/// Layer `l`'s moving bodies among `movers`, grouped by layer as `layer_start` says
/// (`movers[layer_start[l]..layer_start[l + 1]]`).
fn of_layer<'a>(movers: &'a [u32], layer_start: &[u32], l: u8) -> &'a [u32] {
    let l = usize::from(l);
    &movers[layer_start[l] as usize..layer_start[l + 1] as usize]
}

/// `b` as a [`Member`] named `handle`.
fn member(b: &BodyEntry, handle: u32) -> Member {
    Member {
        bounds: b.bounds,
        handle,
        dynamic: b.kind == BodyKind::Dynamic,
    }
}
