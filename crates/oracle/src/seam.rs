//! The wrap seam as the referee sees it: in a world with `bounds` and `wrap = true`, a pair
//! also meets through the edges, `b` translated by whole world sizes
//! ([`WorldBounds::image_offsets`]) next to `a`. Ricochet logs such a contact with `b`'s
//! image as `pose_b`, and takes the deepest translation (the earliest touch for a swept
//! pair), the first in the offsets' order (the direct one first) on a tie. The referee
//! gives rapier a collider for each image, and checks the choice with parry.
//!
//! What the logged poses show is the rule: the referee judges a pair with both bodies
//! wrapped into the world first (its own wrap of each pose, [`Seam::wrapped`]), however far
//! out Ricochet's detect poses are. Inside the world a body sticks out by at most half its
//! width, so the translations by `-1, 0, 1` sizes reach every overlap of a body narrower
//! than the world.

use ricochet_geom::{Bounds, Pose, Shape, Vec2};
use ricochet_sim::{Scenario, WorldBounds};

use crate::OracleError;
use crate::convert::depth;

/// The translations of `b` a pair is tested at: the direct one alone in a world that does
/// not wrap, else [`WorldBounds::image_offsets`] (direct first).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Seam {
    offsets: Vec<Vec2>,
    /// The world's bounds when it wraps.
    bounds: Option<WorldBounds>,
}

impl Seam {
    /// The seam of `scenario`'s world.
    pub(crate) fn new(scenario: &Scenario) -> Seam {
        let bounds = scenario.world.bounds.filter(|b| b.wrap);
        let offsets = match bounds {
            Some(b) => b.image_offsets().to_vec(),
            None => vec![Vec2::ZERO],
        };
        Seam { offsets, bounds }
    }

    /// `pose` with its position wrapped into the world, `[min, max)` on each axis (the pose
    /// itself in a world that does not wrap, or already inside).
    pub(crate) fn wrapped(&self, pose: &Pose) -> Pose {
        let Some(b) = self.bounds else {
            return *pose;
        };
        let mut p = pose.position;
        for axis in 0..2 {
            let (lo, hi) = (b.min[axis], b.max[axis]);
            if p[axis] < lo || p[axis] >= hi {
                // The remainder is exact; only adding `lo` back rounds, possibly onto `hi`.
                let q = lo + (p[axis] - lo).rem_euclid(hi - lo);
                p[axis] = if q < hi { q } else { lo };
            }
        }
        Pose::new(p, pose.angle)
    }

    /// The translations, direct first.
    pub(crate) fn offsets(&self) -> &[Vec2] {
        &self.offsets
    }

    /// The translations of `b` a swept pair is cast at, direct first, then by `x` steps and
    /// `y` steps ascending: [`Seam::offsets`] while the two paths' bounds (`path_a`, widened
    /// by the caller, and `path_b`) meet within one world size on each axis, else every
    /// whole-size translation at which they meet (a path longer than the world passes
    /// several images). More than [`MAX_PATH_IMAGES`] is an error: not refereed.
    pub(crate) fn along(&self, path_a: &Bounds, path_b: &Bounds) -> Result<Vec<Vec2>, OracleError> {
        let Some(world) = self.bounds else {
            return Ok(self.offsets.clone());
        };
        let size = world.size();
        // Steps `k` with `path_b + k size` meeting `path_a` on each axis.
        let steps = |axis: usize| {
            let first = ((path_a.min[axis] - path_b.max[axis]) / size[axis]).ceil();
            let last = ((path_a.max[axis] - path_b.min[axis]) / size[axis]).floor();
            (first, last)
        };
        let ((x0, x1), (y0, y1)) = (steps(0), steps(1));
        if x0 >= -1.0 && x1 <= 1.0 && y0 >= -1.0 && y1 <= 1.0 {
            return Ok(self.offsets.clone());
        }
        let n = (x1 - x0 + 1.0).max(0.0) * (y1 - y0 + 1.0).max(0.0);
        if n > MAX_PATH_IMAGES as f64 {
            return Err(OracleError::Unsupported(format!(
                "a swept path through {n:e} world images (more than {MAX_PATH_IMAGES})"
            )));
        }
        let mut out = vec![Vec2::ZERO];
        let mut kx = x0;
        while kx <= x1 {
            let mut ky = y0;
            while ky <= y1 {
                if kx != 0.0 || ky != 0.0 {
                    out.push(Vec2::new(kx * size.x, ky * size.y));
                }
                ky += 1.0;
            }
            kx += 1.0;
        }
        Ok(out)
    }

    /// The world's size when it wraps.
    pub(crate) fn size(&self) -> Option<Vec2> {
        self.bounds.map(|b| b.size())
    }

    /// Whether the world wraps.
    pub(crate) fn wraps(&self) -> bool {
        self.offsets.len() > 1
    }

    /// The offset that takes `pose` exactly (the same addition as Ricochet's) to `image`.
    pub(crate) fn offset_to(&self, pose: &Pose, image: &Pose) -> Option<Vec2> {
        self.offsets
            .iter()
            .copied()
            .find(|&o| moved(pose, o) == *image)
    }

    /// Parry's depth of `a` and `b`, both [wrapped](Seam::wrapped) into the world, at each
    /// translation of `b`: the deepest, and its offset (the first on a tie; `-inf` at the
    /// direct one when all are further apart than `prediction`).
    pub(crate) fn deepest(
        &self,
        a: &Shape,
        pa: &Pose,
        b: &Shape,
        pb: &Pose,
        prediction: f64,
    ) -> Result<(f64, Vec2), OracleError> {
        let (pa, pb) = (&self.wrapped(pa), &self.wrapped(pb));
        let mut best = (f64::NEG_INFINITY, Vec2::ZERO);
        for &o in &self.offsets {
            if o != Vec2::ZERO && !near(a, pa, b, &moved(pb, o), prediction) {
                continue;
            }
            let d = depth(a, pa, b, &moved(pb, o), prediction)?;
            if d > best.0 {
                best = (d, o);
            }
        }
        Ok(best)
    }
}

/// The most translations the referee casts one swept pair at (a path through more world
/// images is reported, not refereed): a 256 x 256 block of world sizes.
pub(crate) const MAX_PATH_IMAGES: usize = 1 << 16;

/// `pose` translated by `offset` (the pose itself for the direct one), as Ricochet
/// translates it.
pub(crate) fn moved(pose: &Pose, offset: Vec2) -> Pose {
    if offset == Vec2::ZERO {
        *pose
    } else {
        Pose::new(pose.position + offset, pose.angle)
    }
}

/// Whether the two shapes' bounds, widened by `margin`, overlap: a translation that fails
/// this is not worth a parry query.
pub(crate) fn near(a: &Shape, pa: &Pose, b: &Shape, pb: &Pose, margin: f64) -> bool {
    widened(a.bounds(pa), margin).overlaps(&b.bounds(pb))
}

/// `b` grown by `margin` (plus a relative rounding margin) on every side.
pub(crate) fn widened(b: Bounds, margin: f64) -> Bounds {
    let m = margin.max(0.0) + 1e-9 * (1.0 + b.min.abs().max(b.max.abs()).max_element());
    Bounds {
        min: b.min - Vec2::splat(m),
        max: b.max + Vec2::splat(m),
    }
}
