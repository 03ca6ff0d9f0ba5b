//! What changed since the previous frame, body by body: the `/bodies` deltas and whether
//! `/scene` or `/scene/static` must be sent again.
//!
//! `/bodies` leaves out what the integrator predicts (see `proto/ricochet.proto`): a position
//! that is `previous + velocity * dt`, an angle that is `previous + angular_velocity * dt`,
//! velocities that did not change. Values are compared by their bits, so a change of sign of
//! a zero, or any NaN, is a change.

use ricochet_geom::{ShapeDef, Vec2};
use ricochet_log::messages::ricochet as pb;
use ricochet_sim::{BodyKind, Entity, FrameOutput, Layers, RemovedBody, World, WorldDef};

/// `/bodies` lists every moving body in full at frame 0 and then at multiples of this many
/// frames (a big scene's less often: see [`KEYFRAME_BYTES_PER_FRAME`]).
pub const KEYFRAME_INTERVAL: u64 = 60;

/// A keyframe of `n` encoded bytes is followed by the next at the first multiple of
/// [`KEYFRAME_INTERVAL`] at least `ceil(n / KEYFRAME_BYTES_PER_FRAME)` frames later: up to
/// 240 KiB (about 1,500 moving bodies) that is the next multiple, as it always was; 10,000
/// asteroids' keyframe (1.7 MB) comes every 420 frames. A keyframe is where a reader may
/// start (every frame between is still exact from the one before); building and
/// compressing 10,000 bodies every second was a third of the cost of recording them, and
/// each such keyframe still costs the 10,000-asteroid level's 600-frame recording about 6%
/// (issue #37, BENCHMARKS.md). Bytes, never time: the same log on every machine.
pub const KEYFRAME_BYTES_PER_FRAME: u64 = 4 * 1024;

mod listed;
mod undisturbed;

/// What was last recorded of a body alive at the end of the previous frame (or, for a body
/// nothing disturbed since, of frame `seen`: see `bodies/undisturbed.rs`).
#[derive(Clone, Debug)]
struct Known {
    generation: u32,
    position: Vec2,
    angle: f64,
    velocity: Vec2,
    angular_velocity: f64,
    /// Its velocity is predicted to fall: `previous + gravity * dt` (see `falling` in
    /// `proto/ricochet.proto`).
    falling: bool,
    /// A static body: drawn on `/scene/static`, and listed in `/bodies` only when it appears
    /// or changes (keyframes list the moving bodies).
    is_static: bool,
    /// The frame it was last seen in the world, which its state is of.
    seen: u64,
}

impl Known {
    /// What a reader predicts of the velocity (the one place this is written; the settling
    /// pass and the general case both ask here): one step of falling, `fall` = `gravity *
    /// dt`, when falling, else unchanged.
    #[inline(always)]
    fn expected_velocity(&self, fall: Vec2) -> Vec2 {
        if self.falling {
            self.fallen(fall)
        } else {
            self.velocity
        }
    }

    /// The velocity after one step of falling.
    #[inline(always)]
    fn fallen(&self, fall: Vec2) -> Vec2 {
        self.velocity + fall
    }

    /// Whether `position` is one integrator step on from this one at `velocity` (this
    /// frame's).
    #[inline(always)]
    fn moved_as_predicted(&self, position: Vec2, velocity: Vec2, dt: f64) -> bool {
        same2(position, self.position + velocity * dt)
    }

    /// Whether `angle` is one integrator step on from this one at `spin` (this frame's).
    #[inline(always)]
    fn turned_as_predicted(&self, angle: f64, spin: f64, dt: f64) -> bool {
        same(angle, self.angle + spin * dt)
    }

    /// Whether a reader predicts this frame's state from this one: the velocity as
    /// [`Known::expected_velocity`] says, the spin unchanged, and the pose one integrator
    /// step on. Then `/bodies` has nothing to say of the body.
    fn as_predicted(
        &self,
        position: Vec2,
        angle: f64,
        velocity: Vec2,
        spin: f64,
        fall: Vec2,
        dt: f64,
    ) -> bool {
        same2(velocity, self.expected_velocity(fall))
            && same(spin, self.angular_velocity)
            && self.moved_as_predicted(position, velocity, dt)
            && self.turned_as_predicted(angle, spin, dt)
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
        // The log's schema has no chain: a chain is written as a compound of its segments,
        // each a capsule of radius 0 (the schema stays as it is, so every log stays readable
        // by the viewers; the ghost points are the neighbours' ends, not written).
        ShapeDef::Chain { points, .. } => Kind::Compound(pb::Compound {
            parts: points
                .windows(2)
                .map(|w| pb::Shape {
                    kind: Some(Kind::Capsule(pb::Capsule {
                        a: w[0].to_vec(),
                        b: w[1].to_vec(),
                        radius: 0.0,
                    })),
                })
                .collect(),
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
        falling: None,
    }
}

/// One frame's changes.
#[derive(Clone)]
pub struct Changes {
    /// `/bodies`, but for its list of bodies, which is `listed`.
    pub bodies: pb::Bodies,
    /// The `bodies` field of `/bodies`, each body encoded as it was listed: a keyframe's
    /// 10,000 bodies are never built as messages (`bodies/listed.rs`).
    pub listed: Vec<u8>,
    /// `/scene` (moving bodies) must be sent again: one moved, turned, appeared or went
    /// (or, when velocities are drawn, changed its velocity).
    pub scene_changed: bool,
    /// `/scene/static` must be sent again: a static body appeared, went, moved or turned.
    pub static_changed: bool,
}

/// The last recorded state of every body, by slot.
#[derive(Clone, Default)]
pub struct Tracker {
    known: Vec<Option<Known>>,
    alive: usize,
    started: bool,
    /// The last frame seen.
    frame: u64,
    /// The first frame that may be a keyframe again (see [`KEYFRAME_BYTES_PER_FRAME`]).
    next_keyframe: u64,
    /// Scratch: the dense indices [`Tracker::settle`] left to the general case.
    unsettled: Vec<usize>,
    /// Scratch: the named bodies no longer in the world (`bodies/undisturbed.rs`).
    gone: Vec<Entity>,
    /// The world's [`ricochet_sim::Disturbed`] serial and step count at the last frame.
    world: (u64, u64),
    /// Some bodies' state is of an earlier frame than the last (`bodies/undisturbed.rs`).
    lagging: bool,
}

/// Which bodies a frame compares with their records.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Pass {
    /// Every body, each moving one listed in full.
    Keyframe,
    /// [`Pass::Keyframe`] where [`Tracker::may_skip`] holds: the records the world did not
    /// disturb are not brought forward, since a keyframe writes each moving body whole from
    /// the world (`bodies/undisturbed.rs`).
    KeyframeNamed,
    /// Every body: the ones that did what a reader predicts settled first.
    Every,
    /// Only the ones the world names as disturbed, and those the usual integration does
    /// not move (`bodies/undisturbed.rs`).
    Disturbed,
}

/// What [`Tracker::settle`] saw move.
#[derive(Default)]
struct Settled {
    scene_changed: bool,
    static_changed: bool,
}

impl Tracker {
    /// Whether a frame was tracked yet. The first one finds every body new: both the scene
    /// and the static scene changed.
    pub fn started(&self) -> bool {
        self.started
    }

    /// The keyframe of frame `frame` was `bytes` encoded bytes: the next waits for them.
    pub fn keyframe_written(&mut self, frame: u64, bytes: u64) {
        self.next_keyframe = frame.saturating_add(bytes.div_ceil(KEYFRAME_BYTES_PER_FRAME));
    }

    /// Settles every known body that did only what a reader predicts (see
    /// [`Known::as_predicted`]): its state is taken as the new last one, and `/bodies` says
    /// nothing of it. The indices of the others go to `unsettled`, ascending. Not for a
    /// keyframe (which lists every moving body). `fall` is `gravity * dt`.
    fn settle(
        &mut self,
        world: &World,
        frame: u64,
        fall: Vec2,
        dt: f64,
        velocities_drawn: bool,
    ) -> Settled {
        let mut out = Settled::default();
        self.unsettled.clear();
        for (i, m) in world.motions().enumerate() {
            let e = m.entity;
            if let Some(Some(k)) = self.known.get_mut(e.index as usize)
                && k.generation == e.generation
                && k.as_predicted(
                    m.position,
                    m.angle,
                    m.velocity,
                    m.angular_velocity,
                    fall,
                    dt,
                )
            {
                let moved = !same2(m.position, k.position) || !same(m.angle, k.angle);
                let sped = !same2(k.velocity, m.velocity);
                if moved || (velocities_drawn && !k.is_static && sped) {
                    *if k.is_static {
                        &mut out.static_changed
                    } else {
                        &mut out.scene_changed
                    } = true;
                }
                k.seen = frame;
                k.position = m.position;
                k.angle = m.angle;
                k.velocity = m.velocity;
            } else {
                self.unsettled.push(i);
            }
        }
        out
    }

    /// The changes of frame `out.frame` (its world is `world`, its settings `def`).
    /// `velocities_drawn`: the scene shows each body's velocity, so a change of velocity
    /// redraws it.
    pub fn frame(
        &mut self,
        world: &World,
        out: &FrameOutput,
        def: &WorldDef,
        want_bodies: bool,
        velocities_drawn: bool,
    ) -> Changes {
        let keyframe = !self.started
            || (out.frame.is_multiple_of(KEYFRAME_INTERVAL) && out.frame >= self.next_keyframe);
        let pass = match (keyframe, self.may_skip(world, out.frame, def.gravity)) {
            (true, false) => Pass::Keyframe,
            (true, true) => Pass::KeyframeNamed,
            (false, true) => Pass::Disturbed,
            (false, false) => Pass::Every,
        };
        #[cfg(debug_assertions)]
        let oracle = matches!(pass, Pass::Disturbed | Pass::KeyframeNamed).then(|| self.clone());
        let changes = self.changes(world, out, def, (want_bodies, velocities_drawn), pass);
        #[cfg(debug_assertions)]
        if let Some(oracle) = oracle {
            let args = (out, def, want_bodies, velocities_drawn);
            undisturbed::check(oracle, self, world, args, &changes, pass);
        }
        let d = world.disturbed();
        self.world = (d.serial(), d.steps());
        changes
    }

    /// [`Tracker::frame`]'s changes, taking its `want_bodies` and `velocities_drawn`, in a
    /// [`Pass`].
    fn changes(
        &mut self,
        world: &World,
        out: &FrameOutput,
        def: &WorldDef,
        (want_bodies, velocities_drawn): (bool, bool),
        pass: Pass,
    ) -> Changes {
        let keyframe = matches!(pass, Pass::Keyframe | Pass::KeyframeNamed);
        let skip = pass == Pass::Disturbed;
        let named = pass == Pass::KeyframeNamed;
        let (layers, dt, gravity) = (&def.layers, def.dt, def.gravity);
        let frame = out.frame;
        let previous = self.frame;
        let (mut scene_changed, mut static_changed) = (!self.started, !self.started);
        for r in &out.removed {
            *if r.kind == BodyKind::Static {
                &mut static_changed
            } else {
                &mut scene_changed
            } = true;
        }
        self.started = true;
        self.frame = frame;
        // A keyframe lists every moving body: room for all of them at once (10,000 bodies
        // are about 1.4 MB, which would otherwise be copied as the list grows).
        let mut listed = Vec::with_capacity(if keyframe && want_bodies {
            world.len() * listed::BODY_BYTES
        } else {
            0
        });
        // Most bodies of a big scene did only what a reader predicts: settled first, in a
        // loop of their own (or, `skip`, not looked at); the others take the general case
        // below, in world order.
        if skip {
            self.gather_disturbed(world, previous, dt);
        } else {
            if named {
                // Only the records of the bodies compared in a skipping frame are brought
                // forward: the others are left alone below.
                self.gather_disturbed(world, previous, dt);
            } else if self.lagging {
                self.catch_up(previous, dt);
            }
            if keyframe {
                self.unsettled.clear();
                self.unsettled.extend(0..world.len());
            } else {
                let settled = self.settle(world, frame, gravity * dt, dt, velocities_drawn);
                scene_changed |= settled.scene_changed;
                static_changed |= settled.static_changed;
            }
        }
        let unsettled = std::mem::take(&mut self.unsettled);
        // A record for every slot at once: the entities are in id order, so the last has
        // the highest slot (10,000 records grown one by one were copied as they grew).
        if let Some(last) = world.entity.last()
            && self.known.len() <= last.index as usize
        {
            self.known.resize_with(last.index as usize + 1, || None);
        }
        // A body's shape, encoded, while it is listed whole.
        let mut shape = Vec::new();
        for &i in &unsettled {
            let e = world.entity[i];
            let (position, angle) = (world.position[i], world.angle[i]);
            let (velocity, angular_velocity) = (world.velocity(i), world.angular_velocity(i));
            let slot = e.index as usize;
            if self.known.len() <= slot {
                self.known.resize_with(slot + 1, || None);
            }
            let fresh = !matches!(&self.known[slot], Some(k) if k.generation == e.generation);
            if fresh {
                if self.known[slot].is_none() {
                    self.alive += 1;
                }
                let is_static = world.kind[i] == BodyKind::Static;
                *if is_static {
                    &mut static_changed
                } else {
                    &mut scene_changed
                } = true;
                let k = Known {
                    generation: e.generation,
                    position,
                    angle,
                    velocity,
                    angular_velocity,
                    falling: false,
                    is_static,
                    seen: frame,
                };
                self.known[slot] = Some(k);
            }
            let Some(k) = self.known[slot].as_mut() else {
                continue;
            };
            // A record the world left alone since `seen` (`named`): its velocities are this
            // frame's, and the integrator moved it on from there.
            let left_alone = named && !fresh && !k.is_static && k.seen < previous;
            let seen = std::mem::replace(&mut k.seen, frame);
            let sped = !same2(k.velocity, velocity);
            // What a reader predicts of the velocity: unchanged, or one step of falling. A
            // velocity that is neither is written; one that is the other switches the mode.
            let fall = gravity * dt;
            let falls = gravity != Vec2::ZERO && same2(velocity, k.fallen(fall));
            let as_predicted = same2(velocity, k.expected_velocity(fall));
            let mode = if as_predicted {
                None
            } else if falls {
                Some(true)
            } else if !sped {
                Some(false)
            } else {
                None
            };
            k.falling = mode.unwrap_or(k.falling);
            let spun = !same(k.angular_velocity, angular_velocity);
            let moved = if left_alone {
                // Written whole, so only whether it moved since the last frame is asked,
                // and only while no other body has said so.
                !scene_changed && k.moved_since(previous - seen, position, angle, dt)
            } else {
                !same2(position, k.position) || !same(angle, k.angle)
            };
            if !fresh && (moved || (velocities_drawn && !k.is_static && (sped || spun))) {
                *if k.is_static {
                    &mut static_changed
                } else {
                    &mut scene_changed
                } = true;
            }
            // What a reader predicts: the integrator's step with this frame's velocities.
            let moved_as_predicted = k.moved_as_predicted(position, velocity, dt);
            let turned_as_predicted = k.turned_as_predicted(angle, angular_velocity, dt);
            let still = same2(position, k.position) && same(angle, k.angle);
            let full = fresh || (keyframe && !k.is_static);
            let predicted = moved_as_predicted && turned_as_predicted;
            if want_bodies && full {
                shape.clear();
                listed::shape(world.shape(i), &mut shape);
                let body = listed::Whole {
                    entity: e,
                    name: world.name(i),
                    layer: layers.name(world.layer[i]),
                    shape: &shape,
                    is_static: world.kind[i] == BodyKind::Static,
                    position,
                    angle,
                    velocity,
                    angular_velocity,
                    falling: if k.falling { Some(true) } else { mode },
                };
                body.encode(&mut listed);
            } else if want_bodies && (!as_predicted || spun || !predicted) {
                let mut b = pb::Body {
                    id: e.index,
                    generation: e.generation,
                    ..Default::default()
                };
                if full {
                    b.name = Some(world.name(i).to_owned());
                    b.layer = Some(layers.name(world.layer[i]).to_owned());
                    b.shape = Some(shape_message(&ShapeDef::from_shape(world.shape(i))));
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
                if full || (!as_predicted && mode.is_none()) {
                    b.velocity = xy(velocity);
                }
                b.falling = if full && k.falling { Some(true) } else { mode };
                if full || spun {
                    b.angular_velocity = Some(angular_velocity);
                }
                listed::encode(&b, &mut listed);
            }
            k.position = position;
            k.angle = angle;
            k.velocity = velocity;
            k.angular_velocity = angular_velocity;
        }
        self.unsettled = unsettled;
        if named {
            // Every record still here is of this frame now (the gone ones go below).
            self.lagging = false;
        }
        if skip {
            let (scene, statics) = self.after_skip(world, out, scene_changed, dt);
            scene_changed |= scene;
            static_changed |= statics;
        } else if self.alive != world.len() {
            // Some bodies went (removed, or despawned between frames): forget them.
            for slot in &mut self.known {
                if let Some(k) = slot.as_ref()
                    && k.seen != frame
                {
                    *if k.is_static {
                        &mut static_changed
                    } else {
                        &mut scene_changed
                    } = true;
                    *slot = None;
                    self.alive -= 1;
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
                bodies: Vec::new(),
                removed,
                dt,
                gravity: if gravity == Vec2::ZERO {
                    Vec::new()
                } else {
                    xy(gravity)
                },
            },
            listed,
            scene_changed,
            static_changed,
        }
    }
}

impl Changes {
    /// `/bodies`, encoded: [`Changes::bodies`] with [`Changes::listed`] as its list of
    /// bodies (`bodies/listed.rs`). Takes the list.
    pub fn encode_bodies(&mut self) -> Vec<u8> {
        listed::message(&self.bodies, std::mem::take(&mut self.listed))
    }
}

#[cfg(test)]
mod tests;
