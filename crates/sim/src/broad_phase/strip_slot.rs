//! A body's place in a `StripList` (`strip_list.rs`): its strip, `min.x` and index packed
//! into one integer whose order is the list's.

use super::strip_reach::Reach;

/// The bit of a slot's `local` field that marks a body's upper slot (indices stay below
/// `2^31`: the broad phase asserts fewer bodies).
const UPPER: u32 = 1 << 31;

/// A body's place in a [`StripList`] (16 bytes, so the insertion sort and the merge move a
/// quarter of what they would with the bounds): `(strip, min.x, local)` packed into one
/// integer whose order is the list order. From the high bits: the strip (`floor(min.y / H)`,
/// clamped, plus one for an upper slot) with its sign bit flipped, `min.x` as
/// [`order_key`], and the body's index in the list's key order with [`UPPER`] on an upper
/// slot, which breaks ties so the order is a function of the input.
///
/// [`StripList`]: super::strip_list::StripList
/// [`order_key`]: super::sorted::order_key
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(super) struct Slot(u128);

impl Slot {
    #[inline]
    pub(super) fn new(strip: i32, x: u64, local: u32) -> Slot {
        let strip = strip as u32 ^ (1 << 31);
        Slot(u128::from(strip) << 96 | u128::from(x) << 32 | u128::from(local))
    }

    /// The slots of a body reaching `reach` with `min.x` at `x` (as `order_key`): its
    /// lower one, then its upper one if any.
    #[inline]
    pub(super) fn both(reach: Reach, x: u64, local: u32) -> (Slot, Option<Slot>) {
        let lower = Slot::new(reach.lower, x, local);
        // Two strips means `lower + 1` did not overflow.
        let upper = reach
            .two
            .then(|| Slot::new(reach.lower + 1, x, local | UPPER));
        (lower, upper)
    }

    /// The slot with `min.x` at `x` instead (its strip and body kept).
    #[inline]
    pub(super) fn at_x(self, x: u64) -> Slot {
        Slot(self.0 & !(u128::from(u64::MAX) << 32) | u128::from(x) << 32)
    }

    #[inline]
    pub(super) fn strip(self) -> i32 {
        ((self.0 >> 96) as u32 ^ (1 << 31)) as i32
    }

    /// The body's index in the list's key order.
    #[inline]
    pub(super) fn local(self) -> u32 {
        self.0 as u32 & !UPPER
    }

    /// The slot of body `local` instead (its strip, key and role kept): the same place for a
    /// body whose index in the list changed.
    #[inline]
    pub(super) fn with_local(self, local: u32) -> Slot {
        Slot((self.0 & !u128::from(!UPPER)) | u128::from(local))
    }

    /// The slot with its role turned (a lower slot made its body's upper one, or the
    /// reverse) when `turn`: the same strip and key.
    #[inline]
    pub(super) fn turned(self, turn: bool) -> Slot {
        Slot(self.0 ^ (u128::from(turn) << 31))
    }

    /// Whether this is the body's lower slot, not its upper one.
    #[inline]
    pub(super) fn is_lower(self) -> bool {
        self.0 as u32 & UPPER == 0
    }

    /// A slot that sorts after every other (a body gone from the list).
    pub(super) const GONE: Slot = Slot(u128::MAX);
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::Slot;
    use crate::broad_phase::sorted::gallop;

    proptest! {
        /// The galloping search ends each run where a scan slot by slot does: runs of one
        /// slot, of a power of two and one either side of it, and one run for all.
        #[test]
        fn a_run_ends_where_a_scan_finds_its_end(
            mut strips in prop::collection::vec(
                prop_oneof![-3..3i32, Just(i32::MIN), Just(i32::MAX)],
                1..300,
            ),
        ) {
            strips.sort_unstable();
            let order: Vec<Slot> = strips
                .iter()
                .enumerate()
                .map(|(k, &s)| Slot::new(s, k as u64, k as u32))
                .collect();
            let mut k = 0;
            while k < order.len() {
                let strip = order[k].strip();
                let scanned = order[k..].iter().take_while(|s| s.strip() == strip).count();
                prop_assert_eq!(gallop(&order[k..], |s| s.strip() == strip), scanned);
                k += scanned;
            }
        }
    }

    /// The galloping search finds where a binary search does: before every slot,
    /// between any two, after all, and on a slot equal to the one looked for.
    #[test]
    fn gallop_finds_where_a_binary_search_does() {
        for len in 0..70u64 {
            let order: Vec<Slot> = (0..len).map(|k| Slot::new(0, 2 * k, 0)).collect();
            for x in 0..2 * len + 2 {
                let f = Slot::new(0, x, 0);
                let want = order.partition_point(|&s| s < f);
                assert_eq!(gallop(&order, |&s| s < f), want, "{x} among {len}");
            }
        }
    }

    #[test]
    fn runs_of_every_length_around_the_doublings() {
        for len in 1..70 {
            for tail in 0..3 {
                let mut order: Vec<Slot> = (0..len).map(|k| Slot::new(5, k, k as u32)).collect();
                order.extend((0..tail).map(|k| Slot::new(6, k, (len + k) as u32)));
                assert_eq!(
                    gallop(&order, |s| s.strip() == 5),
                    len as usize,
                    "{len} then {tail}"
                );
            }
        }
    }
}
