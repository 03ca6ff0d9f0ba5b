//! The `view` frame on `/tf`: where the shipped layout's camera looks.

use ricochet_geom::Vec2;
use ricochet_log::messages::fox::{FrameTransform, Timestamp};
use ricochet_sim::{Entity, World};

use super::{VIEW, WORLD, vec3, yaw};

/// Where the layout's camera looks: the body the active region follows while it is alive
/// ([`ricochet_sim::Simulation::focus`]), else the centre of the world's bounds, else
/// `fallback` (the centre of the bodies' extent when recording started).
pub fn view_position(
    w: &World,
    focus: Option<Entity>,
    bounds: Option<(Vec2, Vec2)>,
    fallback: Vec2,
) -> Vec2 {
    if let Some(i) = focus.and_then(|e| w.index_of(e)) {
        return w.position[i];
    }
    if let Some((min, max)) = bounds {
        return (min + max) * 0.5;
    }
    fallback
}

/// The centre of the box holding every body's position (the origin with no bodies).
pub fn extent_centre(w: &World) -> Vec2 {
    if w.is_empty() {
        return Vec2::ZERO;
    }
    let (mut lo, mut hi) = (w.position[0], w.position[0]);
    for p in &w.position {
        lo = Vec2::new(lo.x.min(p.x), lo.y.min(p.y));
        hi = Vec2::new(hi.x.max(p.x), hi.y.max(p.y));
    }
    (lo + hi) * 0.5
}

/// The camera's frame at `ts`, child of `world`, upright.
pub fn view_transform(ts: Timestamp, at: Vec2) -> FrameTransform {
    FrameTransform {
        timestamp: Some(ts),
        parent_frame_id: WORLD.to_owned(),
        child_frame_id: VIEW.to_owned(),
        translation: vec3(at.x, at.y, 0.0),
        rotation: yaw(0.0),
    }
}
