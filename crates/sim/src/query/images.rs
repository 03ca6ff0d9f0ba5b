//! The images a query sees in a wrap world: the translations by whole world sizes at which
//! a body's bounds meet a query's region.

use ricochet_geom::{Bounds, Vec2};

use crate::def::WorldBounds;

/// The most images a region query looks at along one axis of a wrap world. A region that
/// spans more world sizes than this along an axis sees the images of the first this many
/// (the least offsets); a query smaller than the world meets at most 2 per axis, 3 for a
/// body sticking out of the world.
pub const MAX_IMAGES_PER_AXIS: i64 = 64;

/// The whole-world-size steps `k` (offset `k * size`) at which `[lo, hi]` translated by
/// `k * size` meets `[qlo, qhi]`, capped at [`MAX_IMAGES_PER_AXIS`].
fn steps(lo: f64, hi: f64, qlo: f64, qhi: f64, size: f64) -> std::ops::RangeInclusive<i64> {
    // lo + k size <= qhi  and  hi + k size >= qlo; padded by a rounding's worth, the exact
    // test follows.
    let pad = 1e-12;
    let first = ((qlo - hi) / size - pad).ceil();
    let last = ((qhi - lo) / size + pad).floor();
    if !(first.is_finite() && last.is_finite()) || first > last {
        return 1..=0;
    }
    let first = first.max(-1e15) as i64;
    let last = (last.min(1e15) as i64).min(first + MAX_IMAGES_PER_AXIS - 1);
    first..=last
}

/// Every offset (whole world sizes, `x` steps then `y` steps ascending) at which `body`
/// translated meets `region`; only `0` (when they meet) outside a wrap world.
pub(crate) fn offsets(
    world: Option<&WorldBounds>,
    body: &Bounds,
    region: &Bounds,
    mut f: impl FnMut(Vec2),
) {
    let Some(w) = world.filter(|w| w.wrap) else {
        if body.overlaps(region) {
            f(Vec2::ZERO);
        }
        return;
    };
    let size = w.size();
    let ys = steps(body.min.y, body.max.y, region.min.y, region.max.y, size.y);
    for kx in steps(body.min.x, body.max.x, region.min.x, region.max.x, size.x) {
        for ky in ys.clone() {
            let o = Vec2::new(kx as f64 * size.x, ky as f64 * size.y);
            if body.translated(o).overlaps(region) {
                f(o);
            }
        }
    }
}
