//! What Foxglove's 3D panel draws: every body in the `world` frame, in few entities, so that
//! a log of 10,000 bodies opens in seconds and a seek shows every body at its exact pose.
//!
//! What the viewer does (Lichtblick 1.10.8, measured with `../shared/viewer`):
//! - on a seek to `t` it takes, per topic, the last message at or before `t`: not per
//!   entity (an entity sent once and never again is gone after a seek);
//! - it keeps a coordinate frame for every frame id it has seen and preloads every
//!   transform of the log: 10,000 body frames froze it;
//! - it draws the cubes and cylinders of one entity as one instanced batch.
//!
//! So:
//! - `/scene` draws the moving bodies and `/scene/static` the static ones, each message whole
//!   (a delete-all, then every entity of its topic): the last message of a topic at any time
//!   is all of its bodies at its last drawing. `/scene` is sent in a frame that draws
//!   (every frame for a small scene: see `pace.rs`) when a moving body moved, turned,
//!   appeared or went since the last drawing, `/scene/static` when a static body did
//!   (usually once);
//! - every entity is in `world`, its primitives placed at the bodies' poses: no frame per
//!   body, no `/tf` for bodies;
//! - [`Style::PerBody`] (scenes of at most [`PER_BODY_LIMIT`] bodies when recording starts):
//!   each body is an entity `body/INDEX:GENERATION`, with its name, id, layer, kind and
//!   velocity as `metadata`, which the 3D panel shows when the body is clicked;
//! - [`Style::Batched`] (larger scenes): a layer's bodies, in id order, fill entities
//!   `LAYER/K` of at most [`CHUNK_PARTS`] body parts each (at most 3 primitives a part:
//!   a capsule draws 3; a polygon's fan joins the entity's one triangle list), so one entity stays a
//!   bounded batch; its metadata names the layer, the body count and the first and last body
//!   id, and the body at a point is found in `/bodies` (or with `ricochet dump`);
//! - `/scene/contacts` draws the frame's contact normals as one red line list in `world`: sent in every
//!   frame that has contacts, and once, empty, after the last.
//!
//! Numbers are drawn at f32 precision (rounded to the nearest `f32`), the precision the
//! viewer renders at: the bytes that would only say more than the screen can show are zero,
//! and compress away. `/bodies` has the exact states.
//!
//! A body's shape is drawn filled: cubes for boxes, cylinders for circles, a cube (the
//! segment's rectangle) and two cylinders for a capsule, and for polygons fans of triangles
//! in the entity's one triangle list, every point in world coordinates.

use ricochet_geom::{Number, Numbers, Primitive, Rot, Vec2};
use ricochet_log::messages::fox::{
    Color, CubePrimitive, CylinderPrimitive, KeyValuePair, LinePrimitive, Point3, Pose, Quaternion,
    SceneEntity, SceneEntityDeletion, SceneUpdate, Timestamp, TriangleListPrimitive, Vector3,
    line_primitive, scene_entity_deletion,
};
use ricochet_sim::{BodyKind, ContactRecord, Entity, Layers, World};

mod encoded;
mod view;
mod wire;

pub use encoded::snapshot_encoded;
pub use view::{extent_centre, view_position, view_transform};

/// The root frame: world coordinates.
pub const WORLD: &str = "world";

/// The frame the shipped layout's camera follows: see [`view_position`].
pub const VIEW: &str = "view";

/// At most this many bodies when recording starts: each body is an entity of its own.
pub const PER_BODY_LIMIT: usize = 256;

/// At most this many body parts in one batched entity (a body is never split; compounds have
/// at most `MAX_COMPOUND_PARTS`, 1024, parts).
pub const CHUNK_PARTS: usize = 1024;

/// Thickness of drawn shapes along z.
const DEPTH: f64 = 0.05;

/// Width of a drawn terrain chain's lines, world units (a chain itself has none).
const CHAIN_THICKNESS: f64 = 0.08;

/// How bodies become entities.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Style {
    /// Each body an entity, with metadata: small scenes.
    PerBody,
    /// Each layer's bodies in entities of at most [`CHUNK_PARTS`] body parts.
    Batched,
}

impl Style {
    /// The style for a scene of `bodies` bodies.
    pub fn for_bodies(bodies: usize) -> Style {
        if bodies <= PER_BODY_LIMIT {
            Style::PerBody
        } else {
            Style::Batched
        }
    }
}

/// The per-body entity id: `body/index:generation`, stable for the body's life, and never
/// another body's.
pub fn entity_id(entity: Entity) -> String {
    format!("body/{entity}")
}

/// `x` at f32 precision: see the module docs.
fn r(x: f64) -> f64 {
    f64::from(x as f32)
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
    let (cr, cg, cb) = PALETTE[usize::from(layer) % PALETTE.len()];
    let a = if kind == BodyKind::Static { 0.5 } else { 0.9 };
    Color {
        r: r(cr),
        g: r(cg),
        b: r(cb),
        a: r(a),
    }
}

fn vec3(x: f64, y: f64, z: f64) -> Option<Vector3> {
    Some(Vector3 {
        x: r(x),
        y: r(y),
        z: r(z),
    })
}

/// A rotation by `yaw` about z.
fn yaw(angle: f64) -> Option<Quaternion> {
    if angle == 0.0 {
        // What `sincos` gives, but for a zero's sign, which proto3 never encodes.
        return Some(Quaternion {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            w: 1.0,
        });
    }
    let (s, c) = libm::sincos(angle / 2.0);
    Some(Quaternion {
        x: 0.0,
        y: 0.0,
        z: r(s),
        w: r(c),
    })
}

fn planar(at: Vec2, angle: f64) -> Option<Pose> {
    Some(Pose {
        position: vec3(at.x, at.y, 0.0),
        orientation: yaw(angle),
    })
}

fn p3(v: Vec2) -> Point3 {
    Point3 {
        x: r(v.x),
        y: r(v.y),
        z: 0.0,
    }
}

/// Where [`draw`] puts a body's primitives: an entity's lists ([`SceneEntity`]), or their
/// encoding (`scene/encoded.rs`). The message is the same either way.
trait Canvas {
    fn cube(&mut self, cube: CubePrimitive);
    fn cylinder(&mut self, cylinder: CylinderPrimitive);
    /// A convex outline, in world coordinates, as a fan of triangles from its first point in
    /// the one triangle list (made in `color` if there is none yet).
    fn fan(&mut self, outline: impl Iterator<Item = Vec2>, color: Color);
    /// A segment, in world coordinates, of the one line list (made in `color` if there is
    /// none yet).
    fn segment(&mut self, a: Vec2, b: Vec2, color: Color);
}

impl Canvas for SceneEntity {
    fn cube(&mut self, cube: CubePrimitive) {
        self.cubes.push(cube);
    }

    fn cylinder(&mut self, cylinder: CylinderPrimitive) {
        self.cylinders.push(cylinder);
    }

    fn fan(&mut self, outline: impl Iterator<Item = Vec2>, color: Color) {
        if self.triangles.is_empty() {
            self.triangles.push(triangle_list(color, &Room::default()));
        }
        let list = &mut self.triangles[0];
        debug_assert_eq!(list.color, Some(color), "one colour a batch");
        let first = list.points.len() as u32;
        list.points.extend(outline.map(p3));
        let n = list.points.len() as u32 - first;
        list.indices.extend(fan_indices(first, n));
    }

    fn segment(&mut self, a: Vec2, b: Vec2, color: Color) {
        if self.lines.is_empty() {
            self.lines.push(line_list(color));
        }
        self.lines[0].points.extend([a, b].map(p3));
    }
}

/// The indices of a fan of triangles over the `n` points from `first`.
fn fan_indices(first: u32, n: u32) -> impl Iterator<Item = u32> {
    (1..n.saturating_sub(1)).flat_map(move |k| [first, first + k, first + k + 1])
}

/// An empty line list (segments, two points each) in `color`: a chain's drawing.
fn line_list(color: Color) -> LinePrimitive {
    LinePrimitive {
        r#type: line_primitive::Type::LineList as i32,
        pose: planar(Vec2::ZERO, 0.0),
        thickness: r(CHAIN_THICKNESS),
        scale_invariant: false,
        points: Vec::new(),
        color: Some(color),
        colors: Vec::new(),
        indices: Vec::new(),
    }
}

/// An entity's one triangle list, empty, in `color`, with room for `room`'s points and
/// indices.
fn triangle_list(color: Color, room: &Room) -> TriangleListPrimitive {
    TriangleListPrimitive {
        pose: planar(Vec2::ZERO, 0.0),
        color: Some(color),
        points: Vec::with_capacity(room.points),
        indices: Vec::with_capacity(room.indices),
        ..Default::default()
    }
}

/// What the drawing of some bodies holds, counted before drawing them so that each of an
/// entity's lists is allocated once, at its size (growing them was a fifth of the time a
/// 10,000-body drawing took).
#[derive(Clone, Copy, Debug, Default)]
struct Room {
    points: usize,
    indices: usize,
    cubes: usize,
    cylinders: usize,
}

impl Room {
    /// Counts what [`draw`] adds for `prim` (a chain's segments, drawn with static bodies
    /// once, are not counted).
    fn add(&mut self, prim: &Primitive) {
        match prim {
            Primitive::Circle(_) => self.cylinders += 1,
            Primitive::Aabb(_) | Primitive::Obb(_) => self.cubes += 1,
            Primitive::Capsule(_) => {
                self.cubes += 1;
                self.cylinders += 2;
            }
            Primitive::Polygon(p) => {
                let n = p.vertices().len();
                self.points += n;
                self.indices += 3 * n.saturating_sub(2);
            }
            Primitive::Segment(_) => {}
        }
    }
}

/// Adds the drawing of one primitive of a body at `at`, turned by `angle`, to `entity`, in
/// world coordinates. An AABB part does not turn: only its centre turns with the body.
/// Polygons and capsules join the entity's one triangle list (one batch for the viewer).
fn draw(canvas: &mut impl Canvas, prim: &Primitive, at: Vec2, angle: f64, color: Color) {
    // The turn is found only for a part off the body's centre: a centred circle is at `at`
    // whatever the angle (but for a zero's sign, which proto3 never encodes), and a sine and
    // cosine per body were a quarter of a big scene's drawing.
    let rot = || Rot::from_angle(angle);
    let place = |v: Vec2| {
        if v == Vec2::ZERO {
            at
        } else {
            at + rot().apply(v)
        }
    };
    match prim {
        Primitive::Circle(c) => canvas.cylinder(CylinderPrimitive {
            // Foxglove cylinders stand along z: lying in the XY plane needs no turn.
            pose: planar(place(c.center), 0.0),
            size: vec3(2.0 * c.radius, 2.0 * c.radius, DEPTH),
            bottom_scale: 1.0,
            top_scale: 1.0,
            color: Some(color),
        }),
        Primitive::Aabb(b) => canvas.cube(CubePrimitive {
            pose: planar(place(b.center), 0.0),
            size: vec3(2.0 * b.half_extents.x, 2.0 * b.half_extents.y, DEPTH),
            color: Some(color),
        }),
        Primitive::Obb(b) => canvas.cube(CubePrimitive {
            pose: planar(place(b.center), angle + b.angle),
            size: vec3(2.0 * b.half_extents.x, 2.0 * b.half_extents.y, DEPTH),
            color: Some(color),
        }),
        // A capsule is its segment's rectangle and a disc at each end: primitives that the
        // viewer draws as instanced batches, in fewer numbers than an outline.
        Primitive::Capsule(c) => {
            let rot = rot();
            let (a, b) = (at + rot.apply(c.a), at + rot.apply(c.b));
            let d = b - a;
            let turn = if d == Vec2::ZERO {
                0.0
            } else {
                libm::atan2(d.y, d.x)
            };
            canvas.cube(CubePrimitive {
                pose: planar((a + b) * 0.5, turn),
                size: vec3(d.length(), 2.0 * c.radius, DEPTH),
                color: Some(color),
            });
            for end in [a, b] {
                canvas.cylinder(CylinderPrimitive {
                    pose: planar(end, 0.0),
                    size: vec3(2.0 * c.radius, 2.0 * c.radius, DEPTH),
                    bottom_scale: 1.0,
                    top_scale: 1.0,
                    color: Some(color),
                });
            }
        }
        Primitive::Polygon(p) => {
            let rot = rot();
            canvas.fan(p.vertices().iter().map(|v| at + rot.apply(*v)), color);
        }
        // A chain segment (zero thickness) is drawn as a line of the entity's one line list.
        Primitive::Segment(s) => {
            let rot = rot();
            canvas.segment(at + rot.apply(s.a), at + rot.apply(s.b), color);
        }
    }
}

fn pair(key: &str, value: String) -> KeyValuePair {
    KeyValuePair {
        key: key.to_owned(),
        value,
    }
}

fn entity(id: String, ts: Timestamp, metadata: Vec<KeyValuePair>) -> SceneEntity {
    SceneEntity {
        timestamp: Some(ts),
        frame_id: WORLD.to_owned(),
        id,
        lifetime: None,
        frame_locked: false,
        metadata,
        ..Default::default()
    }
}

fn kind_name(kind: BodyKind) -> &'static str {
    match kind {
        BodyKind::Static => "static",
        BodyKind::Kinematic => "kinematic",
        BodyKind::Dynamic => "dynamic",
    }
}

/// The whole of one topic at time `ts`: a delete-all, then the static bodies
/// (`statics`) or the moving ones of `w`, as `style` says. [`snapshot_encoded`] gives its
/// encoding, without building it.
pub fn snapshot(
    w: &World,
    layers: &Layers,
    statics: bool,
    style: Style,
    ts: Timestamp,
) -> SceneUpdate {
    let chosen = (0..w.len()).filter(|&i| (w.kind[i] == BodyKind::Static) == statics);
    let entities = match style {
        Style::PerBody => chosen
            .map(|i| {
                let e = w.entity[i];
                let mut metadata = vec![
                    pair("name", w.name(i).to_owned()),
                    pair("id", e.to_string()),
                    pair("layer", layers.name(w.layer[i]).to_owned()),
                    pair("kind", kind_name(w.kind[i]).to_owned()),
                ];
                if !statics {
                    let v = w.velocity(i);
                    metadata.push(pair("velocity", Numbers([v.x, v.y]).to_string()));
                    let spin = Number(w.angular_velocity(i)).to_string();
                    metadata.push(pair("angular_velocity", spin));
                }
                let mut drawn = entity(entity_id(e), ts, metadata);
                draw_body(&mut drawn, w, i);
                drawn
            })
            .collect(),
        Style::Batched => {
            let mut all = Vec::new();
            for_each_batch(w, layers, chosen, |batch| {
                let mut drawn = batch.entity(w, ts);
                let room = batch.room;
                drawn.cubes.reserve_exact(room.cubes);
                drawn.cylinders.reserve_exact(room.cylinders);
                if room.points > 0 {
                    drawn.triangles.push(triangle_list(batch.color(w), &room));
                }
                for &i in batch.bodies {
                    draw_body(&mut drawn, w, i);
                }
                all.push(drawn);
            });
            all
        }
    };
    SceneUpdate {
        deletions: vec![delete_all(ts)],
        entities,
    }
}

/// What removes every entity of a topic before its whole state.
fn delete_all(ts: Timestamp) -> SceneEntityDeletion {
    SceneEntityDeletion {
        timestamp: Some(ts),
        r#type: scene_entity_deletion::Type::All as i32,
        id: String::new(),
    }
}

/// Adds body `i`'s primitives to `canvas`.
fn draw_body(canvas: &mut impl Canvas, w: &World, i: usize) {
    let color = color(w.layer[i], w.kind[i]);
    for prim in w.shape(i).primitives() {
        draw(canvas, prim, w.position[i], w.angle[i], color);
    }
}

/// The bodies of one batched entity, `LAYER/K`.
struct Batch<'a> {
    layer: &'a str,
    k: usize,
    /// In id order; at least one.
    bodies: &'a [usize],
    /// What their drawing holds.
    room: Room,
}

impl Batch<'_> {
    /// The entity, with its metadata and no primitive yet.
    fn entity(&self, w: &World, ts: Timestamp) -> SceneEntity {
        let (first, last) = (self.bodies[0], self.bodies[self.bodies.len() - 1]);
        let metadata = vec![
            pair("layer", self.layer.to_owned()),
            pair("bodies", self.bodies.len().to_string()),
            pair("first", w.entity[first].to_string()),
            pair("last", w.entity[last].to_string()),
        ];
        entity(format!("{}/{}", self.layer, self.k), ts, metadata)
    }

    /// The colour of its triangle list: a batch is of one layer and one side of static.
    fn color(&self, w: &World) -> Color {
        let first = self.bodies[0];
        color(w.layer[first], w.kind[first])
    }
}

/// Calls `f` with the bodies `chosen` (in id order) in batches: each layer's in entities
/// `LAYER/K` of at most [`CHUNK_PARTS`] body parts (a body is never split), by layer, then
/// by `K`.
fn for_each_batch(
    w: &World,
    layers: &Layers,
    chosen: impl Iterator<Item = usize>,
    mut f: impl FnMut(Batch),
) {
    let names = layers.names();
    let mut by_layer: Vec<Vec<usize>> = vec![Vec::new(); names.len()];
    for i in chosen {
        by_layer[usize::from(w.layer[i])].push(i);
    }
    for (name, bodies) in names.iter().zip(&by_layer) {
        let mut rest = bodies.as_slice();
        let mut k = 0;
        while !rest.is_empty() {
            // The batch: bodies while their parts fit (the first one whatever its parts).
            let (mut parts, mut room, mut n) = (0, Room::default(), 0);
            for &i in rest {
                let prims = w.shape(i).primitives();
                if n > 0 && parts + prims.len() > CHUNK_PARTS {
                    break;
                }
                parts += prims.len();
                prims.iter().for_each(|p| room.add(p));
                n += 1;
            }
            let (bodies, after) = rest.split_at(n);
            f(Batch {
                layer: name,
                k,
                bodies,
                room,
            });
            rest = after;
            k += 1;
        }
    }
}

/// The contact normals of a frame: a red segment from each contact point along its normal,
/// as long as the depth but at least 0.8 units (about 8 px at the layout's zoom), all in one
/// line list (one batch for the viewer).
pub fn contact_normals(contacts: &[ContactRecord], ts: Timestamp) -> SceneUpdate {
    let points = contacts
        .iter()
        .flat_map(|c| {
            let tip = c.point + c.normal * c.depth.max(0.8);
            [c.point, tip].map(|p| Point3 {
                z: r(DEPTH),
                ..p3(p)
            })
        })
        .collect();
    let line = LinePrimitive {
        r#type: line_primitive::Type::LineList as i32,
        pose: planar(Vec2::ZERO, 0.0),
        thickness: r(0.12),
        scale_invariant: false,
        points,
        color: Some(Color {
            r: 1.0,
            g: r(0.2),
            b: r(0.2),
            a: 1.0,
        }),
        colors: Vec::new(),
        indices: Vec::new(),
    };
    SceneUpdate {
        deletions: Vec::new(),
        entities: vec![SceneEntity {
            timestamp: Some(ts),
            frame_id: WORLD.to_owned(),
            id: "contacts".to_owned(),
            lines: vec![line],
            ..Default::default()
        }],
    }
}
