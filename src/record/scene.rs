//! What Foxglove's 3D panel draws, built so that a seek shows every body at its exact pose
//! while each frame costs only the poses that changed.
//!
//! Foxglove, on a seek, takes the last message of each topic at or before the new time, and
//! it preloads every transform of the log. So:
//! - every body has a coordinate frame of its own, `body/INDEX:GENERATION`, child of
//!   `world`, moved on `/tf` (`foxglove.FrameTransforms`) as `motion.rs` decides. It turns
//!   with the body, except for a body with an AABB part (which does not turn): its frame
//!   stays upright and the entity draws the other parts turned;
//! - `/scene` (`foxglove.SceneUpdate`) draws every body in its own frame, `frame_locked`
//!   so it follows its frame; it is sent whole (a delete-all, then every body) when the set
//!   of bodies changes, so its last message at any time is the whole scene then;
//! - `/scene/contacts` draws the frame's contact normals as arrows in `world`: sent in every
//!   frame that has contacts, and once, empty, after the last.
//!
//! A body's shape is drawn filled: cubes for boxes, cylinders for circles, triangle fans for
//! polygons and capsules.

use ricochet_geom::{Primitive, Rot, Shape, Vec2};
use ricochet_log::messages::fox::{
    ArrowPrimitive, Color, CubePrimitive, CylinderPrimitive, FrameTransform, KeyValuePair, Point3,
    Pose, Quaternion, SceneEntity, SceneEntityDeletion, SceneUpdate, Timestamp,
    TriangleListPrimitive, Vector3, scene_entity_deletion,
};
use ricochet_sim::{BodyKind, ContactRecord, Entity};

/// The root frame: world coordinates.
pub const WORLD: &str = "world";

/// Thickness of drawn shapes along z.
const DEPTH: f64 = 0.05;

/// The scene entity id, and the coordinate frame, of a body: `body/index:generation`,
/// stable for the body's life, and never another body's.
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
    Color { r, g, b, a }
}

fn vec3(x: f64, y: f64, z: f64) -> Option<Vector3> {
    Some(Vector3 { x, y, z })
}

/// A rotation by `yaw` about z.
fn yaw(angle: f64) -> Option<Quaternion> {
    let (s, c) = libm::sincos(angle / 2.0);
    Some(Quaternion {
        x: 0.0,
        y: 0.0,
        z: s,
        w: c,
    })
}

fn planar(x: f64, y: f64, angle: f64) -> Option<Pose> {
    Some(Pose {
        position: vec3(x, y, 0.0),
        orientation: yaw(angle),
    })
}

fn p3(v: Vec2) -> Point3 {
    Point3 {
        x: v.x,
        y: v.y,
        z: 0.0,
    }
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

/// A convex outline, filled: a fan of triangles from its first point.
fn filled(outline: Vec<Point3>, color: Color) -> TriangleListPrimitive {
    let n = outline.len() as u32;
    TriangleListPrimitive {
        pose: planar(0.0, 0.0, 0.0),
        points: outline,
        color: Some(color),
        colors: Vec::new(),
        indices: (1..n.saturating_sub(1))
            .flat_map(|k| [0, k, k + 1])
            .collect(),
    }
}

/// Adds the drawing of one primitive to `entity`, in its body's frame turned by `turn`: 0 for
/// a body whose frame turns with it, its angle for an upright one (see [`upright`]).
fn draw(entity: &mut SceneEntity, prim: &Primitive, turn: f64, color: Color) {
    let rot = Rot::from_angle(turn);
    let at = |v: Vec2| rot.apply(v);
    match prim {
        Primitive::Circle(c) => {
            let c0 = at(c.center);
            entity.cylinders.push(CylinderPrimitive {
                // Foxglove cylinders stand along z: lying in the XY plane needs no turn.
                pose: planar(c0.x, c0.y, 0.0),
                size: vec3(2.0 * c.radius, 2.0 * c.radius, DEPTH),
                bottom_scale: 1.0,
                top_scale: 1.0,
                color: Some(color),
            });
        }
        Primitive::Aabb(b) => {
            // Only in an upright frame: an AABB does not turn with its body.
            let c0 = at(b.center);
            entity.cubes.push(CubePrimitive {
                pose: planar(c0.x, c0.y, 0.0),
                size: vec3(2.0 * b.half_extents.x, 2.0 * b.half_extents.y, DEPTH),
                color: Some(color),
            });
        }
        Primitive::Obb(b) => {
            let c0 = at(b.center);
            entity.cubes.push(CubePrimitive {
                pose: planar(c0.x, c0.y, turn + b.angle),
                size: vec3(2.0 * b.half_extents.x, 2.0 * b.half_extents.y, DEPTH),
                color: Some(color),
            });
        }
        Primitive::Capsule(c) => {
            // A capsule is convex: its outline fans into triangles like a polygon's.
            entity
                .triangles
                .push(filled(capsule_outline(at(c.a), at(c.b), c.radius), color));
        }
        Primitive::Polygon(p) => {
            let pts = p.vertices().iter().map(|v| p3(at(*v))).collect();
            entity.triangles.push(filled(pts, color));
        }
    }
}

/// Whether a body's frame stays upright (its `/tf` rotation is none): a shape with an AABB
/// part, which does not turn with its body. Its other parts are drawn turned by the body's
/// angle in the entity itself.
pub fn upright(shape: &Shape) -> bool {
    shape
        .primitives()
        .iter()
        .any(|p| matches!(p, Primitive::Aabb(_)))
}

/// Whether drawing `shape` depends on the body's angle: in an upright frame, every part but a
/// centred AABB turns with the body, so `/scene` is drawn again when such a body turns.
pub fn drawing_depends_on_angle(shape: &Shape) -> bool {
    upright(shape) && !matches!(shape.primitives(), [Primitive::Aabb(b)] if b.center == Vec2::ZERO)
}

/// One body as a scene entity in its own frame.
pub struct BodyDrawing<'a> {
    /// The body.
    pub entity: Entity,
    /// Its name (the entity's `name` metadata).
    pub name: &'a str,
    /// Its shape.
    pub shape: &'a Shape,
    /// Its angle (drawn into the entity only if its frame is [`upright`]).
    pub angle: f64,
    /// Its layer, for the colour.
    pub layer: u8,
    /// Static bodies are dimmed.
    pub kind: BodyKind,
}

/// The whole scene at time `ts`: a delete-all, then every body.
pub fn snapshot<'a>(bodies: impl Iterator<Item = BodyDrawing<'a>>, ts: Timestamp) -> SceneUpdate {
    let entities = bodies
        .map(|b| {
            let id = entity_id(b.entity);
            let mut e = SceneEntity {
                timestamp: Some(ts),
                frame_id: id.clone(),
                id,
                lifetime: None,
                frame_locked: true,
                metadata: vec![KeyValuePair {
                    key: "name".to_owned(),
                    value: b.name.to_owned(),
                }],
                ..Default::default()
            };
            let color = color(b.layer, b.kind);
            let turn = if upright(b.shape) { b.angle } else { 0.0 };
            for prim in b.shape.primitives() {
                draw(&mut e, prim, turn, color);
            }
            e
        })
        .collect();
    SceneUpdate {
        deletions: vec![SceneEntityDeletion {
            timestamp: Some(ts),
            r#type: scene_entity_deletion::Type::All as i32,
            id: String::new(),
        }],
        entities,
    }
}

/// A body's frame at time `ts`: where it is and how it is turned.
pub fn transform(frame: &str, ts: Timestamp, position: Vec2, angle: f64) -> FrameTransform {
    FrameTransform {
        timestamp: Some(ts),
        parent_frame_id: WORLD.to_owned(),
        child_frame_id: frame.to_owned(),
        translation: vec3(position.x, position.y, 0.0),
        rotation: yaw(angle),
    }
}

/// The contact normals of a frame: an arrow from each contact point along its normal, as
/// long as the depth but at least 0.8 units (about 8 px at the layout's zoom).
pub fn contact_arrows(contacts: &[ContactRecord], ts: Timestamp) -> SceneUpdate {
    let arrows = contacts
        .iter()
        .map(|c| ArrowPrimitive {
            pose: Some(Pose {
                position: vec3(c.point.x, c.point.y, DEPTH),
                orientation: yaw(libm::atan2(c.normal.y, c.normal.x)),
            }),
            shaft_length: c.depth.max(0.8),
            shaft_diameter: 0.12,
            head_length: 0.35,
            head_diameter: 0.3,
            color: Some(Color {
                r: 1.0,
                g: 0.2,
                b: 0.2,
                a: 1.0,
            }),
        })
        .collect();
    SceneUpdate {
        deletions: Vec::new(),
        entities: vec![SceneEntity {
            timestamp: Some(ts),
            frame_id: WORLD.to_owned(),
            id: "contacts".to_owned(),
            arrows,
            ..Default::default()
        }],
    }
}
