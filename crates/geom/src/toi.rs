//! Time of impact: the first moment two shapes moving in straight lines come within a hair
//! of touching.

use crate::collide::compound;
use crate::{Bounds, Contact, Pose, Primitive, Shape, Vec2, contact};

/// How close the search must get, relative to the smaller shape's size.
const TOI_TOLERANCE: f64 = 1e-9;

/// A shape's motion over one step: a straight line from `start` to `end` at a fixed
/// `angle` (rotation during the step is not swept).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sweep {
    /// Position at `t = 0`.
    pub start: Vec2,
    /// Position at `t = 1`.
    pub end: Vec2,
    /// Angle throughout, radians.
    pub angle: f64,
}

impl Sweep {
    /// The pose at `t` in `[0, 1]`: `start + (end - start) * t`.
    #[must_use]
    pub fn pose_at(&self, t: f64) -> Pose {
        Pose::new(self.start + (self.end - self.start) * t, self.angle)
    }
}

/// Where and when two swept shapes first touch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Impact {
    /// The moment, in `[0, 1]`.
    pub t: f64,
    /// The exact contact of the two shapes at the poses below (depth about zero: touching).
    pub contact: Contact,
    /// `a`'s pose at `t`.
    pub pose_a: Pose,
    /// `b`'s pose at `t`.
    pub pose_b: Pose,
}

/// The first moment `t` in `[0, 1]` when shape `a` moving along `sweep_a` and shape `b`
/// moving along `sweep_b` come within `1e-9` times the smaller shape's size of touching
/// (sizes measured at the end poses), with the contact and poses there. `None` when they
/// stay further apart than that for the whole step. Shapes that already overlap at `t = 0`
/// touch at `0`.
///
/// Each pair of convex parts is searched on its own, and the earliest touch wins. With the
/// angles fixed, the signed distance between two convex parts is a convex function of `t`
/// (the distance from a point moving on a line to a convex set), which makes the search
/// exact: conservative advancement first (distance ÷ relative speed can never step past the
/// first touch, and is quick when heading straight in); if that crawls, as on a grazing
/// path, a golden-section search finds the closest approach, and bisection the first
/// moment before it within the tolerance.
///
/// Two shapes whose discs (`Shape::reach`) stay apart by more than the tolerance for the
/// whole step never come within it: `None` at once, before any part is placed.
#[must_use]
pub fn time_of_impact(a: &Shape, sweep_a: &Sweep, b: &Shape, sweep_b: &Sweep) -> Option<Impact> {
    let size = |s: &Shape, w: &Sweep| s.bounds(&Pose::new(w.end, w.angle)).half_extents().length();
    let tol = TOI_TOLERANCE * size(a, sweep_a).min(size(b, sweep_b));
    if crate::reach::paths_beyond_reach((a, sweep_a), (b, sweep_b), tol) {
        return None;
    }
    searched(a, sweep_a, b, sweep_b, tol)
}

/// [`time_of_impact`] by the search alone, at tolerance `tol`.
pub(crate) fn searched(
    a: &Shape,
    sweep_a: &Sweep,
    b: &Shape,
    sweep_b: &Sweep,
    tol: f64,
) -> Option<Impact> {
    let (sa, sb) = (sweep_a.start, sweep_b.start);
    let (da, db) = (sweep_a.end - sa, sweep_b.end - sb);
    let speed = (da - db).length();
    let poses = |t: f64| {
        (
            Pose::new(sa + da * t, sweep_a.angle),
            Pose::new(sb + db * t, sweep_b.angle),
        )
    };
    let mut first: Option<f64> = None;
    let mut search = |pa: &Primitive, pb: &Primitive| {
        // A chain segment alone, without its joint rule: the first touch of the chain is the
        // earliest of its segments' as lines (a convex gap), whichever segment then answers
        // for the contact's normal (`contact` of the whole shapes, below).
        let (part_a, part_b) = (Shape::Primitive(bare(*pa)), Shape::Primitive(bare(*pb)));
        let gap = |t: f64| {
            let (pa, pb) = poses(t);
            -contact(&part_a, &pa, &part_b, &pb).depth
        };
        if let Some(t) = first_touch(gap, speed, tol)
            && first.is_none_or(|f| t < f)
        {
            first = Some(t);
        }
    };
    let (parts_a, parts_b) = (a.primitives(), b.primitives());
    if parts_a.len() * parts_b.len() <= compound::ALL_PAIRS {
        for pa in parts_a {
            for pb in parts_b {
                search(pa, pb);
            }
        }
    } else {
        // Part pairs whose swept boxes stay apart by more than the tolerance never come
        // within it: only the others are searched (the earliest touch is the same).
        let (ba, bb) = (swept(parts_a, sweep_a, sa), swept(parts_b, sweep_b, sa));
        let reach = tol + compound::margin(&ba, &bb);
        compound::near_pairs(&ba, &bb, reach, |i, j| search(&parts_a[i], &parts_b[j]));
    }
    let t = first?;
    let (pose_a, pose_b) = poses(t);
    Some(Impact {
        t,
        contact: contact(a, &pose_a, b, &pose_b),
        pose_a,
        pose_b,
    })
}

/// A chain segment without its neighbours; any other part as it is.
fn bare(p: Primitive) -> Primitive {
    match p {
        Primitive::Segment(s) => Primitive::Segment(crate::shape::Segment {
            prev: None,
            next: None,
            ..s
        }),
        other => other,
    }
}

/// The box each part of a shape sweeps over the step (the union of its boxes at both ends:
/// it moves on a line at a fixed angle), relative to `origin`.
fn swept(parts: &[Primitive], sweep: &Sweep, origin: Vec2) -> Vec<Bounds> {
    parts
        .iter()
        .map(|p| {
            let part = Shape::Primitive(*p);
            let at = |position: Vec2| part.bounds(&Pose::new(position - origin, sweep.angle));
            at(sweep.start).union(at(sweep.end))
        })
        .collect()
}

/// The first `t` in `[0, 1]` with `gap(t) <= tol`, for a convex `gap` that changes at most
/// `speed` per unit of `t`.
fn first_touch(gap: impl Fn(f64) -> f64, speed: f64, tol: f64) -> Option<f64> {
    let mut t = 0.0;
    let mut g = gap(t);
    for _ in 0..16 {
        if g <= tol {
            return Some(t);
        }
        if speed == 0.0 {
            return None;
        }
        t += g / speed;
        if t > 1.0 {
            return None;
        }
        g = gap(t);
    }
    if g <= tol {
        return Some(t);
    }
    // Closest approach on [t, 1] (a convex function is unimodal).
    const INV_PHI: f64 = 0.618_033_988_749_894_8;
    let (mut lo, mut hi) = (t, 1.0);
    for _ in 0..80 {
        let m1 = hi - (hi - lo) * INV_PHI;
        let m2 = lo + (hi - lo) * INV_PHI;
        if gap(m1) <= gap(m2) {
            hi = m2;
        } else {
            lo = m1;
        }
    }
    let closest = 0.5 * (lo + hi);
    if gap(closest) > tol {
        return None;
    }
    // The gap falls from above tol at t to at most tol at `closest`: bisect the crossing.
    let (mut above, mut below) = (t, closest);
    for _ in 0..80 {
        let mid = 0.5 * (above + below);
        if gap(mid) > tol {
            above = mid;
        } else {
            below = mid;
        }
    }
    Some(below)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn circle(radius: f64) -> Shape {
        Shape::circle(radius).unwrap()
    }

    fn sweep(start: (f64, f64), end: (f64, f64)) -> Sweep {
        Sweep {
            start: Vec2::new(start.0, start.1),
            end: Vec2::new(end.0, end.1),
            angle: 0.0,
        }
    }

    #[test]
    fn two_circles_closing_head_on_touch_when_the_gap_is_closed() {
        // Radii 1 and 1, centres 10 apart closing at 20 units per step: the gap of 8 closes
        // at t = 8 / 20 = 0.4, with the centres at 4 and 6.
        let hit = time_of_impact(
            &circle(1.0),
            &sweep((0.0, 0.0), (10.0, 0.0)),
            &circle(1.0),
            &sweep((10.0, 0.0), (0.0, 0.0)),
        )
        .expect("they meet");
        assert!((hit.t - 0.4).abs() < 1e-15, "{}", hit.t);
        assert!((hit.pose_a.position.x - 4.0).abs() < 1e-12);
        assert!((hit.pose_b.position.x - 6.0).abs() < 1e-12);
        assert!(hit.contact.depth.abs() < 1e-12, "{}", hit.contact.depth);
        assert_eq!(hit.contact.normal, Vec2::new(1.0, 0.0));
    }

    /// A circle of radius 0.5 flying from x = -10 to x = 10 at `height` past a circle of
    /// radius 1 resting at the origin.
    fn fly_past(height: f64) -> Option<Impact> {
        time_of_impact(
            &circle(0.5),
            &sweep((-10.0, height), (10.0, height)),
            &circle(1.0),
            &sweep((0.0, 0.0), (0.0, 0.0)),
        )
    }

    #[test]
    fn a_grazing_circle_touches_where_the_line_passes_at_the_radii_sum() {
        // At height 1.2 (< 1.5) it touches where x^2 + 1.2^2 = 1.5^2, x = -0.9, i.e. at
        // t = (10 - 0.9) / 20.
        let hit = fly_past(1.2).expect("it touches");
        let exact = (10.0 - 0.9) / 20.0;
        assert!((hit.t - exact).abs() < 1e-9, "{} vs {exact}", hit.t);
    }

    #[test]
    fn shapes_that_pass_apart_never_touch_and_overlapping_ones_touch_at_zero() {
        assert_eq!(fly_past(1.6), None);
        let box_shape = Shape::aabb(Vec2::new(1.0, 1.0)).unwrap();
        let now = time_of_impact(
            &box_shape,
            &sweep((0.0, 0.0), (5.0, 0.0)),
            &circle(1.0),
            &sweep((1.5, 0.0), (1.5, 0.0)),
        )
        .expect("already overlapping");
        assert_eq!(now.t, 0.0);
        assert!((now.contact.depth - 0.5).abs() < 1e-12);
    }
}
