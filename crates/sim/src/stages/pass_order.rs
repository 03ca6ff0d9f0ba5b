//! The order in which a per-axis pass settles its dynamic boxes (`separate.rs`): lowest
//! coordinate along the axis first, ties by dense index, kept from one frame to the next.
//!
//! Boxes move a little each frame, so last frame's order along an axis is nearly this
//! frame's: an insertion sort from it moves a box only past the few it overtook (a walker
//! passing another, a box falling past a floor of standing ones), where a sort from scratch
//! compares every box `log n` times. The keys are unique (the index breaks ties), so any
//! starting order sorts to the same list, bit for bit the order a full sort gives. When the
//! insertion sort has to move boxes far (the moving bodies changed, a box wrapped round the
//! world), it gives up after a few moves a box and the list is sorted from scratch.

/// One box to settle: its lowest coordinate along the axis, its dense index, and its place
/// among the moving bodies ([`crate::World::movers`]) when the order was made.
pub(crate) type Entry = (f64, u32, u32);

/// A pass's order along one axis, kept between frames.
#[derive(Debug, Default, Clone)]
pub(crate) struct PassOrder {
    /// The moving bodies (dense indices) when `last` was made: a place is an index into it.
    movers: Vec<u32>,
    /// Last pass's places, in order.
    last: Vec<u32>,
    /// Per place: this pass's key, and whether the box settles (1) or is already listed (2).
    keys: Vec<f64>,
    state: Vec<u8>,
}

/// Whether `a` settles before `b`: the lower coordinate, then the lower index.
#[inline]
fn before(a: &Entry, b: &Entry) -> bool {
    a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).is_lt()
}

impl PassOrder {
    /// Into `out`, the boxes `settles` picks among `movers` (the world's moving bodies), in
    /// order: `settles(place, index)` is the box's key when it settles this pass.
    pub(crate) fn sort(
        &mut self,
        movers: &[u32],
        mut settles: impl FnMut(usize, u32) -> Option<f64>,
        out: &mut Vec<Entry>,
    ) {
        if self.movers != movers {
            // New places: last frame's order says nothing about them.
            self.movers.clear();
            self.movers.extend_from_slice(movers);
            self.last.clear();
        }
        let n = movers.len();
        self.keys.resize(n, 0.0);
        self.state.resize(n, 0);
        let (keys, state) = (&mut self.keys[..n], &mut self.state[..n]);
        for (k, ((&i, key), s)) in movers
            .iter()
            .zip(keys.iter_mut())
            .zip(state.iter_mut())
            .enumerate()
        {
            (*key, *s) = settles(k, i).map_or((0.0, 0), |x| (x, 1));
        }
        out.clear();
        out.reserve(n);
        // Last pass's boxes that still settle, in last pass's order, then the new ones.
        for &k in &self.last {
            let k = k as usize;
            if state[k] == 1 {
                state[k] = 2;
                out.push((keys[k], movers[k], k as u32));
            }
        }
        let kept = out.len();
        for (k, (&s, &key)) in state.iter().zip(keys.iter()).enumerate() {
            if s == 1 {
                out.push((key, movers[k], k as u32));
            }
        }
        let budget = 4 * out.len() + 64;
        if kept == 0 || !insertion_sort(out, budget) {
            // Unstable is the same order: no two keys are equal.
            out.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        }
        self.last.clear();
        self.last.extend(out.iter().map(|e| e.2));
    }
}

/// Sorts `v` by insertion, unless that takes more than `budget` moves: then `false`, with
/// `v` some permutation of what it held.
fn insertion_sort(v: &mut [Entry], budget: usize) -> bool {
    let mut moves = 0;
    for k in 1..v.len() {
        if !before(&v[k], &v[k - 1]) {
            continue;
        }
        let e = v[k];
        let mut at = k;
        while at > 0 && before(&e, &v[at - 1]) {
            v[at] = v[at - 1];
            at -= 1;
        }
        v[at] = e;
        moves += k - at;
        if moves > budget {
            return false;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    /// The order a sort from scratch gives.
    fn sorted(mut v: Vec<Entry>) -> Vec<Entry> {
        v.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        v
    }

    proptest! {
        #[test]
        fn the_kept_order_is_the_sorted_order_frame_after_frame(
            frames in proptest::collection::vec(
                proptest::collection::vec((prop_oneof![Just(0.5), -50.0..50.0f64], any::<bool>()), 40),
                1..6,
            ),
            movers_change in any::<bool>(),
        ) {
            let mut order = PassOrder::default();
            let mut out = Vec::new();
            for (f, boxes) in frames.iter().enumerate() {
                // Every other body moves; some frames drop the last one from the movers.
                let n = if movers_change && f % 2 == 1 { boxes.len() - 1 } else { boxes.len() };
                let movers: Vec<u32> = (0..n as u32).map(|k| 2 * k + 1).collect();
                order.sort(&movers, |k, _| boxes[k].1.then_some(boxes[k].0), &mut out);
                let expected: Vec<Entry> = (0..n)
                    .filter(|&k| boxes[k].1)
                    .map(|k| (boxes[k].0, movers[k], k as u32))
                    .collect();
                prop_assert_eq!(&out, &sorted(expected));
            }
        }
    }

    #[test]
    fn a_reversed_order_is_sorted_from_scratch() {
        let mut order = PassOrder::default();
        let mut out = Vec::new();
        let movers: Vec<u32> = (0..200).collect();
        order.sort(&movers, |k, _| Some(k as f64), &mut out);
        // Every box overtakes every other: 19,900 moves by insertion, over the budget.
        let mut reversed: Vec<Entry> = out.iter().rev().copied().collect();
        assert!(!insertion_sort(&mut reversed, 4 * 200 + 64));
        order.sort(&movers, |k, _| Some(-(k as f64)), &mut out);
        let expected: Vec<Entry> = (0..200u32).rev().map(|k| (-f64::from(k), k, k)).collect();
        assert_eq!(out, expected);
    }
}
