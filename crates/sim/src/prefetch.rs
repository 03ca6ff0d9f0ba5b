//! Prefetch hints: asking the processor to bring memory into the cache without waiting for
//! it, so that a read that would miss overlaps the work before it. A hint changes no value,
//! so no result and no log depends on it; off x86-64 (aarch64, wasm32) it does nothing.
//!
//! A plain read issued early is no substitute: it must finish before the instructions after
//! it retire, and a miss then stalls the loop it was meant to help. The narrow phase read
//! the shapes two pairs ahead that way, and a tenth of rain-10000's samples (`perf`) stood
//! on that read.
//!
//! `safe_arch` wraps the `prefetcht0` instruction in a safe function: this crate has no
//! `unsafe` of its own.

use ricochet_geom::{Primitive, Shape};

/// Asks for the cache line that holds `value`'s first byte.
#[inline(always)]
pub(crate) fn line_of<T>(value: &T) {
    #[cfg(all(target_arch = "x86_64", target_feature = "sse"))]
    safe_arch::prefetch_t0(value);
    #[cfg(not(all(target_arch = "x86_64", target_feature = "sse")))]
    let _ = value;
}

/// Asks for the lines of `shape`'s first part that its first line may not hold: a part can
/// straddle two lines, and a polygon's vertices, normals and count take up to 264 bytes
/// (five lines), asked for every 64 bytes and at the ends. Reads the shape's kind, so its
/// first line should have been asked for a little before ([`line_of`]), or this read waits
/// for it.
#[inline]
pub(crate) fn rest_of(shape: &Shape) {
    match shape.primitives().first() {
        Some(Primitive::Polygon(p)) => {
            let (vertices, normals, count) = p.storage();
            for array in [vertices, normals] {
                line_of(&array[0]);
                line_of(&array[4]);
            }
            line_of(count);
        }
        Some(Primitive::Circle(c)) => line_of(&c.radius),
        Some(Primitive::Aabb(b)) => line_of(&b.half_extents),
        Some(Primitive::Obb(b)) => line_of(&b.angle),
        Some(Primitive::Capsule(c)) => line_of(&c.radius),
        Some(Primitive::Segment(_)) | None => {}
    }
}
