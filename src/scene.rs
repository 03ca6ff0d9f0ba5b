//! Drawing a frame as a `foxglove.SceneUpdate`: every body in the XY plane, filled (cubes for
//! boxes, cylinders for circles, triangle fans for polygons and capsules), contact normals as
//! arrows, and deletions for the bodies removed this frame.

use ricochet_geom::{Primitive, Rot, Shape, Vec2};
use ricochet_log::foxglove::{
    ArrowPrimitive, Color, CubePrimitive, CylinderPrimitive, Point3, Pose, Quaternion, SceneEntity,
    SceneEntityDeletion, SceneUpdate, Timestamp, TriangleListPrimitive, Vector3,
};
use ricochet_sim::{BodyKind, Entity, FrameOutput, World};

/// The frame every entity is drawn in.
pub const FRAME_ID: &str = "world";

/// Thickness of drawn shapes along z, and of outlines.
const DEPTH: f64 = 0.05;

/// The scene entity id of a body, `body/index:generation`: stable for the body's life, and
/// never another body's.
pub fn entity_id(entity: Entity) -> String {
    format!("body/{entity}")
}

/// A colour per layer, from a fixed palette, dimmed for static bodies.
fn color(layer: u8, kind: BodyKind) -> Color {
    const PALETTE: [(f64, f64, f64); 8] = [
        (0.30, 0.69, 0.96),
        (0.96, 0.62, 0.26),
        (0.55, 0.85, 0.40),
        (0.93, 0.35, 0.40),
        (0.75, 0.55, 0.95),
        (0.98, 0.85, 0.30),
        (0.40, 0.85, 0.80),
        (0.85, 0.85, 0.85),
    ];
    let (r, g, b) = PALETTE[usize::from(layer) % PALETTE.len()];
    let a = if kind == BodyKind::Static { 0.5 } else { 0.9 };
    Color::rgba(r, g, b, a)
}

fn p3(v: Vec2) -> Point3 {
    Point3::new(v.x, v.y, 0.0)
}

/// Points around a capsule's outline: a half circle at each end, 8 segments each.
fn capsule_outline(a: Vec2, b: Vec2, r: f64) -> Vec<Point3> {
    let d = b - a;
    let base = if d == Vec2::ZERO {
        0.0
    } else {
        libm::atan2(d.y, d.x)
    };
    let mut pts = Vec::with_capacity(18);
    for (centre, start) in [
        (b, base - std::f64::consts::FRAC_PI_2),
        (a, base + std::f64::consts::FRAC_PI_2),
    ] {
        for k in 0..=8 {
            let t = start + std::f64::consts::PI * f64::from(k) / 8.0;
            let (s, c) = libm::sincos(t);
            pts.push(p3(centre + Vec2::new(c, s) * r));
        }
    }
    pts
}

/// A convex outline, filled: a fan of triangles from its first point (filled like the
/// circles and boxes, where a thin outline was a faint one-pixel line at the layout's zoom).
fn filled(outline: &[Point3], color: Color) -> TriangleListPrimitive {
    let n = outline.len() as u32;
    TriangleListPrimitive {
        pose: Pose::planar(0.0, 0.0, 0.0),
        points: outline.to_vec(),
        color,
        colors: Vec::new(),
        indices: (1..n.saturating_sub(1))
            .flat_map(|k| [0, k, k + 1])
            .collect(),
    }
}

/// Adds the drawing of one primitive of a body at `position`/`angle` to `entity`.
fn draw(
    entity: &mut SceneEntity,
    prim: &Primitive,
    position: Vec2,
    angle: f64,
    rot: Rot,
    color: Color,
) {
    match prim {
        Primitive::Circle(c) => {
            let at = position + rot.apply(c.center);
            entity.cylinders.push(CylinderPrimitive {
                // Foxglove cylinders stand along z: lying in the XY plane needs no turn.
                pose: Pose::planar(at.x, at.y, angle),
                size: Vector3::new(2.0 * c.radius, 2.0 * c.radius, DEPTH),
                bottom_scale: 1.0,
                top_scale: 1.0,
                color,
            });
        }
        Primitive::Aabb(b) => {
            let at = position + rot.apply(b.center);
            entity.cubes.push(CubePrimitive {
                pose: Pose::planar(at.x, at.y, 0.0),
                size: Vector3::new(2.0 * b.half_extents.x, 2.0 * b.half_extents.y, DEPTH),
                color,
            });
        }
        Primitive::Obb(b) => {
            let at = position + rot.apply(b.center);
            entity.cubes.push(CubePrimitive {
                pose: Pose::planar(at.x, at.y, angle + b.angle),
                size: Vector3::new(2.0 * b.half_extents.x, 2.0 * b.half_extents.y, DEPTH),
                color,
            });
        }
        Primitive::Capsule(c) => {
            let (a, b) = (position + rot.apply(c.a), position + rot.apply(c.b));
            // A capsule is convex: its outline fans into triangles like a polygon's.
            entity
                .triangles
                .push(filled(&capsule_outline(a, b, c.radius), color));
        }
        Primitive::Polygon(p) => {
            let pts: Vec<Point3> = p
                .vertices()
                .iter()
                .map(|v| p3(position + rot.apply(*v)))
                .collect();
            entity.triangles.push(filled(&pts, color));
        }
    }
}

fn shape_entity(
    id: String,
    ts: Timestamp,
    shape: &Shape,
    position: Vec2,
    angle: f64,
    color: Color,
) -> SceneEntity {
    let mut e = SceneEntity::new(id, FRAME_ID, ts);
    let rot = Rot::from_angle(angle);
    for prim in shape.primitives() {
        draw(&mut e, prim, position, angle, rot, color);
    }
    e
}

/// The scene update of one frame.
pub fn scene_update(world: &World, out: &FrameOutput, ts: Timestamp) -> SceneUpdate {
    let mut entities = Vec::with_capacity(world.len() + 1);
    for i in 0..world.len() {
        let mut e = shape_entity(
            entity_id(world.entity[i]),
            ts,
            &world.shape[i],
            world.position[i],
            world.angle[i],
            color(world.layer[i], world.kind[i]),
        );
        e.metadata.push(ricochet_log::foxglove::KeyValuePair::new(
            "name",
            world.name[i].clone(),
        ));
        entities.push(e);
    }
    // Contact normals: an arrow from the contact point along the normal, as long as the depth
    // but at least 0.8 units (about 8 px at the layout's zoom; shallow contacts stay visible).
    // Replaced every frame.
    let mut contacts = SceneEntity::new("contacts", FRAME_ID, ts);
    for c in &out.contacts {
        contacts.arrows.push(ArrowPrimitive {
            pose: Pose::new(
                Vector3::new(c.point.x, c.point.y, DEPTH),
                Quaternion::from_yaw(libm::atan2(c.normal.y, c.normal.x)),
            ),
            shaft_length: c.depth.max(0.8),
            shaft_diameter: 0.12,
            head_length: 0.35,
            head_diameter: 0.3,
            color: Color::rgba(1.0, 0.2, 0.2, 1.0),
        });
    }
    entities.push(contacts);
    // A removed body's slot may be reused by a body spawned this frame, under another id
    // (the next generation); deletions are applied before entities anyway.
    let deletions = out
        .removed
        .iter()
        .map(|r| SceneEntityDeletion::matching_id(ts, entity_id(r.entity)))
        .collect();
    SceneUpdate {
        deletions,
        entities,
    }
}
