//! Touch events (`stages/touch.rs`, `docs/touches.md`): a pair begins touching at its first
//! frame with a contact record, stays touching while it has records or rests flush, and ends
//! at the first frame it does neither (or a body is removed). Every expected frame below is
//! computed by hand from the scene's numbers.

use std::collections::BTreeSet;

use proptest::prelude::*;
use ricochet_geom::{Shape, Vec2};
use ricochet_sim::{
    Action, BodyDef, BodyKind, Entity, FrameOutput, GameEvent, Layers, Phase, Removal, Response,
    Simulation, Stage, WorldBounds, WorldDef, load_scenario,
};

/// A unit box dropped from rest, bottom 0.5 above a static floor whose top is at y = 0.
/// Gravity 36 at 60 Hz: each frame `v -= 36 / 60 = 0.6`, then `y += v / 60`, so after frame
/// `n` the box has fallen `0.01 * (1 + ... + n) = 0.005 n (n + 1)`: 0.45 after frame 9
/// (0.05 still to go), 0.55 after frame 10 (0.05 into the floor). It lands at frame 10:
/// `resolve_y` pushes it up by 0.05 (the pass's record, phase y, floor #0 below box #1:
/// normal +y). From then on every frame sinks it 0.01 into the floor (`v` was zeroed, gravity
/// gives it 0.6 again) and the pass pushes it back: a record a frame. At frame 140 the
/// script sets its velocity to 6 up; gravity leaves 5.4, so it rises 0.09 off the floor:
/// no record, 0.09 apart, more than SLOP: the touch ends at frame 140.
fn drop_scene(extra_world: &str, script: &str, touches: &str) -> String {
    format!(
        r#"
layers = ["box", "floor"]
script = [{script}]
[world]
gravity = [0, -36]
{extra_world}
[[collide]]
a = "box"
b = "floor"
response = "separate"
{touches}
[[bodies]]
name = "floor"
layer = "floor"
kind = "static"
shape = {{ kind = "aabb", half_extents = [10, 0.5] }}
position = [0, -0.5]
[[bodies]]
name = "box"
layer = "box"
shape = {{ kind = "aabb", half_extents = [0.5, 0.5] }}
position = [0, 1]
"#
    )
}

const JUMP: &str = r#"{ frame = 140, action = "set_velocity", body = "box", velocity = [0, 6] }"#;

fn touch_events(out: &FrameOutput) -> Vec<&GameEvent> {
    out.events
        .iter()
        .filter(|e| matches!(e, GameEvent::TouchBegin { .. } | GameEvent::TouchEnd { .. }))
        .collect()
}

fn entity(sim: &Simulation, name: &str) -> Entity {
    sim.entity_named(name).unwrap()
}

/// Runs the drop scene to frame 150 and checks its one begin and one end.
fn box_lands_rests_and_jumps(extra_world: &str) -> Vec<FrameOutput> {
    let text = drop_scene(extra_world, JUMP, "");
    let mut sim = Simulation::new(&load_scenario(&text, "drop.toml").unwrap());
    let (floor, box_) = (entity(&sim, "floor"), entity(&sim, "box"));
    let mut outs = Vec::new();
    for frame in 0..=150u64 {
        let out = sim.step();
        let touches = touch_events(&out);
        match frame {
            10 => {
                let [
                    GameEvent::TouchBegin {
                        a,
                        b,
                        normal,
                        depth,
                        ..
                    },
                ] = touches[..]
                else {
                    panic!("frame 10: one begin, got {touches:?}");
                };
                assert_eq!((*a, *b), (floor, box_));
                assert_eq!(*normal, Vec2::new(0.0, 1.0));
                assert!((depth - 0.05).abs() < 1e-9, "depth {depth}");
                assert_eq!(out.contacts[0].phase, Phase::Y);
            }
            140 => assert_eq!(touches, [&GameEvent::TouchEnd { a: floor, b: box_ }]),
            _ => assert!(touches.is_empty(), "frame {frame}: {touches:?}"),
        }
        let touching = (10..140).contains(&frame);
        let expected: &[(Entity, Entity)] = if touching { &[(floor, box_)] } else { &[] };
        assert_eq!(sim.touching(), expected, "frame {frame}");
        outs.push(out);
    }
    outs
}

#[test]
fn a_box_dropped_on_a_floor_begins_once_rests_silently_and_ends_when_it_jumps() {
    let outs = box_lands_rests_and_jumps("");
    // Resting, it has a record every frame (the push back out of the floor).
    assert!(outs[10..140].iter().all(|o| o.contacts.len() == 1));
}

/// With `sleep_after = 10` the resting box falls asleep (it is pushed back exactly where it
/// started a frame once the pushes have settled), and then it has no records at all: a
/// sleeper and a static body are both at rest, so the pair still touches, and nothing ends
/// until the script wakes it at frame 140 and it jumps.
#[test]
fn a_box_asleep_on_a_floor_still_touches_it_without_contacts() {
    let outs = box_lands_rests_and_jumps("sleep_after = 10");
    let silent = outs[10..140]
        .iter()
        .filter(|o| o.contacts.is_empty() && o.stats.asleep == 1)
        .count();
    assert!(silent >= 100, "asleep without contacts for {silent} frames");
}

/// The same box destroyed by the script at frame 50, while resting: the pair ends in that
/// frame, right after the Removed event (the script stage's), and nothing else happens.
#[test]
fn a_body_destroyed_while_touching_ends_in_its_destroy_frame_after_the_removal() {
    let destroy = r#"{ frame = 50, action = "destroy", body = "box" }"#;
    let text = drop_scene("", destroy, "");
    let mut sim = Simulation::new(&load_scenario(&text, "drop.toml").unwrap());
    let (floor, box_) = (entity(&sim, "floor"), entity(&sim, "box"));
    for frame in 0..=60u64 {
        let out = sim.step();
        match frame {
            10 => assert!(matches!(
                touch_events(&out)[..],
                [GameEvent::TouchBegin { .. }]
            )),
            50 => assert_eq!(
                out.events,
                [
                    GameEvent::Removed {
                        body: box_,
                        layer: 0,
                        cause: Removal::Script
                    },
                    GameEvent::TouchEnd { a: floor, b: box_ },
                ]
            ),
            _ => assert!(touch_events(&out).is_empty(), "frame {frame}"),
        }
    }
    assert!(sim.touching().is_empty());
}

/// A bullet (radius 0.5, 60 units/s: 1 unit a frame from x = 0) meets a static rock
/// (radius 1 at x = 4) that `destroy`s it: the centres are `4 - n` apart after frame `n`,
/// overlapping below 1.5, so first at frame 3 (1 apart, depth 0.5). The pair begins and
/// ends in that frame, begin first, both after the removal.
#[test]
fn a_pair_that_begins_in_its_bodys_removal_frame_begins_and_ends_there() {
    let text = r#"
layers = ["rock", "bullet"]
[[collide]]
a = "rock"
b = "bullet"
response = "destroy"
destroy = "b"
[[bodies]]
name = "rock"
layer = "rock"
kind = "static"
shape = { kind = "circle", radius = 1 }
position = [4, 0]
[[bodies]]
name = "bullet"
layer = "bullet"
shape = { kind = "circle", radius = 0.5 }
velocity = [60, 0]
"#;
    let mut sim = Simulation::new(&load_scenario(text, "hit.toml").unwrap());
    let (rock, bullet) = (entity(&sim, "rock"), entity(&sim, "bullet"));
    for frame in 0..=5u64 {
        let out = sim.step();
        if frame != 3 {
            assert!(out.events.is_empty(), "frame {frame}: {:?}", out.events);
            continue;
        }
        let [removed, begin, end] = &out.events[..] else {
            panic!("frame 3: {:?}", out.events);
        };
        assert_eq!(
            removed,
            &GameEvent::Removed {
                body: bullet,
                layer: 1,
                cause: Removal::HitBy(rock)
            }
        );
        let GameEvent::TouchBegin { a, b, depth, .. } = begin else {
            panic!("{begin:?}");
        };
        assert_eq!((*a, *b), (rock, bullet));
        assert!((depth - 0.5).abs() < 1e-12, "depth {depth}");
        assert_eq!(end, &GameEvent::TouchEnd { a: rock, b: bullet });
        assert!(sim.touching().is_empty());
    }
}

/// A swept bullet (radius 0.1, 600 units/s: 10 units a frame from x = 0) through a `report`
/// wall 30 wide (x from 25 to 55). Frame 3 moves it from 20 to 30: its front (x + 0.1)
/// reaches 25 at t = 0.49, the swept hit, and the pair begins. Frames 4 to 6 start inside
/// the wall (30, 40, 50): each is a hit at t = 0, a record. Frame 6 ends at 60, out of the
/// wall (59.9 > 55), and frame 7 (60 to 70) never meets it: no record, and 4.9 apart at the
/// end: the pair ends at frame 7, the first frame without a record.
#[test]
fn a_fast_bullet_through_a_report_wall_begins_at_its_swept_hit_and_ends_when_out() {
    let text = r#"
layers = ["wall", "bullet"]
fast_layers = ["bullet"]
[[collide]]
a = "wall"
b = "bullet"
response = "report"
[[bodies]]
name = "wall"
layer = "wall"
kind = "static"
shape = { kind = "aabb", half_extents = [15, 2] }
position = [40, 0]
[[bodies]]
name = "bullet"
layer = "bullet"
shape = { kind = "circle", radius = 0.1 }
velocity = [600, 0]
"#;
    let mut sim = Simulation::new(&load_scenario(text, "bullet.toml").unwrap());
    let (wall, bullet) = (entity(&sim, "wall"), entity(&sim, "bullet"));
    for frame in 0..=10u64 {
        let out = sim.step();
        let touches = touch_events(&out);
        let swept = |o: &FrameOutput| o.contacts.iter().all(|c| c.phase == Phase::Swept);
        assert!(swept(&out));
        assert_eq!(
            !out.contacts.is_empty(),
            (3..=6).contains(&frame),
            "frame {frame}"
        );
        match frame {
            3 => {
                let [
                    GameEvent::TouchBegin {
                        a,
                        b,
                        normal,
                        point,
                        ..
                    },
                ] = touches[..]
                else {
                    panic!("frame 3: {touches:?}");
                };
                assert_eq!((*a, *b), (wall, bullet));
                assert_eq!(*normal, Vec2::new(-1.0, 0.0), "from the wall to the bullet");
                assert!((point.x - 25.0).abs() < 1e-6, "point {point}");
                let pose = out.contacts[0].pose_b.position;
                assert!(
                    (pose.x - 24.9).abs() < 1e-6,
                    "the bullet at its hit: {pose}"
                );
            }
            7 => assert_eq!(touches, [&GameEvent::TouchEnd { a: wall, b: bullet }]),
            _ => assert!(touches.is_empty(), "frame {frame}: {touches:?}"),
        }
        assert_eq!(sim.touching().len(), usize::from((3..7).contains(&frame)));
    }
}

/// `touches = false`: the box still lands at frame 10 and is pushed every frame after
/// (its records unchanged), but the pair is never tracked: no touch event, nothing
/// touching, and with no other pair the stage never runs.
#[test]
fn a_pair_with_touches_off_has_contacts_and_no_touch_events() {
    let text = drop_scene("", JUMP, "touches = false");
    let scenario = load_scenario(&text, "drop.toml").unwrap();
    let layers = &scenario.world.layers;
    assert!(!layers.touches(0, 1) && !layers.touches(1, 0));
    let mut sim = Simulation::new(&scenario);
    let on = drop_scene("", JUMP, "");
    let mut reference = Simulation::new(&load_scenario(&on, "drop.toml").unwrap());
    for frame in 0..=150u64 {
        let (out, with) = (sim.step(), reference.step());
        assert!(touch_events(&out).is_empty(), "frame {frame}");
        assert!(sim.touching().is_empty());
        assert!(out.stats.stages_skipped.contains(Stage::Touch));
        assert_eq!(
            out.contacts, with.contacts,
            "frame {frame}: the same records"
        );
        assert_eq!(!out.contacts.is_empty(), (10..140).contains(&frame));
    }
}

/// The matrix's switch: on by default, off both ways round, never on an `ignore` pair.
#[test]
fn an_ignore_pair_never_touches_and_the_switch_is_symmetric() {
    let mut layers = Layers::new(vec!["a".into(), "b".into()]);
    assert!(
        !layers.touches(0, 1) && !layers.any_touches(),
        "ignored by default"
    );
    layers.set(0, 1, Response::Report);
    assert!(layers.touches(0, 1) && layers.touches(1, 0));
    layers.set_touches(1, 0, false);
    assert!(!layers.touches(0, 1) && !layers.any_touches());
    layers.set_touches(0, 1, true);
    layers.set(0, 1, Response::Ignore);
    assert!(!layers.touches(0, 1), "an ignored pair is never tested");
}

/// A `touches` value of the wrong type is located at the value, like any other.
#[test]
fn a_touches_value_that_is_not_a_bool_is_located() {
    let text = "layers = [\"a\", \"b\"]\n[[collide]]\na = \"a\"\nb = \"b\"\n\
                response = \"report\"\ntouches = 1\n";
    let err = load_scenario(text, "t.toml").unwrap_err();
    assert_eq!((err.line, err.column), (6, 11), "{err}");
    assert_eq!(err.field, "collide[0].touches", "{err}");
}

/// A random small scene: layers, their responses and touch switches, bodies, destroys.
#[derive(Clone, Debug)]
struct Scene {
    /// Per layer pair `(a <= b)`: response (0 ignore, 1 report, 2 destroy, 3 separate) and
    /// whether it touches.
    pairs: Vec<(u8, bool)>,
    fast: bool,
    gravity: bool,
    sleep: bool,
    /// 0: no bounds, 1: bodies leaving are removed, 2: wrap-around.
    bounds: u8,
    bodies: Vec<Body>,
    /// Script destroys: (frame, body).
    destroys: Vec<(u64, usize)>,
}

/// A random body: layer, kind (0-2 dynamic, 3 static, 4 kinematic), box or circle, size,
/// position, velocity.
type Body = (u8, u8, bool, f64, (f64, f64), (f64, f64));

const LAYERS: usize = 2;

fn scene() -> impl Strategy<Value = Scene> {
    let pair = (0u8..4, prop::bool::weighted(0.8));
    let body = (
        0..LAYERS as u8,
        0u8..5,
        any::<bool>(),
        0.3f64..1.0,
        (-4.0f64..4.0, -4.0f64..4.0),
        (-6.0f64..6.0, -6.0f64..6.0),
    );
    (
        prop::collection::vec(pair, 3),
        any::<bool>(),
        any::<bool>(),
        any::<bool>(),
        0u8..3,
        prop::collection::vec(body, 3..10),
        prop::collection::vec((1u64..40, 0usize..9), 0..3),
    )
        .prop_map(
            |(pairs, fast, gravity, sleep, bounds, bodies, destroys)| Scene {
                pairs,
                fast,
                gravity,
                sleep,
                bounds,
                bodies,
                destroys,
            },
        )
}

fn build(scene: &Scene) -> (Simulation, Vec<Entity>) {
    let mut layers = Layers::new(vec!["a".into(), "b".into()]);
    if scene.fast {
        layers.set_fast(1);
    }
    for (k, &(a, b)) in [(0, 0), (0, 1), (1, 1)].iter().enumerate() {
        let (response, touches) = scene.pairs[k];
        let response = match response {
            0 => Response::Ignore,
            1 => Response::Report,
            2 => Response::Destroy(ricochet_sim::Doomed::Both),
            _ => Response::Separate,
        };
        layers.set(a, b, response);
        layers.set_touches(a, b, touches);
    }
    let def = WorldDef {
        layers,
        gravity: Vec2::new(0.0, if scene.gravity { -20.0 } else { 0.0 }),
        sleep_after: scene.sleep.then_some(5),
        bounds: (scene.bounds > 0).then_some(WorldBounds {
            min: Vec2::splat(-6.0),
            max: Vec2::splat(6.0),
            wrap: scene.bounds == 2,
        }),
        ..WorldDef::default()
    };
    let mut sim = Simulation::from_def(def).unwrap();
    let bodies = scene
        .bodies
        .iter()
        .map(|&(layer, kind, is_box, size, (x, y), (vx, vy))| {
            let kind = match kind {
                3 => BodyKind::Static,
                4 => BodyKind::Kinematic,
                _ => BodyKind::Dynamic,
            };
            let moving = kind != BodyKind::Static;
            sim.spawn(&BodyDef {
                layer,
                kind,
                shape: if is_box {
                    Shape::aabb(Vec2::splat(size)).unwrap()
                } else {
                    Shape::circle(size).unwrap()
                },
                position: Vec2::new(x, y),
                velocity: if moving {
                    Vec2::new(vx, vy)
                } else {
                    Vec2::ZERO
                },
                ..BodyDef::default()
            })
        })
        .collect();
    (sim, bodies)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

    /// At every frame: the begins so far less the ends so far are `touching()`; every begin's
    /// pair has a record that frame; no pair begins twice without an end between (nor ends
    /// without a begin); begins come before ends, each in pair order; and every recorded
    /// pair whose layers touch and whose bodies are alive is touching.
    #[test]
    fn touch_events_add_up_to_the_touching_set(scene in scene()) {
        let (mut sim, bodies) = build(&scene);
        let mut model: BTreeSet<(Entity, Entity)> = BTreeSet::new();
        for frame in 0..60u64 {
            for &(f, k) in &scene.destroys {
                if f == frame && let Some(&e) = bodies.get(k) && sim.contains(e) {
                    sim.apply(e, Action::Destroy).unwrap();
                }
            }
            let out = sim.step();
            let recorded: BTreeSet<(Entity, Entity)> =
                out.contacts.iter().map(|c| (c.a, c.b)).collect();
            let (mut begins, mut ends) = (Vec::new(), Vec::new());
            let mut ended = false;
            for e in &out.events {
                match *e {
                    GameEvent::TouchBegin { a, b, .. } => {
                        prop_assert!(!ended, "frame {}: a begin after an end", frame);
                        prop_assert!(a < b);
                        prop_assert!(recorded.contains(&(a, b)), "frame {}: no record", frame);
                        prop_assert!(model.insert((a, b)), "frame {}: began twice", frame);
                        begins.push((a, b));
                    }
                    GameEvent::TouchEnd { a, b } => {
                        ended = true;
                        prop_assert!(model.remove(&(a, b)), "frame {}: ended untouched", frame);
                        ends.push((a, b));
                    }
                    _ => prop_assert!(begins.is_empty() && !ended, "frame {}: order", frame),
                }
            }
            prop_assert!(begins.is_sorted() && ends.is_sorted());
            let touching: Vec<_> = model.iter().copied().collect();
            prop_assert_eq!(sim.touching(), &touching[..], "frame {}", frame);
            let layers = &sim.scenario().world.layers;
            let w = sim.world();
            for &(a, b) in &recorded {
                if let (Some(i), Some(j)) = (w.index_of(a), w.index_of(b))
                    && layers.touches(w.layer[i], w.layer[j])
                {
                    prop_assert!(model.contains(&(a, b)), "frame {}: recorded, not touching", frame);
                }
            }
        }
    }
}
