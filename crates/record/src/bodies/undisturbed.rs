//! The bodies the step did not disturb, left alone (issue #37).
//!
//! In a world without gravity, a body the step only integrated, with the usual pass, is
//! exactly where a reader of `/bodies` predicts: `position + velocity * dt`, `angle +
//! angular_velocity * dt`, its velocities unchanged. The world names every other body
//! ([`ricochet_sim::Disturbed`]). So when the world says what it disturbed since the last
//! frame, the tracker compares only those and the bodies the usual pass does not move
//! (static, asleep, frozen), and leaves every other body's record as it was, of an earlier
//! frame (its `seen`). A record is brought forward, step by step with the integrator's own
//! arithmetic, when it is next needed: the body is disturbed, a full pass comes, or the
//! frame needs one moved body to know `/scene` must be drawn again. A keyframe in such a
//! world writes every moving body whole from the world, so it takes each undisturbed
//! body's state as it is, and brings a record forward only to ask whether the body moved,
//! while no other body has said so.
//!
//! In a debug build every frame taken this way, keyframes too, is checked against the full
//! comparison ([`check`]): the same `/bodies` bytes, the same redraw flags and the same
//! records.

use ricochet_geom::Vec2;
use ricochet_sim::{Entity, FrameOutput, World};

use super::{Known, Tracker, same, same2};

impl Known {
    /// The pose `steps` integrator steps on, at this velocity and spin: `p + v * dt`, as
    /// the usual pass computes it (a pose the step leaves as it is ends the loop).
    pub(super) fn advanced(&self, steps: u64, dt: f64) -> (Vec2, f64) {
        let (d, s) = (self.velocity * dt, self.angular_velocity * dt);
        let (mut p, mut a) = (self.position, self.angle);
        for _ in 0..steps {
            let (next_p, next_a) = (p + d, a + s);
            if same2(next_p, p) && same(next_a, a) {
                break;
            }
            (p, a) = (next_p, next_a);
        }
        (p, a)
    }

    /// Whether the body, `steps` integrator steps on from this record last frame, is not
    /// at `position` and `angle` now.
    pub(super) fn moved_since(&self, steps: u64, position: Vec2, angle: f64, dt: f64) -> bool {
        let (p, a) = self.advanced(steps, dt);
        !same2(p, position) || !same(a, angle)
    }

    /// Brings the record forward to frame `to`.
    fn bring_to(&mut self, to: u64, dt: f64) {
        if self.seen < to {
            debug_assert!(!self.falling, "no falling without gravity");
            (self.position, self.angle) = self.advanced(to - self.seen, dt);
            self.seen = to;
        }
    }
}

impl Tracker {
    /// Whether frame `frame` may leave the undisturbed bodies alone: no gravity, the
    /// frame right after the last one, of the same world, stepped once since, which names
    /// what it disturbed.
    pub(super) fn may_skip(&self, world: &World, frame: u64, gravity: Vec2) -> bool {
        let d = world.disturbed();
        self.started
            && gravity == Vec2::ZERO
            && frame == self.frame + 1
            && (d.serial(), d.steps()) == (self.world.0, self.world.1 + 1)
            && !d.all()
    }

    /// The bodies to compare, into `unsettled` (ascending dense indices): the disturbed
    /// ones still in the world and every one the usual pass does not move. Their records
    /// are brought forward to `previous`. The named ones gone go to `gone`.
    pub(super) fn gather_disturbed(&mut self, world: &World, previous: u64, dt: f64) {
        self.unsettled.clear();
        self.gone.clear();
        for &e in world.disturbed().bodies() {
            match world.index_of(e) {
                Some(i) => self.unsettled.push(i),
                None => self.gone.push(e),
            }
        }
        let active = world.active();
        if active.len() != world.len() {
            let mut next = active.iter().peekable();
            for i in 0..world.len() {
                if next.peek().is_some_and(|&&a| a as usize == i) {
                    next.next();
                } else {
                    self.unsettled.push(i);
                }
            }
        }
        self.unsettled.sort_unstable();
        self.unsettled.dedup();
        for &i in &self.unsettled {
            let e = world.entity[i];
            if let Some(Some(k)) = self.known.get_mut(e.index as usize)
                && k.generation == e.generation
            {
                k.bring_to(previous, dt);
            }
        }
    }

    /// Every record brought forward to `previous`, before a full comparison.
    pub(super) fn catch_up(&mut self, previous: u64, dt: f64) {
        for k in self.known.iter_mut().flatten() {
            k.bring_to(previous, dt);
        }
        self.lagging = false;
    }

    /// After a frame that left the undisturbed bodies alone: the bodies that went are
    /// forgotten, and, unless `scene_known`, one undisturbed body that moved is looked
    /// for. Whether `/scene` and `/scene/static` must be drawn again.
    pub(super) fn after_skip(
        &mut self,
        world: &World,
        out: &FrameOutput,
        scene_known: bool,
        dt: f64,
    ) -> (bool, bool) {
        let (frame, mut changed) = (out.frame, (false, false));
        self.lagging = true;
        let gone = std::mem::take(&mut self.gone);
        for e in out
            .removed
            .iter()
            .map(|r| r.entity)
            .chain(gone.iter().copied())
        {
            self.forget(e, &mut changed);
        }
        self.gone = gone;
        if self.alive != world.len() {
            // Something went unnamed: look at every record.
            let slots = (0..self.known.len()).filter_map(|slot| {
                let k = self.known[slot].as_ref()?;
                let e = Entity {
                    index: slot as u32,
                    generation: k.generation,
                };
                world.index_of(e).is_none().then_some(e)
            });
            for e in slots.collect::<Vec<_>>() {
                self.forget(e, &mut changed);
            }
        }
        if !scene_known && !changed.0 {
            changed.0 = self.one_moved(world, frame, dt);
        }
        changed
    }

    /// Forgets body `e` if its record is there: `changed` says which scene lost it.
    fn forget(&mut self, e: Entity, changed: &mut (bool, bool)) {
        if let Some(slot) = self.known.get_mut(e.index as usize)
            && let Some(k) = slot
            && k.generation == e.generation
        {
            *if k.is_static {
                &mut changed.1
            } else {
                &mut changed.0
            } = true;
            *slot = None;
            self.alive -= 1;
        }
    }

    /// Whether an active body not compared this frame moved or turned since the last
    /// frame. Each one looked at is brought up to this frame (from the world: nothing
    /// disturbed it).
    fn one_moved(&mut self, world: &World, frame: u64, dt: f64) -> bool {
        for &i in world.active() {
            let i = i as usize;
            let e = world.entity[i];
            let Some(Some(k)) = self.known.get_mut(e.index as usize) else {
                debug_assert!(false, "an active body {e:?} with no record was not named");
                continue;
            };
            if k.generation != e.generation || k.seen == frame {
                debug_assert!(k.generation == e.generation, "{e:?} was not named");
                continue;
            }
            let (position, angle) = k.advanced(frame - 1 - k.seen, dt);
            (k.position, k.angle, k.seen) = (world.position[i], world.angle[i], frame);
            if !same2(position, k.position) || !same(angle, k.angle) {
                return true;
            }
        }
        false
    }
}

/// What [`Tracker::frame`] was given besides the world.
#[cfg(any(test, debug_assertions))]
pub(super) type Args<'a> = (&'a FrameOutput, &'a ricochet_sim::WorldDef, bool, bool);

/// Checks a frame that left the undisturbed bodies alone against the full comparison run
/// from the tracker as it was before (`oracle`): the same `/bodies` bytes, the same redraw
/// flags, and the same records once every one is brought forward. Debug builds (and
/// tests) only.
#[cfg(any(test, debug_assertions))]
pub(super) fn check(
    mut oracle: Tracker,
    fast: &Tracker,
    world: &World,
    (out, def, want_bodies, velocities_drawn): Args<'_>,
    got: &super::Changes,
    pass: super::Pass,
) {
    let wants = (want_bodies, velocities_drawn);
    let full = match pass {
        super::Pass::KeyframeNamed => super::Pass::Keyframe,
        _ => super::Pass::Every,
    };
    let mut want = oracle.changes(world, out, def, wants, full);
    let frame = out.frame;
    assert!(
        want.encode_bodies() == got.clone().encode_bodies(),
        "frame {frame}: /bodies differs from the full comparison's"
    );
    assert_eq!(
        (want.scene_changed, want.static_changed),
        (got.scene_changed, got.static_changed),
        "frame {frame}: the redraw flags differ from the full comparison's"
    );
    let mut fast = fast.clone();
    fast.catch_up(frame, def.dt);
    assert_eq!(fast.alive, oracle.alive, "frame {frame}: bodies counted");
    let bits = |k: Option<&Option<Known>>| {
        k.and_then(Option::as_ref).map(|k| {
            let b = [
                k.position.x,
                k.position.y,
                k.angle,
                k.velocity.x,
                k.velocity.y,
            ];
            let flags = (k.falling, k.is_static, k.seen);
            (
                b.map(f64::to_bits),
                k.angular_velocity.to_bits(),
                k.generation,
                flags,
            )
        })
    };
    for slot in 0..fast.known.len().max(oracle.known.len()) {
        let (a, b) = (fast.known.get(slot), oracle.known.get(slot));
        assert_eq!(bits(a), bits(b), "frame {frame}: slot {slot}'s record");
    }
}

#[cfg(test)]
mod tests {
    use std::fmt::Write as _;

    use ricochet_geom::{Pose, Vec2};
    use ricochet_scenes::bench::Scene;
    use ricochet_sim::{Action, BodyDef, BodyKind, Shape, Simulation, load_scenario};

    use super::super::{Pass, Tracker};

    /// What [`run`] counted.
    #[derive(Debug, Default)]
    struct Counts {
        /// Frames that left the undisturbed bodies alone.
        skipped: u64,
        /// Frames after the first that were not keyframes.
        others: u64,
        /// Keyframes that left the undisturbed records alone.
        named_keyframes: u64,
    }

    /// Runs `sim` for `frames` frames through a tracker, comparing each frame (keyframes
    /// too) that leaves the undisturbed bodies alone with the full comparison
    /// ([`super::check`], in every build), `between(sim, frame)` run after each frame is
    /// recorded.
    fn run(
        sim: &mut Simulation,
        frames: u64,
        mut between: impl FnMut(&mut Simulation, u64),
    ) -> Counts {
        let mut tracker = Tracker::default();
        let mut counts = Counts::default();
        for frame in 0..=frames {
            let out = sim.step();
            let def = &sim.scenario().world;
            let before = tracker.clone();
            let changes = tracker.frame(sim.world(), &out, def, true, frame % 2 == 0);
            // What `frame` chose, asked again of the tracker as it was.
            let keyframe = changes.bodies.keyframe;
            if before.started && !keyframe {
                counts.others += 1;
            }
            if before.started && before.may_skip(sim.world(), out.frame, def.gravity) {
                let pass = if keyframe {
                    counts.named_keyframes += 1;
                    Pass::KeyframeNamed
                } else {
                    counts.skipped += 1;
                    Pass::Disturbed
                };
                let args = (&out, def, true, frame % 2 == 0);
                super::check(before, &tracker, sim.world(), args, &changes, pass);
            }
            between(sim, frame);
        }
        counts
    }

    /// A zero-gravity bench scene (asteroids, bullets fired and expiring, a ship turning
    /// and thrusting, wrap-around) leaves the undisturbed bodies alone in nearly every frame,
    /// and every such frame is the full comparison's, byte for byte.
    #[test]
    fn asteroids_leave_the_undisturbed_alone_and_agree_with_the_full_comparison() {
        let scenario = Scene::parse("asteroids-300").unwrap().build(200);
        let mut sim = Simulation::new(&scenario);
        let c = run(&mut sim, 200, |_, _| {});
        assert!(c.others > 190, "{c:?}");
        assert!(c.skipped * 10 >= c.others * 9, "{c:?}");
        // Frames 60, 120 and 180.
        assert_eq!(c.named_keyframes, 3, "{c:?}");
    }

    /// A keyframe in which the world named nobody: whether `/scene` is drawn again comes
    /// from the records left alone, bodies drifting (moved) or too slow to leave their
    /// floating-point place (not moved, though every motion stage ran). The frame before,
    /// the one body that does not turn is put somewhere and stopped, so that the frame
    /// before is known to redraw without a look at the others (whose records are then left
    /// alone for two frames).
    #[test]
    fn a_keyframe_with_nobody_named_still_sees_the_drift() {
        for (speed, moved) in [("0.25", true), ("1e-300", false)] {
            let mut text = String::from(
                "name = \"drift\"\nhz = 60\nframes = 130\nlayers = [\"rock\"]\n\
                 [world]\ngravity = [0, 0]\n",
            );
            for k in 0..5 {
                write!(
                    text,
                    "[[bodies]]\nname = \"r{k}\"\nlayer = \"rock\"\n\
                     shape = {{ kind = \"circle\", radius = 0.5 }}\n\
                     position = [{}, 1]\nangle = 1\nvelocity = [{speed}, {speed}]\n\
                     angular_velocity = {}\n",
                    3 + k * 3,
                    // The last one does not turn: stopped, it stays put.
                    if k < 4 { speed } else { "0" }
                )
                .unwrap();
            }
            let scenario = load_scenario(&text, "drift.toml").unwrap();
            let mut sim = Simulation::new(&scenario);
            let mut tracker = Tracker::default();
            let last = sim.entity_named("r4").unwrap();
            for frame in 0..=130 {
                if frame == 59 || frame == 119 {
                    sim.set_position(last, Vec2::new(20.0, 5.0)).unwrap();
                    sim.set_velocity(last, Vec2::ZERO).unwrap();
                }
                let out = sim.step();
                let def = &sim.scenario().world;
                let before = tracker.clone();
                let changes = tracker.frame(sim.world(), &out, def, true, false);
                if frame == 60 || frame == 120 {
                    assert!(changes.bodies.keyframe);
                    assert!(before.may_skip(sim.world(), out.frame, def.gravity));
                    assert!(sim.world().disturbed().bodies().is_empty());
                    assert_eq!(changes.scene_changed, moved, "frame {frame}, speed {speed}");
                    let args = (&out, def, true, false);
                    let pass = Pass::KeyframeNamed;
                    super::check(before, &tracker, sim.world(), args, &changes, pass);
                }
            }
        }
    }

    /// The hard cases of a scene that may leave bodies alone (no gravity, no `separate`
    /// pair, whose per-axis passes name every body), each frame compared with the full
    /// comparison: static bodies, a kinematic body following its target, bodies frozen and
    /// thawed by an active region, bullets with lifetimes destroyed on contact, a
    /// wrap-around world crossed in a frame by a streak (brought back by the seam), a ship
    /// turning, thrusting and firing, and between frames every control a game has:
    /// positions, angles, velocities, forces and targets set, bodies spawned and despawned.
    #[test]
    fn every_kind_of_disturbance_agrees_with_the_full_comparison() {
        let mut text = String::from(
            r#"name = "disturbances"
hz = 60
frames = 300
layers = ["rock", "wall", "bullet", "mover"]
collide = [
  { a = "rock", b = "rock", response = "report" },
  { a = "rock", b = "wall", response = "report" },
  { a = "bullet", b = "rock", response = "destroy", destroy = "both" },
  { a = "mover", b = "rock", response = "report" },
]
[world]
gravity = [0, 0]
bounds = { min = [-20, -20], max = [20, 20], wrap = true }
[world.active_region]
focus = "mover"
half_extents = [12, 12]
[[bodies]]
name = "mover"
layer = "mover"
kind = "kinematic"
shape = { kind = "circle", radius = 1.5 }
velocity = [4, 1]
[[bodies]]
name = "ship"
layer = "mover"
shape = { kind = "polygon", vertices = [[-1, -1], [1, 0], [-1, 1]] }
controller = { kind = "ship", thrust = 12, turn_rate = 3, bullet = "shot", bullet_speed = 30, muzzle = 1.5 }
[[bodies]]
name = "streak"
layer = "rock"
shape = { kind = "circle", radius = 0.1 }
velocity = [2500, 700]
[templates.shot]
layer = "bullet"
shape = { kind = "circle", radius = 0.1 }
lifetime = 30
"#,
        );
        for k in 0..60 {
            let (x, y) = (f64::from(k % 8) * 5.0 - 18.0, f64::from(k / 8) * 5.0 - 18.0);
            let (vx, vy) = (f64::from(k % 5) - 2.0, f64::from(k % 3) - 1.0);
            let (layer, shape, extra) = match k % 6 {
                0 => (
                    "wall",
                    "{ kind = \"circle\", radius = 1.0 }",
                    "kind = \"static\"\n",
                ),
                1 => (
                    "bullet",
                    "{ kind = \"circle\", radius = 0.2 }",
                    "lifetime = 40\n",
                ),
                2 => (
                    "rock",
                    "{ kind = \"polygon\", vertices = [[-1, -1], [1, -1], [0, 1]] }",
                    "angular_velocity = 0.5\n",
                ),
                _ => ("rock", "{ kind = \"circle\", radius = 0.9 }", ""),
            };
            write!(
                text,
                "[[bodies]]\nname = \"b{k}\"\nlayer = \"{layer}\"\nshape = {shape}\n\
                 position = [{x}, {y}]\n{extra}"
            )
            .unwrap();
            if layer != "wall" {
                writeln!(text, "velocity = [{vx}, {vy}]").unwrap();
            }
        }
        let scenario = load_scenario(&text, "disturbances.toml").unwrap();
        let mut sim = Simulation::new(&scenario);
        let rock = BodyDef {
            name: "late".into(),
            layer: scenario.world.layers.id("rock").unwrap(),
            shape: Shape::circle(0.7).unwrap(),
            kind: BodyKind::Dynamic,
            velocity: Vec2::new(1.0, -2.0),
            ..BodyDef::default()
        };
        let mover = sim.entity_named("mover").unwrap();
        let ship = sim.entity_named("ship").unwrap();
        let streak = sim.entity_named("streak").unwrap();
        let c = run(&mut sim, 300, |sim, frame| {
            let ids: Vec<_> = (0..sim.world().len())
                .map(|i| sim.world().entity[i])
                .collect();
            let pick = ids[(frame as usize * 7) % ids.len()];
            if [mover, ship, streak].contains(&pick) {
                return;
            }
            let t = frame as f64;
            match frame % 11 {
                0 => sim
                    .set_position(pick, Vec2::new(t * 0.1 - 10.0, 3.0))
                    .unwrap(),
                2 => sim.set_angle(pick, t * 0.01).unwrap(),
                4 => sim.set_velocity(pick, Vec2::new(-1.0, t * 0.02)).unwrap(),
                5 => sim.set_force(pick, Vec2::new(0.5, -0.5)).unwrap(),
                6 if ids.len() > 20 => sim.despawn(pick).unwrap(),
                7 => _ = sim.spawn(&rock),
                8 => {
                    let pose = Pose::new(Vec2::new(t * 0.05, -t * 0.03), t * 0.02);
                    sim.set_target_pose(mover, pose).unwrap();
                }
                _ => {}
            }
            // The ship: turning (its spin set by `controls`), thrusting and firing.
            let turn = [0.0, 1.0, -0.5][(frame / 17 % 3) as usize];
            sim.apply(ship, Action::Turn(turn)).unwrap();
            sim.apply(ship, Action::Thrust(frame / 23 % 2 == 0))
                .unwrap();
            if frame % 13 == 0 {
                sim.apply(ship, Action::Fire).unwrap();
            }
        });
        assert!(c.others > 290, "{c:?}");
        assert!(c.skipped > 100, "{c:?}");
        assert!(c.named_keyframes > 0, "{c:?}");
    }
}
