//! Swept pairs whose path over the frame is two or more world sizes long, in a wrapping
//! world (a bullet faster than the world a frame): the images of `b` that the pair's
//! relative motion meets are walked **in time order**, and the walk stops as soon as no
//! image left can touch before the earliest hit found. The cost of a pair is then the
//! images until its first hit, not the length of its path (issue #34: a path of 1e13
//! world sizes cast 4,096 images a pair, half a minute a frame).
//!
//! **Which images.** `b + o` (`o` whole world sizes) can touch `a` at `t` in `[0, 1]` only
//! when their bounds overlap on both axes at `t` (each axis gives a window of `t`), and
//! when the centre of `b + o` relative to `a`'s, `c + o + t d`, is within the two bodies'
//! bounding radii: both are tested in closed form for each image, and the later of the two
//! entry times is a lower bound of any touch through the image. Along the path, the `x`
//! steps' windows start later and later (so do the `y` steps' within one `x` step): once
//! one starts after the earliest hit, so do all the rest.
//!
//! **Bounds.** At most [`MAX_PATH_IMAGES`] images are looked at per pair (each a few
//! arithmetic operations), the first along the path; a path longer than that is not
//! looked at beyond them. At most [`MAX_FRAME_PATH_CASTS`] times of impact are cast per
//! frame through such images, for all pairs together. Past that budget an image is not
//! cast: the first one whose bounds and bounding circles meet before the earliest hit is
//! taken as the hit, at the moment the bounding circles first touch (never a missed
//! contact, possibly a touch the exact shapes would not have made, logged with the exact
//! contact of the shapes at that moment, whose depth may be below zero). So a frame costs
//! at most `MAX_FRAME_PATH_CASTS` casts and `MAX_PATH_IMAGES` cheap tests per swept pair,
//! whatever the speeds.
//!
//! The result is the one casting every image listed would give: the earliest touch, the
//! direct one on a tie, then the first by `x` step, then `y` step.

use ricochet_geom::{Bounds, Impact, Pose, Shape, Sweep, Vec2, contact, time_of_impact};

use crate::def::WorldBounds;

/// At most this many images of `b` are looked at for one swept pair whose path is longer
/// than the world: those the path meets first. A longer path (a body faster than about
/// this many world sizes a frame along one axis, or one that meets this many images
/// without a hit) is not followed beyond them.
pub(crate) const MAX_PATH_IMAGES: usize = 4096;

/// At most this many times of impact are cast per frame through the images of long paths,
/// for all swept pairs together (a cast is a few microseconds: about 10 ms a frame at
/// most). A pair's first hit comes within a few images when the path sweeps the world
/// densely, so a scene needs this many only when it holds hundreds of pairs of bodies
/// faster than the world; past it, images are taken by their bounding circles (module docs).
pub(crate) const MAX_FRAME_PATH_CASTS: u64 = 4096;

/// What the frame has left of [`MAX_FRAME_PATH_CASTS`].
#[derive(Debug)]
pub(crate) struct CastBudget(u64);

impl CastBudget {
    /// A frame's whole budget.
    pub(crate) fn new() -> CastBudget {
        CastBudget(MAX_FRAME_PATH_CASTS)
    }
}

/// The distance from `p` of the furthest corner of `b`: a radius about `p` that holds `b`.
fn radius(b: &Bounds, p: Vec2) -> f64 {
    (b.min - p).abs().max((b.max - p).abs()).length()
}

/// The earliest touch of `a` moving along `sa` and the images of `b` moving along `sb`
/// that their path meets, when it is two or more world sizes long on an axis: then
/// `first` (the direct cast's result) is replaced by an earlier touch through an image,
/// each cast counted in `casts`, and `true`. `false` (nothing done) when every image the
/// path meets is within one world size, where the seam's images serve.
pub(crate) fn earliest(
    world: &WorldBounds,
    (a, sa): (&Shape, &Sweep),
    (b, sb): (&Shape, &Sweep),
    first: &mut Option<Impact>,
    budget: &mut CastBudget,
    casts: &mut u64,
) -> bool {
    let size = world.size();
    let ba = a.bounds(&Pose::new(sa.start, sa.angle));
    let bb = b.bounds(&Pose::new(sb.start, sb.angle));
    let d = (sb.end - sb.start) - (sa.end - sa.start);
    let (lo, hi) = (bb.min - ba.max, bb.max - ba.min);
    let scale = lo.abs().max(hi.abs()).max(d.abs()).max(size).max_element();
    // Whether the path is long: the `x` (or `y`) steps whose bounds meet for some `t` in
    // `[0, 1]`, widened by a generous rounding margin.
    let steps = |axis: usize, t0: f64, t1: f64, pad: f64| -> (f64, f64) {
        let (m0, m1) = (t0 * d[axis], t1 * d[axis]);
        let first = ((-hi[axis] - m0.max(m1) - pad) / size[axis]).ceil();
        let last = ((-lo[axis] - m0.min(m1) + pad) / size[axis]).floor();
        (first, last)
    };
    let wide = 1e-9 * (1.0 + scale);
    let within = |(first, last): (f64, f64)| first >= -1.0 && last <= 1.0;
    if within(steps(0, 0.0, 1.0, wide)) && within(steps(1, 0.0, 1.0, wide)) {
        return false;
    }
    // The images themselves are tested with a tighter margin: 2^-46 of the largest
    // magnitude (64 units in the last place), far above the rounding of `c + o + t d` and of
    // the cast's translated positions.
    let pad =
        (1.0 + scale.max(sa.start.abs().max(sb.start.abs()).max_element())) / (1u64 << 46) as f64;
    let (ra, rb) = (radius(&ba, sa.start), radius(&bb, sb.start));
    // A cast reports a touch within 1e-9 of the smaller size (`time_of_impact`).
    let reach = (ra + rb) * (1.0 + 1e-6) + pad;
    let c = sb.start - sa.start;
    let length = d.length();
    // The window of `t` in `[t0, t1]` where the bounds of `b + o` meet `a`'s on `axis`.
    let window = |axis: usize, o: f64, (t0, t1): (f64, f64)| -> (f64, f64) {
        if d[axis] == 0.0 {
            let meets = lo[axis] + o - pad <= 0.0 && 0.0 <= hi[axis] + o + pad;
            return if meets { (t0, t1) } else { (1.0, 0.0) };
        }
        let (p, q) = (
            (-hi[axis] - o - pad) / d[axis],
            (-lo[axis] - o + pad) / d[axis],
        );
        (p.min(q).max(t0), p.max(q).min(t1))
    };
    // When the centre of `b + o` first comes within `reach` of `a`'s, if it does.
    let circle = |o: Vec2| -> Option<f64> {
        let c = c + o;
        if length == 0.0 {
            return (c.length() <= reach).then_some(0.0);
        }
        let u = d / length;
        let (along, across) = (c.dot(u), c.perp_dot(u));
        if across.abs() > reach {
            return None;
        }
        let half = (reach * reach - across * across).sqrt();
        let (enter, exit) = (-along - half, -along + half);
        (exit >= 0.0 && enter <= length).then(|| enter.max(0.0) / length)
    };
    // Along the relative path first: `o` falls as `t` grows when `d > 0`.
    let ordered = |(first, last): (f64, f64), d: f64| {
        let n = if last >= first {
            (last - first + 1.0).min(MAX_PATH_IMAGES as f64) as usize
        } else {
            0
        };
        (0..n).map(move |m| {
            if d > 0.0 {
                last - m as f64
            } else {
                first + m as f64
            }
        })
    };
    let image = Sweep {
        start: sb.start,
        end: sb.end,
        angle: sb.angle,
    };
    // The key of the image a hit is through: `None` (the direct one) before any.
    let mut key: Option<(f64, f64)> = None;
    let mut looked = 0;
    'x: for kx in ordered(steps(0, 0.0, 1.0, pad), d.x) {
        let ox = kx * size.x;
        let (t0, t1) = window(0, ox, (0.0, 1.0));
        if t0 > t1 {
            continue;
        }
        if first.as_ref().is_some_and(|f| t0 > f.t) {
            break;
        }
        for ky in ordered(steps(1, t0, t1, pad), d.y) {
            if looked == MAX_PATH_IMAGES {
                break 'x;
            }
            looked += 1;
            let o = Vec2::new(ox, ky * size.y);
            let (u0, u1) = window(1, o.y, (t0, t1));
            if u0 > u1 || (kx == 0.0 && ky == 0.0) {
                continue;
            }
            if first.as_ref().is_some_and(|f| u0 > f.t) {
                break;
            }
            let Some(enter) = circle(o).map(|t| t.max(u0)) else {
                continue;
            };
            if enter > u1 || first.as_ref().is_some_and(|f| enter > f.t) {
                continue;
            }
            let moved = Sweep {
                start: image.start + o,
                end: image.end + o,
                ..image
            };
            let hit = if budget.0 > 0 {
                budget.0 -= 1;
                *casts += 1;
                time_of_impact(a, sa, b, &moved)
            } else {
                let (pose_a, pose_b) = (sa.pose_at(enter), moved.pose_at(enter));
                Some(Impact {
                    t: enter,
                    contact: contact(a, &pose_a, b, &pose_b),
                    pose_a,
                    pose_b,
                })
            };
            let k = (kx, ky);
            let earlier = |h: &Impact| match first.as_ref() {
                None => true,
                Some(f) => {
                    h.t < f.t
                        || (h.t == f.t
                            && key.is_some_and(|q| {
                                k.0.total_cmp(&q.0).then(k.1.total_cmp(&q.1)).is_lt()
                            }))
                }
            };
            if let Some(h) = hit
                && earlier(&h)
            {
                *first = Some(h);
                key = Some(k);
            }
        }
    }
    true
}
