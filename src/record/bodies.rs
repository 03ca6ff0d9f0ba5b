//! What changed since the previous frame, body by body: the `/bodies` deltas, the `/tf`
//! transforms to send and whether `/scene` must be sent whole again.
//!
//! `/bodies` leaves out what the integrator predicts (see `proto/ricochet.proto`): a position
//! that is `previous + velocity * dt`, an angle that is `previous + angular_velocity * dt`,
//! velocities that did not change. Values are compared by their bits, so a change of sign of
//! a zero, or any NaN, is a change.
//!
//! `/tf` sends a body's pose only at the ends of the stretches where it moves in a straight
//! line at a constant rate (and turns at a constant rate, less than a quarter turn):
//! Foxglove interpolates between a frame's transforms, linearly for the position and
//! spherically for the rotation, which gives back every frame's pose in between (within
//! [`LINE_TOLERANCE`], far below what f32 rendering shows). A stretch still open at the end
//! of the log, or when its body goes, is closed by [`Tracker::close`].

use ricochet_geom::{ShapeDef, Vec2};
use ricochet_log::messages::fox::FrameTransform;
use ricochet_log::messages::ricochet as pb;
use ricochet_sim::{BodyKind, Entity, FrameOutput, Layers, RemovedBody, World};

use super::scene;

/// `/bodies` lists every body in full every this many frames (and at frame 0).
pub const KEYFRAME_INTERVAL: u64 = 60;

/// How far, relative to the value (or absolutely, below 1), a frame's pose may be from the
/// straight line of its stretch: 1e-9, some ten thousand times finer than f32 rendering.
pub const LINE_TOLERANCE: f64 = 1e-9;

/// A pose as `/tf` interpolates it: x, y and angle.
type Pose3 = [f64; 3];

/// A stretch of straight-line motion: its first frame and pose, and the step per frame
/// (known from its second frame on).
struct Stretch {
    frame: u64,
    pose: Pose3,
    step: Option<Pose3>,
}

impl Stretch {
    fn start(frame: u64, pose: Pose3) -> Stretch {
        Stretch {
            frame,
            pose,
            step: None,
        }
    }

    /// Whether `pose` at `frame` is on the line (setting the step at its second frame).
    fn extends_to(&mut self, frame: u64, pose: Pose3) -> bool {
        let n = (frame - self.frame) as f64;
        let Some(step) = self.step else {
            self.step = Some([
                pose[0] - self.pose[0],
                pose[1] - self.pose[1],
                pose[2] - self.pose[2],
            ]);
            return (pose[2] - self.pose[2]).abs() < std::f64::consts::FRAC_PI_2;
        };
        (0..3).all(|k| {
            let want = self.pose[k] + step[k] * n;
            (pose[k] - want).abs() <= LINE_TOLERANCE * pose[k].abs().max(1.0)
        }) && (pose[2] - self.pose[2]).abs() < std::f64::consts::FRAC_PI_2
    }
}

/// What was last recorded of a body alive at the end of the previous frame.
struct Known {
    generation: u32,
    position: Vec2,
    angle: f64,
    velocity: Vec2,
    angular_velocity: f64,
    /// Its frame's name, `body/index:generation`.
    frame_id: String,
    /// The stretch of straight-line motion it is on.
    stretch: Stretch,
    /// The last frame whose pose was sent on `/tf`.
    sent: u64,
    /// Its drawing turns back by its angle (an AABB part): a turn redraws the scene.
    drawn_with_angle: bool,
    /// The frame it was last seen in the world.
    seen: u64,
}

impl Known {
    fn pose(&self) -> Pose3 {
        [self.position.x, self.position.y, self.angle]
    }
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
        angular_velocity: Some(r.angular_velocity),
        still: false,
    }
}

/// One frame's changes.
pub struct Changes {
    /// `/bodies`.
    pub bodies: pb::Bodies,
    /// `/tf`: the transforms of the bodies that appeared, or whose stretch of straight-line
    /// motion ended.
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
    /// The last frame seen.
    frame: u64,
}

fn transform(k: &Known, frame: u64, dt_ns: u64) -> FrameTransform {
    let ts = ricochet_log::messages::timestamp(frame * dt_ns);
    scene::transform(&k.frame_id, ts, k.position, k.angle)
}

impl Tracker {
    /// The changes of frame `out.frame` (its world is `world`). `dt_ns` is the step.
    pub fn frame(
        &mut self,
        world: &World,
        out: &FrameOutput,
        layers: &Layers,
        dt: f64,
        dt_ns: u64,
        want_bodies: bool,
    ) -> Changes {
        let frame = out.frame;
        let keyframe = !self.started || frame.is_multiple_of(KEYFRAME_INTERVAL);
        let mut scene_changed = !self.started || !out.removed.is_empty();
        self.started = true;
        self.frame = frame;
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
                match &self.known[slot] {
                    None => self.alive += 1,
                    // The slot's last body went this frame: close its last stretch.
                    Some(old) if old.sent < old.seen => {
                        transforms.push(transform(old, old.seen, dt_ns));
                    }
                    Some(_) => {}
                }
                scene_changed = true;
                let k = Known {
                    generation: e.generation,
                    position,
                    angle,
                    velocity,
                    angular_velocity,
                    frame_id: scene::entity_id(e),
                    stretch: Stretch::start(frame, [position.x, position.y, angle]),
                    sent: frame,
                    drawn_with_angle: scene::drawing_depends_on_angle(&world.shape[i]),
                    seen: frame,
                };
                transforms.push(transform(&k, frame, dt_ns));
                self.known[slot] = Some(k);
            }
            let Some(k) = self.known[slot].as_mut() else {
                continue;
            };
            k.seen = frame;
            let pose = [position.x, position.y, angle];
            if !fresh && !k.stretch.extends_to(frame, pose) {
                // The stretch ended at the previous frame: send its end (unless sent), and
                // start the next stretch there.
                if k.sent < frame - 1 {
                    transforms.push(transform(k, frame - 1, dt_ns));
                    k.sent = frame - 1;
                }
                let mut next = Stretch::start(frame - 1, k.pose());
                if !next.extends_to(frame, pose) {
                    // A quarter turn or more in one step: this frame is a stretch's end too.
                    let ts = ricochet_log::messages::timestamp(frame * dt_ns);
                    transforms.push(scene::transform(&k.frame_id, ts, position, angle));
                    k.sent = frame;
                    next = Stretch::start(frame, pose);
                }
                k.stretch = next;
            }
            if !fresh && k.drawn_with_angle && !same(angle, k.angle) {
                scene_changed = true;
            }
            let sped = !same2(k.velocity, velocity);
            let spun = !same(k.angular_velocity, angular_velocity);
            // What a reader predicts: the integrator's step with this frame's velocities.
            let moved_as_predicted = same2(position, k.position + velocity * dt);
            let turned_as_predicted = same(angle, k.angle + angular_velocity * dt);
            let still = same2(position, k.position) && same(angle, k.angle);
            let full = keyframe || fresh;
            let predicted = moved_as_predicted && turned_as_predicted;
            if want_bodies && (full || sped || spun || !predicted) {
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
                    b.position = xy(position);
                    b.angle = Some(angle);
                } else if still && !predicted {
                    b.still = true;
                } else {
                    if !moved_as_predicted {
                        b.position = xy(position);
                    }
                    if !turned_as_predicted {
                        b.angle = Some(angle);
                    }
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
            // Some bodies went (removed, or despawned between frames): close their last
            // stretch at the frame they were last seen in, and forget them.
            for slot in &mut self.known {
                if let Some(k) = slot.as_ref()
                    && k.seen != frame
                {
                    if k.sent < k.seen {
                        transforms.push(transform(k, k.seen, dt_ns));
                    }
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
                dt,
            },
            transforms,
            scene_changed,
        }
    }

    /// The transforms that close every stretch still open at the last frame seen: called
    /// when the log ends, so that Foxglove has both ends of every stretch.
    pub fn close(&mut self, dt_ns: u64) -> Vec<FrameTransform> {
        let frame = self.frame;
        self.known
            .iter_mut()
            .flatten()
            .filter(|k| k.sent < frame)
            .map(|k| {
                k.sent = frame;
                transform(k, frame, dt_ns)
            })
            .collect()
    }
}
