//! `detect`'s call of the broad phase with the moving bodies: their entries made from the
//! world's columns, counted, and paired. When the movers are one run and sort and sweep's
//! filter takes a big layer (an asteroid field met by a ship and its bullets), that layer is
//! left out of the entries but for its bodies near a small one
//! (`broad_phase/left_out.rs`): its 48-byte entries, written and read back every frame,
//! were a third of the asteroids' step. The pairs, and everything counted, are the same
//! either way.

use std::ops::Range;

use ricochet_geom::Bounds;

use crate::broad_phase::{BodyEntry, BroadPhase, BroadPhaseStats, Extent, Interactions};
use crate::world::{MoverEntries, World};

/// What the broad phase is given of the moving bodies.
pub(crate) struct MoverCall<'a> {
    pub(crate) world: &'a mut World,
    pub(crate) broad_phase: &'a mut BroadPhase,
    /// The layers in `sweeping` and in `separate_swept` ([`World::mover_entries`]).
    pub(crate) widen: (&'a [bool], &'a [bool]),
    /// The static bodies and their generation.
    pub(crate) statics: (&'a [BodyEntry], u64),
    pub(crate) interactions: &'a Interactions,
    /// The entries, made here.
    pub(crate) movers: &'a mut MoverEntries,
}

/// Makes the moving bodies' entries (each shown to `visit`, which says whether its entry
/// is read again after the call) and finds their pairs, as handles, into `out`. Returns the
/// call's stats and the places whose entries were not all made (empty when every one was).
pub(crate) fn mover_pairs(
    call: MoverCall,
    mut visit: impl FnMut(usize, &Bounds) -> bool,
    out: &mut Vec<(u32, u32)>,
) -> (BroadPhaseStats, Range<usize>) {
    let MoverCall {
        world: w,
        broad_phase: bp,
        widen,
        statics: (statics, generation),
        interactions,
        movers,
    } = call;
    let measure = bp.wants_extent();
    // Counted from the world's columns when it can (one run of movers), else from the
    // entries.
    let mut tally = bp.tally();
    if !w.count_movers(&mut tally) {
        let extent = every_entry(w, widen, movers, visit, measure);
        tally.count(movers.list());
        if let Some(extent) = extent {
            bp.give_extent(extent);
        }
        let movers = movers.list();
        let stats = bp.pairs_counted_handles(statics, generation, movers, interactions, out);
        return (stats, 0..0);
    }
    tally.flush();
    bp.load_statics(statics, generation);
    let Some((big, places)) = bp.layer_to_leave_out(interactions) else {
        if let Some(extent) = every_entry(w, widen, movers, visit, measure) {
            bp.give_extent(extent);
        }
        let movers = movers.list();
        let stats = bp.pairs_counted_handles(statics, generation, movers, interactions, out);
        return (stats, 0..0);
    };
    let () = w.mover_entries(widen, movers, places.clone(), &mut visit);
    #[cfg(debug_assertions)]
    check_and_poison(w, bp, widen, movers, places.clone());
    bp.begin_counted(movers.list(), interactions);
    let left_out = match bp.big_pass(big, movers.list(), interactions) {
        Some(mut pass) => {
            w.some_mover_entries(widen, movers, places.clone(), visit, Some(&mut pass));
            let enough = pass.finish();
            if !enough {
                w.some_mover_entries(widen, movers, places.clone(), |_, _| false, None);
            }
            enough
        }
        None => {
            w.some_mover_entries(widen, movers, places.clone(), visit, None);
            false
        }
    };
    let stats = bp.finish_counted(movers.list(), interactions, out);
    (stats, if left_out { places } else { 0..0 })
}

/// Every mover's entry ([`World::mover_entries`]), and when `measure`
/// ([`BroadPhase::wants_extent`]), their [`Extent`].
fn every_entry(
    w: &mut World,
    widen: (&[bool], &[bool]),
    movers: &mut MoverEntries,
    visit: impl FnMut(usize, &Bounds) -> bool,
    measure: bool,
) -> Option<Extent> {
    if measure {
        Some(w.mover_entries(widen, movers, 0..0, visit))
    } else {
        let () = w.mover_entries(widen, movers, 0..0, visit);
        None
    }
}

/// In a debug build, where a layer is left out: checks the count against every entry
/// (made aside), and fills the left-out places with NaN bounds, which pair with nothing, so
/// that a read of an entry not made shows as a pair missed.
#[cfg(debug_assertions)]
fn check_and_poison(
    w: &mut World,
    bp: &BroadPhase,
    widen: (&[bool], &[bool]),
    movers: &mut MoverEntries,
    places: Range<usize>,
) {
    let mut every = MoverEntries::default();
    let () = w.mover_entries(widen, &mut every, 0..0, |_, _| false);
    let (list, every) = (movers.list(), every.list());
    for k in (0..list.len()).filter(|k| !places.contains(k)) {
        assert_eq!(list[k], every[k], "entry {k}");
    }
    bp.check_counted(every);
    let nan = ricochet_geom::Vec2::splat(f64::NAN);
    movers.set_bounds(places, Bounds { min: nan, max: nan });
}
