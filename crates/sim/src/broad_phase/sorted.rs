//! What the broad phase's kept, sorted lists (`sort_and_sweep.rs`, `strips.rs`) share: the
//! integer key of an `f64` coordinate, and the insertion sort that brings a nearly sorted
//! list back in order.

use std::cmp::Ordering;

/// `f64::total_cmp` as an integer: `order_key(a) < order_key(b)` exactly when `a` comes
/// first. `-0.0` comes before `+0.0`, so a query bound is normalised with `+ 0.0` first.
#[inline]
pub(super) fn order_key(x: f64) -> u64 {
    let bits = x.to_bits();
    bits ^ (((bits as i64 >> 63) as u64) | (1 << 63))
}

/// Insertion sort of a nearly sorted list by `cmp` (a total order); `placed(item, index)`
/// hears every item that moves, at its new index. Past `8n + 64` moves it gives up, sorts,
/// and tells `placed` of every item. Returns the moves.
pub(super) fn insertion_sort<T: Copy>(
    order: &mut [T],
    cmp: impl Fn(&T, &T) -> Ordering,
    mut placed: impl FnMut(&T, usize),
) -> u64 {
    let budget = 8 * order.len() as u64 + 64;
    let mut moved = 0;
    for i in 1..order.len() {
        if cmp(&order[i - 1], &order[i]) != Ordering::Greater {
            continue;
        }
        let x = order[i];
        let mut j = i;
        while j > 0 && cmp(&x, &order[j - 1]) == Ordering::Less {
            order[j] = order[j - 1];
            placed(&order[j], j);
            j -= 1;
        }
        order[j] = x;
        placed(&x, j);
        moved += (i - j) as u64;
        if moved > budget {
            order.sort_unstable_by(&cmp);
            for (p, s) in order.iter().enumerate() {
                placed(s, p);
            }
            break;
        }
    }
    moved
}
