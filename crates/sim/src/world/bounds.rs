//! Each body's bounds for the broad phase: the bounds relative to the body kept from frame
//! to frame (`local_bounds.rs`), placed at the body's position, and the moving bodies' entries.

use std::ops::Range;

use ricochet_geom::{Bounds, Pose, Vec2};

use super::local_bounds::LocalBoundsRows;
use super::runs::RowRun;
use super::{NO_ROW, World};
use crate::broad_phase::{BigPass, BodyEntry, Extent, Marking, Tally};
use crate::def::BodyKind;
use crate::entity::Entity;
use crate::interned::ShapeTable;

impl World {
    /// Bounds of body `i` for the broad phase: they hold the shape, and are exact for a body
    /// that has not turned since it was created (or whose bounds turning does not change).
    /// A body that has turned is bounded by the square around the disc that holds its shape
    /// at every angle, so turning never costs a rotation here.
    pub fn bounds(&mut self, i: usize) -> Bounds {
        let p = self.position[i];
        match self.row[i] {
            NO_ROW => self.scenery_bounds(i),
            r => {
                let shape = &self.shapes.get(self.shape_id[i]).0;
                self.rows
                    .local_bounds
                    .at(r as usize, shape, self.angle[i], p)
            }
        }
    }

    /// How far body `i`'s shape reaches from its position at any angle
    /// ([`ricochet_geom::Shape::reach`], kept in the shape table): the disc around it.
    pub(crate) fn reach(&self, i: usize) -> f64 {
        self.shapes.reach(self.shape_id[i])
    }

    /// [`World::bounds`] of scenery `i`, which never turns: its bounds at its angle,
    /// translated.
    fn scenery_bounds(&self, i: usize) -> Bounds {
        let (shape, zero) = self.shapes.get(self.shape_id[i]);
        let angle = self.angle[i];
        let local = if angle.to_bits() == 0 {
            *zero
        } else {
            shape.bounds(&Pose::new(Vec2::ZERO, angle))
        };
        placed(local, self.position[i])
    }

    /// Moves moving body `i` to `position`, whole world sizes from where it is, and its
    /// frame's start by the same: the wrap seam brings a body far out of a wrapping world
    /// back in before `detect`, its motion over the frame unchanged.
    pub(crate) fn wrap_to(&mut self, i: usize, position: Vec2) {
        let shift = position - self.position[i];
        *self.position_mut(i) = position;
        let r = self.row[i];
        if r != NO_ROW {
            self.rows.start_position[r as usize] += shift;
        }
    }

    /// Body `i`'s entity as one number, ordered as entities are: the broad phase's key.
    pub(crate) fn key(&self, i: usize) -> u64 {
        let e = self.entity[i];
        (u64::from(e.index) << 32) | u64::from(e.generation)
    }

    /// The dense index of the live body whose [`World::key`] is `key`.
    pub(crate) fn index_of_key(&self, key: u64) -> Option<usize> {
        self.index_of(Entity {
            index: (key >> 32) as u32,
            generation: key as u32,
        })
    }

    /// The broad phase's view of every moving body, in [`World::movers`] order, into `out`:
    /// [`World::bounds`], widened over the frame's motion for a body of a layer in
    /// `sweeping` (a bullet that went right through something is still paired with it), or of
    /// a layer in `separate_swept` that moved more than half its [`ricochet_geom::Shape::min_width`] (a
    /// `separate` pair that time of impact may have to stop), and
    /// a frozen body handed over as kinematic (it keeps its place in the dense order; the
    /// caller drops its pairs). `visit` sees each entry's place in `out` and its bounds as
    /// they are made (the wrap seam looks for bodies near an edge without another pass).
    ///
    /// The places in `skip` are left as they were: [`World::some_mover_entries`] makes them
    /// (`out` is sized to every mover first). Returns what `M` measures of the entries made,
    /// as they are made: their [`Extent`], from which the broad phase's strips choose their
    /// height (`BroadPhase::give_extent`) instead of reading every entry again, or nothing.
    ///
    /// Each entry's key, layer and kind are written only when the layout or a frozen bit
    /// changed since they were (`MoverEntries`), every place's then; the passes that make
    /// the entries write their bounds alone.
    pub(crate) fn mover_entries<M: Measure>(
        &mut self,
        (sweeping, separate_swept): (&[bool], &[bool]),
        out: &mut MoverEntries,
        skip: Range<usize>,
        mut visit: impl FnMut(usize, &Bounds) -> bool,
    ) -> M {
        let at = (self.layout, self.frozen_changes);
        if out.made != Some(at) || out.list.len() != self.movers.len() {
            self.entry_keys(&mut out.list);
            out.made = Some(at);
        }
        let out = &mut out.list[..];
        let (before, after) = (0..skip.start, skip.end..out.len());
        let mut measured = M::default();
        for places in [before, after] {
            let made: M =
                self.entries_where((sweeping, separate_swept), out, places, &mut visit, None);
            measured.merge(made);
        }
        measured
    }

    /// [`World::mover_entries`] of the places in `places` only (within the movers), each
    /// shown to `visit`. With a `pass` (the broad phase's big layer left out of the
    /// entries: `broad_phase/left_out.rs`), a place is made only when `visit` or the pass
    /// keeps it, the others left as they were: only the bodies near a small one, or noted
    /// by `visit`, are read again.
    pub(crate) fn some_mover_entries(
        &mut self,
        widen: (&[bool], &[bool]),
        out: &mut MoverEntries,
        places: Range<usize>,
        mut visit: impl FnMut(usize, &Bounds) -> bool,
        pass: Option<&mut BigPass>,
    ) {
        debug_assert_eq!(
            out.made,
            Some((self.layout, self.frozen_changes)),
            "after `mover_entries` in the same layout: every place's key made"
        );
        let () = self.entries_where(widen, &mut out.list, places, &mut visit, pass);
    }

    /// Every mover's key, layer and kind into its place in `out`, sized to the movers (a
    /// frozen body handed over as kinematic); the bounds of a place new to `out` are
    /// empty until made.
    fn entry_keys(&self, out: &mut Vec<BodyEntry>) {
        let placeholder = BodyEntry {
            key: 0,
            bounds: Bounds {
                min: Vec2::ZERO,
                max: Vec2::ZERO,
            },
            layer: 0,
            kind: BodyKind::Dynamic,
        };
        out.resize(self.movers.len(), placeholder);
        for (out, &i) in out.iter_mut().zip(&self.movers) {
            let i = i as usize;
            let frozen = self.rows.frozen[self.row[i] as usize];
            out.key = self.key(i);
            out.layer = self.layer[i];
            out.kind = if frozen {
                BodyKind::Kinematic
            } else {
                self.kind[i]
            };
        }
    }

    /// The entries of `places` ([`World::some_mover_entries`]).
    fn entries_where<M: Measure>(
        &mut self,
        (sweeping, separate_swept): (&[bool], &[bool]),
        out: &mut [BodyEntry],
        places: Range<usize>,
        visit: &mut impl FnMut(usize, &Bounds) -> bool,
        pass: Option<&mut BigPass>,
    ) -> M {
        if places.is_empty() {
            return M::default();
        }
        let run = self.movers_run();
        // Every column sliced to its exact length first: the columns of one index then share
        // one bounds check (`i < n`, `r < m`) instead of one each.
        let n = self.row.len();
        let rows = &mut self.rows;
        let m = rows.local_bounds.len();
        // Per layer, whether its bodies may be widened over their motion (a fixed-size table
        // read by a `u8`: no bounds check).
        let mut widen = [0u8; 256];
        for (l, w) in widen.iter_mut().enumerate() {
            let flag = |of: &[bool], bit: u8| if of.get(l) == Some(&true) { bit } else { 0 };
            *w = flag(sweeping, SWEEPS) | flag(separate_swept, SEPARATE_SWEPT);
        }
        let mut columns = EntryColumns {
            position: &self.position[..n],
            angle: &self.angle[..n],
            layers: &self.layer[..n],
            shape_id: &self.shape_id[..n],
            local_bounds: rows.local_bounds.rows(0, m),
            start_position: &rows.start_position[..m],
            shapes: &self.shapes,
            widen: &widen,
        };
        let out = &mut out[places.clone()];
        let first = places.start;
        let list = match run {
            Some(_) => None,
            None => Some((&self.row[..n], &self.movers[places])),
        };
        // One loop for each test (monomorphised), the pass's state in locals.
        match pass {
            None => fill(&mut columns, run, list, out, first, visit, &mut Every),
            Some(pass) => match pass.marking() {
                None => fill(&mut columns, run, list, out, first, visit, &mut Noted),
                Some(mut marking) => {
                    let made = fill(&mut columns, run, list, out, first, visit, &mut marking);
                    let seen = marking.seen;
                    pass.measured(seen);
                    made
                }
            },
        }
    }
}

/// What [`World::mover_entries`] measures of the bounds of the entries it makes: their
/// [`Extent`] (when the broad phase's strips need it), or nothing (`()`).
pub(crate) trait Measure: Default {
    /// Takes the bounds of an entry made in.
    fn add(&mut self, b: &Bounds);

    /// Takes in what `other` took in.
    fn merge(&mut self, other: Self);
}

impl Measure for () {
    #[inline(always)]
    fn add(&mut self, _: &Bounds) {}

    #[inline(always)]
    fn merge(&mut self, (): ()) {}
}

impl Measure for Extent {
    #[inline(always)]
    fn add(&mut self, b: &Bounds) {
        Extent::add(self, b);
    }

    #[inline(always)]
    fn merge(&mut self, other: Extent) {
        Extent::merge(self, other);
    }
}

/// Which entries [`World::some_mover_entries`] makes, besides those `visit` notes.
trait Keep {
    /// Whether the entry at place `k`, of bounds `b`, is made.
    fn keep(&mut self, k: usize, b: &Bounds) -> bool;

    /// The one layer of every place shown, when the caller knows it.
    fn layer(&self) -> Option<u8> {
        None
    }
}

/// Every entry (no pass).
struct Every;

impl Keep for Every {
    #[inline(always)]
    fn keep(&mut self, _: usize, _: &Bounds) -> bool {
        true
    }
}

/// Only the entries `visit` notes (a pass with nothing marked).
struct Noted;

impl Keep for Noted {
    #[inline(always)]
    fn keep(&mut self, _: usize, _: &Bounds) -> bool {
        false
    }
}

impl Keep for Marking<'_> {
    #[inline(always)]
    fn keep(&mut self, k: usize, b: &Bounds) -> bool {
        Marking::keep(self, k, b)
    }

    fn layer(&self) -> Option<u8> {
        Some(self.layer)
    }
}

/// The entries of the places from `first` on, into `out`: each body with its row in place
/// over one `run` (`runs.rs`), else through `list` (the movers' indices and the row
/// column). Always inlined: the test, in a closure called from both loops, was not, and
/// the call cost a quarter of the asteroids' step.
#[inline(always)]
fn fill<M: Measure>(
    columns: &mut EntryColumns,
    run: Option<RowRun>,
    list: Option<(&[u32], &[u32])>,
    out: &mut [BodyEntry],
    first: usize,
    visit: &mut impl FnMut(usize, &Bounds) -> bool,
    keep: &mut impl Keep,
) -> M {
    // In a local, so that it stays in registers.
    let mut measured = M::default();
    match (run, list) {
        (Some(run), _) => {
            // Every column sliced to the places first: one index then reads them all
            // without a bounds check.
            let len = out.len();
            let (i0, r0) = (run.index + first, run.row + first);
            let mut columns = columns.slice(i0, r0, len);
            // One loop for each way of making a place's bounds (monomorphised). The big
            // pass's places are all of its layer: its flags read once. With no layer widened
            // (no bullet, nothing separated by time of impact), the bounds as placed, with no
            // path that keeps them across a call (the compiler kept every body's bounds on
            // the stack for it).
            let c = &mut columns;
            return if let Some(layer) = keep.layer() {
                let widen = c.widen[usize::from(layer)];
                fill_run(c, out, first, visit, keep, |c, k| {
                    debug_assert_eq!(c.layers[k], layer, "the pass's one layer");
                    c.widened(k, k, widen)
                })
            } else if c.widen.iter().all(|&w| w == 0) {
                fill_run(c, out, first, visit, keep, |c, k| c.widened(k, k, 0))
            } else {
                fill_run(c, out, first, visit, keep, |c, k| c.bounds(k, k))
            };
        }
        (None, Some((row, movers))) => {
            for (k, (out, &i)) in out.iter_mut().zip(movers).enumerate() {
                let (i, r) = (i as usize, row[i as usize] as usize);
                let bounds = columns.bounds(i, r);
                let near = visit(first + k, &bounds);
                if keep.keep(first + k, &bounds) || near {
                    measured.add(&bounds);
                    out.bounds = bounds;
                }
            }
        }
        (None, None) => {}
    }
    measured
}

/// [`fill`]'s loop over the places of one run (`columns` sliced to them), each place's
/// bounds made by `bounds_of`.
#[inline(always)]
fn fill_run<M: Measure>(
    columns: &mut EntryColumns,
    out: &mut [BodyEntry],
    first: usize,
    visit: &mut impl FnMut(usize, &Bounds) -> bool,
    keep: &mut impl Keep,
    mut bounds_of: impl FnMut(&mut EntryColumns, usize) -> Bounds,
) -> M {
    // In a local, so that it stays in registers.
    let mut measured = M::default();
    for (k, out) in out.iter_mut().enumerate() {
        let bounds = bounds_of(columns, k);
        let near = visit(first + k, &bounds);
        if keep.keep(first + k, &bounds) || near {
            measured.add(&bounds);
            out.bounds = bounds;
        }
    }
    measured
}

/// What [`World::mover_entries`] reads of each body, and of its row.
struct EntryColumns<'a> {
    position: &'a [Vec2],
    angle: &'a [f64],
    layers: &'a [u8],
    shape_id: &'a [u32],
    local_bounds: LocalBoundsRows<'a>,
    start_position: &'a [Vec2],
    shapes: &'a ShapeTable,
    /// Per layer, [`SWEEPS`] and [`SEPARATE_SWEPT`].
    widen: &'a [u8; 256],
}

/// A layer in `sweeping` ([`World::mover_entries`]).
const SWEEPS: u8 = 1;
/// A layer in `separate_swept`.
const SEPARATE_SWEPT: u8 = 2;

impl EntryColumns<'_> {
    /// The columns of `len` bodies from `i` and rows from `r`, indexed from 0.
    #[inline(always)]
    fn slice(&mut self, i: usize, r: usize, len: usize) -> EntryColumns<'_> {
        // Each `[start..][..len]`: the compiler then knows every length is `len`.
        EntryColumns {
            position: &self.position[i..][..len],
            angle: &self.angle[i..][..len],
            layers: &self.layers[i..][..len],
            shape_id: &self.shape_id[i..][..len],
            local_bounds: self.local_bounds.rows(r, len),
            start_position: &self.start_position[r..][..len],
            shapes: self.shapes,
            widen: self.widen,
        }
    }

    /// The broad phase's bounds of body `i`, of row `r`.
    #[inline(always)]
    fn bounds(&mut self, i: usize, r: usize) -> Bounds {
        let widen = self.widen[usize::from(self.layers[i])];
        self.widened(i, r, widen)
    }

    /// [`EntryColumns::bounds`] of a body of a layer whose widening flags are `widen`.
    #[inline(always)]
    fn widened(&mut self, i: usize, r: usize, widen: u8) -> Bounds {
        let p = self.position[i];
        // The shape table is read only when needed (a scene's shapes may all differ).
        let (shapes, ids) = (self.shapes, self.shape_id);
        let shape = || &shapes.get(ids[i]).0;
        // Of the kept bounds, only their half extents when they have some (16 bytes).
        let bounds = self.local_bounds.placed(r, shape, || self.angle[i], p);
        // The frame's start is read only for a layer that may be widened.
        if widen != 0 {
            let moved = self.start_position[r] - p;
            if moved != Vec2::ZERO
                && (widen & SWEEPS != 0 || moved.length() > 0.5 * shape().min_width())
            {
                return bounds.union(bounds.translated(moved));
            }
        }
        bounds
    }
}

/// The moving bodies' entries ([`World::mover_entries`]), kept by the caller from call to
/// call, with the world's layout and count of frozen-bit changes their keys, layers and
/// kinds were written at. While those stay, the keys, layers and kinds do (the
/// layout changes with every body added or removed and every restore, as
/// [`World::count_movers`]' kept answer says), so only the bounds are written: 16 bytes of a
/// body's 48 not read from four columns, and no key made, each frame.
#[derive(Clone, Debug, Default)]
pub(crate) struct MoverEntries {
    list: Vec<BodyEntry>,
    made: Option<(u64, u64)>,
}

impl MoverEntries {
    /// The entries, in [`World::movers`] order.
    pub(crate) fn list(&self) -> &[BodyEntry] {
        &self.list
    }

    /// Sets the bounds of the entries at `places` (a debug build's poison of the places not
    /// made: their keys stay).
    #[cfg(debug_assertions)]
    pub(crate) fn set_bounds(&mut self, places: Range<usize>, bounds: Bounds) {
        for e in &mut self.list[places] {
            e.bounds = bounds;
        }
    }
}

/// [`World::count_movers`]' answer, kept while the bodies and their frozen bits stay.
#[derive(Clone, Debug, Default)]
pub(super) struct KeptCount {
    /// The `layout` and `frozen_changes` it was counted at.
    at: Option<(u64, u64)>,
    /// Each stretch of one layer: its layer, first place, length and dynamic bodies.
    stretches: Vec<(u8, u32, u32, u32)>,
}

impl World {
    /// Counts the moving bodies by layer into `tally`, as the broad phase would count their
    /// entries ([`World::mover_entries`], where a frozen body is kinematic), when they are
    /// one run (`runs.rs`): the layer and kind columns are read in place, one layer's
    /// stretch at a time, instead of every 48-byte entry, and only when a body came, went,
    /// was given another look or had its frozen bit changed since the last count (kind and
    /// layer never change else). Returns whether it counted them (nothing is counted when
    /// they are not one run).
    pub(crate) fn count_movers(&mut self, tally: &mut Tally) -> bool {
        let Some(run) = self.movers_run() else {
            return false;
        };
        let at = (self.layout, self.frozen_changes);
        let kept = &mut self.kept_count;
        if kept.at != Some(at) {
            kept.at = Some(at);
            kept.stretches.clear();
            let (layers, kinds) = (&self.layer[run.indices()], &self.kind[run.indices()]);
            let frozen = &self.rows.frozen[run.rows()];
            let mut start = 0;
            while start < layers.len() {
                let layer = layers[start];
                let end = start + stretch(&layers[start..], layer);
                let dynamic: u32 = (kinds[start..end].iter().zip(&frozen[start..end]))
                    .map(|(&k, &f)| u32::from(k == BodyKind::Dynamic && !f))
                    .sum();
                let stretch = (layer, start as u32, (end - start) as u32, dynamic);
                kept.stretches.push(stretch);
                start = end;
            }
        }
        for &(layer, start, len, dynamic) in &kept.stretches {
            tally.add_run(layer, start, len, dynamic);
        }
        true
    }
}

/// How many of `column`'s first values are `value` (in blocks without an early exit
/// inside, which the compiler vectorises).
fn stretch(column: &[u8], value: u8) -> usize {
    let mut n = 0;
    for block in column.chunks(32) {
        if block.iter().fold(true, |all, &v| all & (v == value)) {
            n += block.len();
        } else {
            return n + block.iter().take_while(|&&v| v == value).count();
        }
    }
    n
}

/// Bounds `b`, relative to a body, placed at `p`.
#[inline]
pub(crate) fn placed(b: Bounds, p: Vec2) -> Bounds {
    // Translating rounds differently from placing the shape at `p` (a rounding or two,
    // each at most half an ulp of these magnitudes): pad by more than that.
    let pad = (p.abs() + b.min.abs().max(b.max.abs())) * 1e-15;
    Bounds {
        min: b.min + p - pad,
        max: b.max + p + pad,
    }
}

#[cfg(test)]
mod tests {
    use super::stretch;

    #[test]
    fn a_stretch_ends_at_the_first_other_value_whatever_block_it_is_in() {
        for len in [0, 1, 31, 32, 33, 64, 100] {
            for end in 0..=len {
                let column: Vec<u8> = (0..len).map(|k| if k < end { 7 } else { 8 }).collect();
                assert_eq!(stretch(&column, 7), end, "{end} of {len}");
            }
        }
        assert_eq!(stretch(&[7, 7, 8, 7, 7], 7), 2);
    }
}
