//! What a body reaches in a `StripList` (`strip_list.rs`): the strip of its `min.y` and
//! maybe the next ([`Reach`]), and, when that changes from one call to the next, what
//! becomes of its slots ([`Fate`]).

use ricochet_geom::Bounds;

use super::grid::cell_coord;

/// The strips a body reaches: its lower one, and the next one too when `two`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct Reach {
    pub(super) lower: i32,
    pub(super) two: bool,
}

impl Reach {
    /// A reach no body has: a finite coordinate's strip is within `2^30` of 0
    /// (`strip_height.rs` makes `H` at least the largest finite coordinate over `2^30`), and
    /// a box reaching down to `-inf` is infinitely tall (one strip for all) or reaches only
    /// `i32::MIN`.
    pub(super) const NONE: Reach = Reach {
        lower: i32::MIN,
        two: true,
    };

    /// The strips `b` reaches at `1 / H` = `inv_h`. A box with a NaN or inverted `y` range
    /// overlaps nothing, and has its lower slot only.
    #[inline]
    pub(super) fn of(b: &Bounds, inv_h: f64) -> Reach {
        let lower = cell_coord(b.min.y, inv_h);
        // The top's strip, `cell_coord(b.max.y)`, is `lower` or `lower + 1` for every box at
        // most `H` tall (anything else is a box that overlaps nothing: NaN maps to strip 0),
        // so only whether it reaches `lower + 1` is asked: the top against that integer
        // (exact in an `f64`), without a second cast. Nothing reaches past strip `i32::MAX`,
        // as the cast's clamp says; a NaN top (an infinite one at `inv_h = 0`: one strip for
        // all) reaches no other strip, as the cast's NaN to 0 says. `&`, not `&&`: a branch
        // here, on whether a body reaches two strips, was mispredicted often enough to cost
        // rain-10000 7% of its step.
        let ordered = b.min.y <= b.max.y;
        let top = b.max.y * inv_h;
        let two = ordered & (top >= f64::from(lower) + 1.0) & (lower < i32::MAX);
        debug_assert_eq!(
            two,
            ordered && i64::from(cell_coord(b.max.y, inv_h)) == i64::from(lower) + 1,
            "the top's strip, without the cast"
        );
        debug_assert!(
            !ordered || cell_coord(b.max.y, inv_h) == lower || two,
            "H is at least as tall as every body"
        );
        Reach { lower, two }
    }
}

/// What becomes of a moved body's slots when its reach changes from `was` to `now`: a slot
/// in a strip the body still reaches stays where it is (a lower slot that becomes the upper
/// one, or the reverse, has one bit turned: the same strip and key, so the same place in the
/// list up to ties in `min.x`); a slot in a strip it no longer reaches leaves; a strip newly
/// reached gets a fresh slot. A body falling through strips keeps one of its two slots at
/// each crossing, and gets at most one fresh one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Fate {
    /// Two bits for the body's lower slot, then two for its upper one: [`Fate::STAYS`],
    /// [`Fate::TURNS`].
    pub(super) code: u8,
    /// Whether its new lower slot, and its new upper one (if any), are fresh.
    pub(super) new_lower: bool,
    pub(super) new_upper: bool,
}

impl Fate {
    /// The slot stays in the list.
    pub(super) const STAYS: u8 = 1;
    /// The slot's role turns.
    pub(super) const TURNS: u8 = 2;
    /// A body whose reach did not change: both slots stay as they are.
    pub(super) const SAME: u8 = Fate::STAYS | Fate::STAYS << 2;

    /// The two bits of `code` for a body's upper slot when `upper`, else for its lower one.
    #[inline]
    pub(super) fn slot_bits(code: u8, upper: bool) -> u8 {
        code >> (2 * u8::from(upper))
    }

    /// The fate of the slots of a body whose reach changed from `was` ([`Reach::NONE`] for a
    /// body new to the list) to `now`.
    pub(super) fn of(was: Reach, now: Reach) -> Fate {
        // A body new to the list ([`Reach::NONE`]) has no slot.
        let old = was != Reach::NONE;
        let strips = |r: Reach| {
            let lower = i64::from(r.lower);
            (lower, r.two.then_some(lower + 1))
        };
        let ((was_lower, was_upper), (now_lower, now_upper)) = (strips(was), strips(now));
        // An old slot in `strip`: stays if the body still reaches that strip, turning if it
        // does so in the other role.
        let fate = |strip: i64, upper: bool| -> u8 {
            if strip == now_lower {
                Fate::STAYS | if upper { Fate::TURNS } else { 0 }
            } else if Some(strip) == now_upper {
                Fate::STAYS | if upper { 0 } else { Fate::TURNS }
            } else {
                0
            }
        };
        let lower = if old { fate(was_lower, false) } else { 0 };
        let upper = match was_upper {
            Some(strip) if old => fate(strip, true),
            _ => 0,
        };
        let had = |strip: i64| old && (strip == was_lower || Some(strip) == was_upper);
        Fate {
            code: lower | upper << 2,
            new_lower: !had(now_lower),
            new_upper: now_upper.is_some_and(|strip| !had(strip)),
        }
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use ricochet_geom::{Bounds, Vec2};

    use super::{Fate, Reach};

    /// A reach near 0 or at the ends of the strips (`lower + 1` never overflows when `two`).
    fn reach() -> impl Strategy<Value = Reach> {
        prop_oneof![
            (
                prop_oneof![-3..3i32, Just(i32::MIN), Just(i32::MAX - 1)],
                any::<bool>(),
            )
                .prop_map(|(lower, two)| Reach { lower, two }),
            Just(Reach {
                lower: i32::MAX,
                two: false,
            }),
        ]
    }

    /// A box infinitely tall at its top makes the strip infinitely tall (`inv_h = 0`): one
    /// strip for all, and the box reaches no other (its top times `inv_h` is NaN). A box at
    /// `+inf` is in the last strip, and reaches none past it.
    #[test]
    fn infinite_tops_reach_no_strip_that_is_not_there() {
        let tall = Bounds {
            min: Vec2::new(0.0, 2.0),
            max: Vec2::new(1.0, f64::INFINITY),
        };
        let first = Reach {
            lower: 0,
            two: false,
        };
        assert_eq!(Reach::of(&tall, 0.0), first);
        let at_inf = Bounds {
            min: Vec2::new(0.0, f64::INFINITY),
            max: Vec2::new(1.0, f64::INFINITY),
        };
        let last = Reach {
            lower: i32::MAX,
            two: false,
        };
        assert_eq!(Reach::of(&at_inf, 0.125), last);
    }

    proptest! {
        /// A moved body's slots after its fate are its new reach's, each once: the old
        /// slots that stay (in their new role) and the fresh ones, with nothing left over.
        #[test]
        fn a_moved_body_ends_with_exactly_its_new_slots(
            was in prop_oneof![Just(Reach::NONE), reach()],
            now in reach(),
        ) {
            prop_assume!(was != now);
            let fate = Fate::of(was, now);
            // (strip, upper) of each slot.
            let slots = |r: Reach| {
                let mut v = vec![(i64::from(r.lower), false)];
                if r.two {
                    v.push((i64::from(r.lower) + 1, true));
                }
                v
            };
            let mut after = Vec::new();
            if was != Reach::NONE {
                for (strip, upper) in slots(was) {
                    let bits = Fate::slot_bits(fate.code, upper);
                    if bits & Fate::STAYS != 0 {
                        after.push((strip, upper != (bits & Fate::TURNS != 0)));
                    }
                }
            }
            let want = slots(now);
            if fate.new_lower {
                after.push(want[0]);
            }
            if fate.new_upper {
                prop_assert!(now.two, "a fresh upper slot for a body with none");
                after.push(want[1]);
            }
            after.sort_unstable();
            let mut want = want;
            want.sort_unstable();
            prop_assert_eq!(after, want);
        }
    }
}
