//! The push along a contact normal: how `detect` separates a `separate` pair that is not
//! two boxes (those are resolved per axis in `separate.rs`). The dynamic body moves out by
//! the depth (two dynamic bodies half each), and loses its velocity into the other.

use ricochet_geom::Vec2;

use crate::def::BodyKind;
use crate::world::World;

/// Pushes the dynamic body (or both, half each) apart along `normal` (from `i` to `j`), and
/// removes the velocity that drives them into each other. Returns the push on the body that
/// moved (`j`'s when both did).
pub(crate) fn separate_along_normal(
    w: &mut World,
    i: usize,
    j: usize,
    normal: Vec2,
    depth: f64,
) -> Vec2 {
    let (di, dj) = (
        w.kind[i] == BodyKind::Dynamic,
        w.kind[j] == BodyKind::Dynamic,
    );
    let share = if di && dj { 0.5 } else { 1.0 };
    let mut pushed = Vec2::ZERO;
    if di {
        let p = -normal * (depth * share);
        w.position[i] += p;
        let vn = w.velocity(i).dot(normal);
        if vn > 0.0 {
            *w.velocity_mut(i) -= normal * vn;
        }
        if normal.y < -0.7 {
            *w.grounded_mut(i) = true;
            *w.on_static_mut(i) |= w.kind[j] == BodyKind::Static;
        }
        pushed = p;
    }
    if dj {
        let p = normal * (depth * share);
        w.position[j] += p;
        let vn = w.velocity(j).dot(normal);
        if vn < 0.0 {
            *w.velocity_mut(j) -= normal * vn;
        }
        if normal.y > 0.7 {
            *w.grounded_mut(j) = true;
            *w.on_static_mut(j) |= w.kind[i] == BodyKind::Static;
        }
        pushed = p;
    }
    pushed
}
