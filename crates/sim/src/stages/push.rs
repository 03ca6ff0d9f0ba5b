//! The push along a contact normal: how `detect` separates a `separate` pair that is not
//! two boxes (those are resolved per axis in `separate.rs`). The dynamic body moves out by
//! the depth (two dynamic bodies half each), and loses its velocity into the other.
//!
//! Statics win. A push between two dynamic bodies never moves either into a static body it
//! `separate`s from (deeper than it already was, or more than [`SLOP`]), nor through one:
//! each body's push is clipped by the static bodies near its path ([`Statics`]), Box2D- and
//! rapier-style (a static body has infinite mass). A body that hits a static surface stops
//! flush on it and slides along it with what is left of its push; the part of the depth it
//! could not take goes to the other body (itself clipped). So a pile of bodies that all start
//! at one point spreads out above a floor instead of squeezing some through it. A
//! kinematic body's push is not clipped: both are unstoppable, and the dynamic body between
//! them is left where the push puts it (as the per-axis pass leaves a crushed box).

use ricochet_geom::{Shape, Sweep, Vec2, contact, time_of_impact};

use crate::broad_phase::FixedGrid;
use crate::def::{BodyKind, Layers, Response};
use crate::stages::SLOP;
use crate::stages::obstacles::static_index;
use crate::stages::slope::{self, Climb};
use crate::world::World;

/// How many times a clipped push is checked against the static bodies again before it is
/// given up (the body stays where it is). A push is clipped by a surface, then slides along
/// it; a second surface (a corner) clips the slide; a third round confirms.
const CLIP_ROUNDS: usize = 4;

/// The static bodies a dynamic-dynamic push is clipped by: those of layers that `separate`
/// from some layer, in a grid built the first time a pass needs it after the static bodies
/// changed (a scene whose pushes are all against statics never builds it).
#[derive(Debug, Default, Clone)]
pub(crate) struct Statics {
    /// The static generation `grid` was built at.
    generation: Option<u64>,
    /// Each static body's bounds, with its rank among the static bodies and its layer.
    grid: FixedGrid,
    /// A lookup's static bodies near a path, as dense indices, ascending.
    found: Vec<u32>,
}

impl Statics {
    /// Rebuilds the grid if the static bodies changed.
    pub(crate) fn refresh(&mut self, w: &World, layers: &Layers) {
        if self.generation == Some(w.static_generation()) {
            return;
        }
        self.generation = Some(w.static_generation());
        let n = layers.names().len();
        let separating: Vec<bool> = (0..n)
            .map(|l| (0..n).any(|m| layers.response(l as u8, m as u8) == Response::Separate))
            .collect();
        let mut entries = Vec::new();
        let mut rank = 0;
        for i in 0..w.len() {
            if w.kind[i] != BodyKind::Static {
                continue;
            }
            if separating[usize::from(w.layer[i])] {
                entries.push((w.shape(i).bounds(&w.pose(i)), rank, w.layer[i]));
            }
            rank += 1;
        }
        self.grid = FixedGrid::new(&entries);
    }

    /// The static bodies the last [`Statics::near`] found, as dense indices, ascending.
    pub(crate) fn found(&self) -> &[u32] {
        &self.found
    }

    /// Into `found`, the static bodies whose bounds meet `q` and that body `i` `separate`s
    /// from, in id order (after [`Statics::refresh`]).
    pub(crate) fn near(&mut self, w: &World, layers: &Layers, i: usize, q: &ricochet_geom::Bounds) {
        self.found.clear();
        let (movers, layer, found) = (w.movers(), w.layer[i], &mut self.found);
        self.grid.query(q, |s, _, l| {
            if layers.response(layer, l) == Response::Separate {
                found.push(static_index(movers, s));
            }
        });
        self.found.sort_unstable();
    }

    /// What is left of push `p` on dynamic body `i` once the static bodies near its path
    /// have clipped it: the body stops flush at the first static surface it would meet and
    /// slides along it, and never goes deeper into a static body it already overlaps than it
    /// is (or than [`SLOP`]). `Vec2::ZERO` when no clipped push can be found that holds.
    fn clip(&mut self, w: &World, layers: &Layers, i: usize, mut p: Vec2) -> Vec2 {
        if p == Vec2::ZERO {
            return p;
        }
        let (shape, from, angle) = (w.shape(i), w.position[i], w.angle[i]);
        let at = |x: Vec2| ricochet_geom::Pose::new(x, angle);
        // Every place the push can reach, slid or not (a slide is never longer than `p`).
        let mut region = shape.bounds(&at(from));
        region.min -= Vec2::splat(p.length());
        region.max += Vec2::splat(p.length());
        self.near(w, layers, i, &region);
        if self.found.is_empty() {
            return p;
        }
        for _ in 0..CLIP_ROUNDS {
            let mut clipped = false;
            for &s in &self.found {
                let s = s as usize;
                let (other, pose_s) = (w.shape(s), w.pose(s));
                let before = contact(shape, &at(from), other, &pose_s);
                let after = contact(shape, &at(from + p), other, &pose_s);
                if before.depth > SLOP {
                    // Already inside (landed this frame, its own push comes later in the
                    // pass): it may leave or slide, never go deeper.
                    let into = p.dot(before.normal);
                    if into > 0.0 {
                        clipped |= into > SLOP;
                        p -= before.normal * into;
                    } else if after.depth > before.depth + SLOP {
                        return Vec2::ZERO;
                    }
                    continue;
                }
                let reach = 0.5 * (shape.min_width() + other.min_width());
                if after.depth <= SLOP && p.length() <= reach {
                    // Ends outside, and too short a push to have gone through.
                    continue;
                }
                let Some(hit) = touch(shape, from, p, angle, other, &pose_s) else {
                    if after.depth > SLOP {
                        return Vec2::ZERO;
                    }
                    continue;
                };
                // Flush at the touch, then along the surface with the rest.
                let n = hit.normal;
                let rest = p * (1.0 - hit.t);
                let into = rest.dot(n).max(0.0);
                let slid = p * hit.t + (rest - n * into);
                // A graze (a touch it slides past) changes the push by rounding only.
                clipped |= (slid - p).length() > SLOP;
                p = slid;
            }
            if !clipped {
                return p;
            }
        }
        Vec2::ZERO
    }
}

/// Where a body of `shape` at `from` moving by `p` first touches a static `other`: the
/// fraction of the push and the contact normal there.
fn touch(
    shape: &Shape,
    from: Vec2,
    p: Vec2,
    angle: f64,
    other: &Shape,
    pose: &ricochet_geom::Pose,
) -> Option<Touch> {
    let sweep = Sweep {
        start: from,
        end: from + p,
        angle,
    };
    let fixed = Sweep {
        start: pose.position,
        end: pose.position,
        angle: pose.angle,
    };
    let hit = time_of_impact(shape, &sweep, other, &fixed)?;
    Some(Touch {
        t: hit.t,
        normal: hit.contact.normal,
    })
}

/// A path's first touch of a static body.
struct Touch {
    /// The fraction of the path.
    t: f64,
    /// The contact normal there, from the moving body to the static one.
    normal: Vec2,
}

/// Pushes the dynamic body (or both, half each) apart along `normal` (from `i` to `j`), and
/// removes the velocity that drives them into each other. Two dynamic bodies' pushes are
/// clipped by `statics` (statics win, see the module docs). Returns the push on the body
/// that moved (`j`'s when both did).
/// A controlled body (`runner`, `walker`) on a sloped surface is lifted or stopped instead
/// (`slope.rs`, by the world's `climb`).
pub(crate) fn separate_along_normal(
    w: &mut World,
    statics: Option<(&mut Statics, &Layers)>,
    (i, j): (usize, usize),
    (normal, depth): (Vec2, f64),
    climb: Climb,
) -> Vec2 {
    if let Some(s) = slope::surface(w, i, j, -normal, climb) {
        return slope::stand(w, (i, j), -normal, depth, s);
    }
    if let Some(s) = slope::surface(w, j, i, normal, climb) {
        return slope::stand(w, (j, i), normal, depth, s);
    }
    let (di, dj) = (
        w.kind[i] == BodyKind::Dynamic,
        w.kind[j] == BodyKind::Dynamic,
    );
    let (mut pi, mut pj) = (Vec2::ZERO, Vec2::ZERO);
    match statics {
        Some((statics, layers)) if di && dj => {
            statics.refresh(w, layers);
            let half = depth * 0.5;
            let (want_i, want_j) = (-normal * half, normal * half);
            pi = statics.clip(w, layers, i, want_i);
            pj = statics.clip(w, layers, j, want_j);
            // What one could not take along the normal, the other takes (itself clipped).
            // Unclipped pushes are kept bit for bit: exactly the half each they always were.
            let short = |got: Vec2, want: Vec2| {
                if got == want {
                    0.0
                } else {
                    (want - got).dot(want) / half
                }
            };
            let (short_i, short_j) = (short(pi, want_i), short(pj, want_j));
            if short_i > SLOP && short_j <= SLOP {
                pj = statics.clip(w, layers, j, normal * (half + short_i));
            } else if short_j > SLOP && short_i <= SLOP {
                pi = statics.clip(w, layers, i, -normal * (half + short_j));
            }
        }
        _ => {
            let share = if di && dj { 0.5 } else { 1.0 };
            if di {
                pi = -normal * (depth * share);
            }
            if dj {
                pj = normal * (depth * share);
            }
        }
    }
    let mut pushed = Vec2::ZERO;
    if di {
        *w.position_mut(i) += pi;
        let vn = w.velocity(i).dot(normal);
        if vn > 0.0 {
            *w.velocity_mut(i) -= normal * vn;
        }
        if normal.y < -0.7 {
            *w.grounded_mut(i) = true;
            *w.on_static_mut(i) |= w.kind[j] == BodyKind::Static;
        }
        pushed = pi;
    }
    if dj {
        *w.position_mut(j) += pj;
        let vn = w.velocity(j).dot(normal);
        if vn < 0.0 {
            *w.velocity_mut(j) -= normal * vn;
        }
        if normal.y > 0.7 {
            *w.grounded_mut(j) = true;
            *w.on_static_mut(j) |= w.kind[i] == BodyKind::Static;
        }
        pushed = pj;
    }
    pushed
}
