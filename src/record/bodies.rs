//! What changed since the previous frame, body by body: the `/bodies` deltas, the `/tf`
//! transforms to send and whether `/scene` must be sent whole again.
//!
//! Values are compared by their bits, so a change of sign of a zero, or any NaN, is a change.

use ricochet_geom::{ShapeDef, Vec2};
use ricochet_log::messages::fox::{FrameTransform, Timestamp};
use ricochet_log::messages::ricochet as pb;
use ricochet_sim::{BodyKind, Entity, FrameOutput, Layers, RemovedBody, World};

use super::scene;

/// `/bodies` lists every body in full every this many frames (and at frame 0).
pub const KEYFRAME_INTERVAL: u64 = 60;

/// What was last recorded of a body alive at the end of the previous frame.
struct Known {
    generation: u32,
    position: Vec2,
    angle: f64,
    velocity: Vec2,
    angular_velocity: f64,
    /// Its frame's name, `body/index:generation`.
    frame_id: String,
    /// The last frame a transform of it was sent in.
    transform_frame: u64,
    /// Its drawing turns back by its angle (an AABB part): a turn redraws the scene.
    drawn_with_angle: bool,
    /// The frame it was last seen in the world.
    seen: u64,
}

fn same(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits()
}

fn same2(a: Vec2, b: Vec2) -> bool {
    same(a.x, b.x) && same(a.y, b.y)
}

fn xy(v: Vec2) -> Vec<f64> {
    vec![v.x, v.y]
}

/// The shape as `/bodies` writes it.
pub fn shape_message(def: &ShapeDef) -> pb::Shape {
    use pb::shape::Kind;
    let kind = match def {
        ShapeDef::Circle { radius, center } => Kind::Circle(pb::Circle {
            radius: *radius,
            center: center.to_vec(),
        }),
        ShapeDef::Aabb {
            half_extents,
            center,
        } => Kind::Aabb(pb::Box {
            half_extents: half_extents.to_vec(),
            center: center.to_vec(),
            angle: 0.0,
        }),
        ShapeDef::Obb {
            half_extents,
            center,
            angle,
        } => Kind::Obb(pb::Box {
            half_extents: half_extents.to_vec(),
            center: center.to_vec(),
            angle: *angle,
        }),
        ShapeDef::Capsule {
            a,
            b,
            radius,
            center,
        } => Kind::Capsule(pb::Capsule {
            a: vec![a[0] + center[0], a[1] + center[1]],
            b: vec![b[0] + center[0], b[1] + center[1]],
            radius: *radius,
        }),
        ShapeDef::Polygon { vertices, center } => Kind::Polygon(pb::Polygon {
            vertices: vertices
                .iter()
                .flat_map(|v| [v[0] + center[0], v[1] + center[1]])
                .collect(),
        }),
        ShapeDef::Compound { parts } => Kind::Compound(pb::Compound {
            parts: parts.iter().map(shape_message).collect(),
        }),
    };
    pb::Shape { kind: Some(kind) }
}

/// A removed body, with every field: its last state.
pub fn removed_message(r: &RemovedBody, layers: &Layers) -> pb::Body {
    pb::Body {
        id: r.entity.index,
        generation: r.entity.generation,
        name: Some(r.name.clone()),
        layer: Some(layers.name(r.layer).to_owned()),
        shape: Some(shape_message(&ShapeDef::from_shape(&r.shape))),
        r#static: Some(r.kind == BodyKind::Static),
        position: xy(r.pose.position),
        angle: Some(r.pose.angle),
        velocity: xy(r.velocity),
        angular_velocity: None,
    }
}

/// One frame's changes.
pub struct Changes {
    /// `/bodies`.
    pub bodies: pb::Bodies,
    /// `/tf`: the transforms of the bodies that appeared or moved.
    pub transforms: Vec<FrameTransform>,
    /// `/scene` must be sent whole: a body appeared or went, or an AABB body turned.
    pub scene_changed: bool,
}

/// The last recorded state of every body, by slot.
#[derive(Default)]
pub struct Tracker {
    known: Vec<Option<Known>>,
    alive: usize,
    started: bool,
}

impl Tracker {
    /// The changes of frame `out.frame` (its world is `world`). `dt_ns` is the step.
    pub fn frame(
        &mut self,
        world: &World,
        out: &FrameOutput,
        layers: &Layers,
        dt_ns: u64,
        want_bodies: bool,
    ) -> Changes {
        let frame = out.frame;
        let ts = ricochet_log::messages::timestamp(frame * dt_ns);
        let before: Timestamp = ricochet_log::messages::timestamp(frame.saturating_sub(1) * dt_ns);
        let keyframe = !self.started || frame.is_multiple_of(KEYFRAME_INTERVAL);
        let mut scene_changed = !self.started || !out.removed.is_empty();
        self.started = true;
        let mut bodies = Vec::new();
        let mut transforms = Vec::new();
        for i in 0..world.len() {
            let e: Entity = world.entity[i];
            let (position, angle) = (world.position[i], world.angle[i]);
            let (velocity, angular_velocity) = (world.velocity[i], world.angular_velocity[i]);
            let slot = e.index as usize;
            if self.known.len() <= slot {
                self.known.resize_with(slot + 1, || None);
            }
            let fresh = !matches!(&self.known[slot], Some(k) if k.generation == e.generation);
            if fresh {
                if self.known[slot].is_none() {
                    self.alive += 1;
                }
                scene_changed = true;
                let frame_id = scene::entity_id(e);
                transforms.push(scene::transform(&frame_id, ts, position, angle));
                self.known[slot] = Some(Known {
                    generation: e.generation,
                    position,
                    angle,
                    velocity,
                    angular_velocity,
                    frame_id,
                    transform_frame: frame,
                    drawn_with_angle: scene::drawing_depends_on_angle(&world.shape[i]),
                    seen: frame,
                });
            }
            let Some(k) = self.known[slot].as_mut() else {
                continue;
            };
            k.seen = frame;
            let moved = !same2(k.position, position);
            let turned = !same(k.angle, angle);
            let sped = !same2(k.velocity, velocity);
            let spun = !same(k.angular_velocity, angular_velocity);
            if !fresh && (moved || turned) {
                if k.transform_frame + 1 < frame {
                    // Foxglove interpolates between a frame's transforms: the pose it had
                    // since its last transform is sent again just before it changes.
                    transforms.push(scene::transform(&k.frame_id, before, k.position, k.angle));
                }
                transforms.push(scene::transform(&k.frame_id, ts, position, angle));
                k.transform_frame = frame;
                if turned && k.drawn_with_angle {
                    scene_changed = true;
                }
            }
            let full = keyframe || fresh;
            if want_bodies && (full || moved || turned || sped || spun) {
                let mut b = pb::Body {
                    id: e.index,
                    generation: e.generation,
                    ..Default::default()
                };
                if full {
                    b.name = Some(world.name[i].clone());
                    b.layer = Some(layers.name(world.layer[i]).to_owned());
                    b.shape = Some(shape_message(&ShapeDef::from_shape(&world.shape[i])));
                    b.r#static = Some(world.kind[i] == BodyKind::Static);
                }
                if full || moved {
                    b.position = xy(position);
                }
                if full || turned {
                    b.angle = Some(angle);
                }
                if full || sped {
                    b.velocity = xy(velocity);
                }
                if full || spun {
                    b.angular_velocity = Some(angular_velocity);
                }
                bodies.push(b);
            }
            k.position = position;
            k.angle = angle;
            k.velocity = velocity;
            k.angular_velocity = angular_velocity;
        }
        if self.alive != world.len() {
            // Some bodies went (removed, or despawned between frames): forget them.
            for slot in &mut self.known {
                if slot.as_ref().is_some_and(|k| k.seen != frame) {
                    *slot = None;
                    self.alive -= 1;
                    scene_changed = true;
                }
            }
        }
        let removed = if want_bodies {
            out.removed
                .iter()
                .map(|r| removed_message(r, layers))
                .collect()
        } else {
            Vec::new()
        };
        Changes {
            bodies: pb::Bodies {
                frame,
                time: 0.0,
                keyframe,
                bodies,
                removed,
            },
            transforms,
            scene_changed,
        }
    }
}
