//! What the broad phase's kept, sorted lists (`sort_and_sweep.rs`, `strip_list.rs`) share:
//! the integer key of an `f64` coordinate, the insertion sort that brings a nearly sorted
//! list back in order, the galloping search for a place near the start, and the match of a
//! list's bodies with this call's.

use std::cmp::Ordering;

use super::BodyEntry;

/// Walks a list's keys of the last call (`old`, ascending) and this call's bodies (`handles`
/// into `bodies`, key order) together: `kept(i, j)` for a body at place `i` then and `j` now,
/// `new(j, body)` for a body new to the list.
pub(super) fn match_keys(
    old: &[u64],
    handles: &[u32],
    bodies: &[BodyEntry],
    mut kept: impl FnMut(usize, usize),
    mut new: impl FnMut(usize, &BodyEntry),
) {
    let mut i = 0;
    for (j, &h) in handles.iter().enumerate() {
        let b = &bodies[h as usize];
        while i < old.len() && old[i] < b.key {
            i += 1;
        }
        if i < old.len() && old[i] == b.key {
            kept(i, j);
            i += 1;
        } else {
            new(j, b);
        }
    }
}

/// `f64::total_cmp` as an integer: `order_key(a) < order_key(b)` exactly when `a` comes
/// first. `-0.0` comes before `+0.0`, so a query bound is normalised with `+ 0.0` first.
#[inline]
pub(super) fn order_key(x: f64) -> u64 {
    let bits = x.to_bits();
    bits ^ (((bits as i64 >> 63) as u64) | (1 << 63))
}

/// The number whose [`order_key`] is `key`, to the bit.
#[inline]
pub(super) fn from_order_key(key: u64) -> f64 {
    // A key with its top bit set is a number with its sign bit clear, whose key only
    // flipped that bit; the others had every bit flipped.
    let flip = if key >> 63 == 1 { 1 << 63 } else { u64::MAX };
    f64::from_bits(key ^ flip)
}

/// `list.partition_point(pred)` by a galloping search from the start: a step that doubles
/// while the item it lands on still has `pred`, then a binary search in the last step.
/// About `2 log2(answer)` reads, all near the start: where the answer is near (the end of a
/// run of one strip among thousands of slots), a binary search over the whole list would
/// miss the cache at each step.
pub(super) fn gallop<T>(list: &[T], pred: impl Fn(&T) -> bool) -> usize {
    // Every item before `below` has `pred`; the item at `step - 1`, if any, has not.
    let (mut below, mut step) = (0, 1);
    while step <= list.len() && pred(&list[step - 1]) {
        below = step;
        step *= 2;
    }
    let end = (step - 1).min(list.len());
    below + list[below..end].partition_point(pred)
}

/// `list.partition_point(|x| key(x) < t)` for each target `t` of `targets` (`list` sorted
/// by `key`), the `N` searches in lockstep: the same halving steps for all, each a
/// selection, not a branch. One search's steps each wait for the read before; the `N`
/// reads of a step are independent, so their waits overlap. The answer to each is the one
/// place where the keys stop being below it: the same as a search on its own.
#[inline]
pub(super) fn lower_bounds<T, const N: usize>(
    list: &[T],
    key: impl Fn(&T) -> u64,
    targets: [u64; N],
) -> [usize; N] {
    let mut base = [0; N];
    if list.is_empty() {
        return base;
    }
    // Every item before `base[k]` is below `targets[k]`, the answer is within
    // `base[k]..=base[k] + size`, and `base[k] + size <= list.len()`. Whether a key is
    // below a target is a coin toss: each step is a selection the compiler is told is
    // unpredictable (as a plain `if`, or as a product, it made a branch of it).
    let mut size = list.len();
    while size > 1 {
        let half = size / 2;
        for (b, &t) in base.iter_mut().zip(&targets) {
            *b = std::hint::select_unpredictable(key(&list[*b + half]) < t, *b + half, *b);
        }
        size -= half;
    }
    for (b, &t) in base.iter_mut().zip(&targets) {
        *b += usize::from(key(&list[*b]) < t);
    }
    base
}

/// Insertion sort of a nearly sorted list by `cmp` (a total order). Past `8n + 64` moves it
/// gives up and sorts. Returns the moves.
///
/// The next item out of order is found by a scan of adjacent pairs (`windows`, which needs
/// no bounds check), and moved back to its place; the scan goes on after it. Indexing both
/// items of each pair instead cost a bounds check each, twelve instructions an item where
/// the scan takes about half.
pub(super) fn insertion_sort<T: Copy>(order: &mut [T], cmp: impl Fn(&T, &T) -> Ordering) -> u64 {
    let budget = 8 * order.len() as u64 + 64;
    let mut moved = 0;
    // Every item before `from` is in order with the one before it.
    let mut from = 1;
    while from < order.len() {
        let Some(d) = order[from - 1..]
            .windows(2)
            .position(|w| cmp(&w[0], &w[1]) == Ordering::Greater)
        else {
            break;
        };
        let i = from + d;
        let x = order[i];
        let mut j = i;
        while j > 0 && cmp(&x, &order[j - 1]) == Ordering::Less {
            order[j] = order[j - 1];
            j -= 1;
        }
        order[j] = x;
        moved += (i - j) as u64;
        if moved > budget {
            order.sort_unstable_by(&cmp);
            break;
        }
        from = i + 1;
    }
    moved
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::{from_order_key, lower_bounds, order_key};

    proptest! {
        /// The searches in lockstep give each target the place `partition_point` gives it,
        /// in lists of every length (none, one, odd, even) with repeated keys, and for
        /// targets before, among and past the keys.
        #[test]
        fn searches_in_lockstep_give_partition_points(
            mut list in proptest::collection::vec(0u64..40, 0..70),
            targets in proptest::array::uniform4(0u64..45),
        ) {
            list.sort_unstable();
            let want = targets.map(|t| list.partition_point(|&x| x < t));
            prop_assert_eq!(lower_bounds(&list, |&x| x, targets), want);
        }
    }

    proptest! {
        /// `from_order_key` undoes `order_key` to the bit, NaNs and signed zeros included.
        #[test]
        fn a_key_gives_its_number_back(bits in any::<u64>()) {
            let x = f64::from_bits(bits);
            prop_assert_eq!(from_order_key(order_key(x)).to_bits(), bits);
        }
    }

    #[test]
    fn a_key_gives_back_zeros_and_infinities() {
        for x in [
            0.0,
            -0.0,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MIN_POSITIVE,
            -1.5,
        ] {
            assert_eq!(from_order_key(order_key(x)).to_bits(), x.to_bits());
        }
    }
}
