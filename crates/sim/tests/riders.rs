//! Riders: a box standing on a kinematic box (a lift) moves with it, is pushed by it, and is
//! crushed (an event, nothing removed) when the lift pushes it into a wall with no room.
//!
//! Expected values come from the lift's own motion, replayed with the `f64` operations the
//! stages do: the lift moves by `v * dt` in `move_x`/`move_y`, and its rider by the same
//! `v * dt` before its own motion. Positions along the carried axis are compared bit for bit;
//! a rider's bottom against the lift's top to the rounding of one push (`SLOP` is far above).

use ricochet_geom::{Bounds, Vec2};
use ricochet_scenes::tiles::Tiles;
use ricochet_sim::{
    Action, BodyKind, Controller, Entity, FrameOutput, GameEvent, JumpOutcome, SLOP, ScriptInput,
    Simulation,
};

/// Gravity of every scene here, units/s².
const G: f64 = -20.0;

/// The lift's half extents: 3 wide, 0.5 high.
const LIFT: [f64; 2] = [1.5, 0.25];

/// A kinematic lift (on the tile layer, still until told) centred at `at`, and a box of half
/// extents 0.4 standing on it 0.3 right of its centre.
fn lift_and_box(at: [f64; 2]) -> Tiles {
    Tiles::new("box", G)
        .tile("lift", LIFT, at)
        .with(|b| b.kind = BodyKind::Kinematic)
        .aabb("box", [0.4, 0.4], [at[0] + 0.3, at[1] + 0.25 + 0.4])
}

fn entity(s: &Simulation, name: &str) -> Entity {
    s.entity_named(name)
        .unwrap_or_else(|| panic!("{name} is alive"))
}

/// The box's bounds, as the per-axis stages compute them (centre ± half extents).
fn bounds(s: &Simulation, e: Entity, half: [f64; 2]) -> Bounds {
    Bounds::around(s.position(e).unwrap(), Vec2::from(half))
}

/// The crushes of a frame, as `(body, by, axis)`.
fn crushes(out: &FrameOutput) -> Vec<(Entity, Entity, u8)> {
    out.events
        .iter()
        .filter_map(|e| match e {
            GameEvent::Crushed { body, by, axis } => Some((*body, *by, *axis)),
            _ => None,
        })
        .collect()
}

/// Asserts that `rider` (half extents `half`) stands on the lift (half extents [`LIFT`]): its
/// bottom on the lift's top to rounding, overlapping it along x, grounded.
fn stands_on_lift(s: &Simulation, rider: Entity, half: [f64; 2], lift: Entity, when: &str) {
    stands_on(s, (rider, half), (lift, LIFT), when);
}

/// [`stands_on_lift`] for a lift of any size.
fn stands_on(s: &Simulation, rider: (Entity, [f64; 2]), lift: (Entity, [f64; 2]), when: &str) {
    let (r, l) = (bounds(s, rider.0, rider.1), bounds(s, lift.0, lift.1));
    let rider = rider.0;
    let gap = r.min.y - l.max.y;
    // One push rounds `y + (top - bottom)` and the bounds `y - h`: a few ulps of the
    // coordinates (here below 20), nowhere near SLOP.
    assert!(
        gap.abs() <= 1e-13,
        "{when}: the rider is {gap} above the lift's top"
    );
    assert!(
        r.max.x > l.min.x && r.min.x < l.max.x,
        "{when}: off the lift"
    );
    assert_eq!(s.grounded(rider), Some(true), "{when}");
}

#[test]
fn a_box_rides_a_lift_right_left_up_down_and_diagonally() {
    let mut s = Simulation::new(&lift_and_box([0.0, 0.0]).scenario());
    let (lift, rider) = (entity(&s, "lift"), entity(&s, "box"));
    s.step(); // frame 0: nothing moves
    s.step(); // frame 1: the box settles on the still lift, and rides it from now on
    assert_eq!(s.world().carrier(1), Some(lift));
    let dt = s.dt();
    let mut lift_at = s.position(lift).unwrap();
    let mut rider_x = s.position(rider).unwrap().x;
    let offset = rider_x - lift_at.x;
    let moves = [
        Vec2::new(3.0, 0.0),
        Vec2::new(-3.0, 0.0),
        Vec2::new(0.0, 3.0),
        Vec2::new(0.0, -3.0),
        Vec2::new(2.5, -1.5),
        Vec2::new(-1.25, 2.0),
    ];
    for v in moves {
        s.apply(lift, Action::SetVelocity(v)).unwrap();
        for k in 0..60 {
            let out = s.step();
            let when = format!("lift at {v}, frame {k}");
            // The lift's own motion, replayed...
            lift_at.x += v.x * dt;
            lift_at.y += v.y * dt;
            assert_eq!(s.position(lift), Some(lift_at), "{when}");
            // ... and the rider carried by exactly the same steps along x (it has no x
            // velocity of its own, and `x + 0` is `x`).
            if v.x * dt != 0.0 {
                rider_x += v.x * dt;
            }
            let at = s.position(rider).unwrap();
            assert_eq!(at.x.to_bits(), rider_x.to_bits(), "{when}");
            assert!(
                (at.x - lift_at.x - offset).abs() <= 1e-14,
                "{when}: offset {}",
                at.x - lift_at.x
            );
            stands_on_lift(&s, rider, [0.4, 0.4], lift, &when);
            assert!(crushes(&out).is_empty(), "{when}: {:?}", out.events);
            assert_eq!(s.world().carrier(1), Some(lift), "{when}");
        }
    }
}

#[test]
fn a_lift_driven_by_the_script_carries_a_box_in_a_scenario_file() {
    // The same through `set_velocity` events: right for a second, then down for a second.
    let mut s = Simulation::new(
        &lift_and_box([0.0, 5.0])
            .event(ricochet_sim::Event {
                frame: 2,
                action: ricochet_sim::ScriptAction::Body {
                    name: "lift".to_owned(),
                    action: Action::SetVelocity(Vec2::new(3.0, 0.0)),
                },
            })
            .event(ricochet_sim::Event {
                frame: 62,
                action: ricochet_sim::ScriptAction::Body {
                    name: "lift".to_owned(),
                    action: Action::SetVelocity(Vec2::new(0.0, -3.0)),
                },
            })
            .scenario(),
    );
    let (lift, rider) = (entity(&s, "lift"), entity(&s, "box"));
    let start = s.position(rider).unwrap();
    for frame in 0..=121 {
        s.step();
        if frame >= 1 {
            stands_on_lift(&s, rider, [0.4, 0.4], lift, &format!("frame {frame}"));
        }
    }
    // 60 frames right at 3 units/s: 3 units (to rounding), as far as the lift went.
    let (l, r) = (s.position(lift).unwrap(), s.position(rider).unwrap());
    assert!((r.x - start.x - 3.0).abs() < 1e-12, "{r}");
    assert!((r.x - l.x - 0.3).abs() < 1e-14, "{r} on {l}");
    assert!((l.y - 2.0).abs() < 1e-12, "down 3 units: {l}");
}

#[test]
fn a_runner_rides_a_lift_jumps_off_it_and_lands_back_on_it() {
    // A wide lift (16 across) moving right at 3 units/s; a runner with no run input.
    let mut s = Simulation::new(
        &Tiles::new("box", G)
            .tile("lift", [8.0, 0.25], [0.0, 0.0])
            .with(|b| {
                b.kind = BodyKind::Kinematic;
                b.velocity = Vec2::new(3.0, 0.0);
            })
            .aabb("runner", [0.4, 0.8], [-2.0, 1.05])
            .with(|b| {
                b.controller = Some(Controller::Runner {
                    run_speed: 5.0,
                    jump_speed: 10.0,
                });
            })
            .scenario(),
    );
    let (lift, runner) = (entity(&s, "lift"), entity(&s, "runner"));
    let dt = s.dt();
    s.step(); // frame 0
    s.step(); // frame 1: lands on the lift (which slid 0.05 under it)
    let offset = s.position(runner).unwrap().x - s.position(lift).unwrap().x;
    for k in 0..30 {
        s.step();
        let x = s.position(runner).unwrap().x - s.position(lift).unwrap().x;
        assert!((x - offset).abs() < 1e-13, "frame {k}: offset {x}");
        let when = format!("riding, {k}");
        stands_on(&s, (runner, [0.4, 0.8]), (lift, [8.0, 0.25]), &when);
    }
    s.apply(runner, Action::Jump).unwrap();
    let out = s.step();
    assert!(out.events.contains(&GameEvent::Input {
        body: runner,
        input: ScriptInput::Jump(JumpOutcome::Jumped),
    }));
    // The frame of the jump it stood on the lift: carried once more. Then it flies straight
    // up while the lift moves on under it.
    let x = s.position(runner).unwrap().x;
    let mut airborne = 0;
    loop {
        s.step();
        if s.grounded(runner) == Some(true) {
            break;
        }
        airborne += 1;
        assert_eq!(s.position(runner).unwrap().x, x, "in the air, not carried");
        assert_eq!(s.world().carrier(1), None);
        assert!(airborne < 120, "it lands");
    }
    // 10 units/s up at 20 units/s² down: about a second in the air, while the lift went about
    // 3 units right; the runner lands on it about 3 units further left, and rides again.
    assert!(
        (55..=62).contains(&airborne),
        "{airborne} frames in the air"
    );
    let offset = s.position(runner).unwrap().x - s.position(lift).unwrap().x;
    assert!(
        (offset - (-2.0 - 3.0 * dt * airborne as f64)).abs() < 0.2,
        "{offset}"
    );
    for k in 0..30 {
        s.step();
        let x = s.position(runner).unwrap().x - s.position(lift).unwrap().x;
        assert!(
            (x - offset).abs() < 1e-13,
            "frame {k} after landing: offset {x}"
        );
        let when = format!("landed, {k}");
        stands_on(&s, (runner, [0.4, 0.8]), (lift, [8.0, 0.25]), &when);
    }
}

#[test]
fn a_box_with_no_gravity_still_rides_a_lift_it_rests_on() {
    // Never pressed into the lift, so never pushed up by it: it still rides (flush on top).
    let mut s = Simulation::new(
        &lift_and_box([0.0, 0.0])
            .with(|b| b.velocity = Vec2::new(0.0, -1.0))
            .with(|b| b.gravity_scale = 0.0)
            .scenario(),
    );
    let (lift, rider) = (entity(&s, "lift"), entity(&s, "box"));
    s.step();
    s.step(); // lands (its y velocity zeroed), and rides from now on
    s.apply(lift, Action::SetVelocity(Vec2::new(-2.0, 0.0)))
        .unwrap();
    let offset = s.position(rider).unwrap().x - s.position(lift).unwrap().x;
    for k in 0..120 {
        s.step();
        let x = s.position(rider).unwrap().x - s.position(lift).unwrap().x;
        assert!((x - offset).abs() < 1e-13, "frame {k}: offset {x}");
        assert_eq!(s.world().carrier(1), Some(lift), "frame {k}");
    }
}

#[test]
fn a_stack_of_boxes_rides_a_lift() {
    // Box on box on lift: the top box rides the box under it, which rides the lift.
    let mut s = Simulation::new(
        &lift_and_box([0.0, 0.0])
            .solid()
            .aabb("top", [0.3, 0.3], [0.2, 0.25 + 0.8 + 0.3])
            .scenario(),
    );
    let (lift, top) = (entity(&s, "lift"), entity(&s, "top"));
    s.step();
    s.step();
    assert_eq!(s.world().carrier(2), Some(entity(&s, "box")));
    for v in [
        Vec2::new(3.0, 0.0),
        Vec2::new(0.0, -3.0),
        Vec2::new(-2.0, 1.0),
    ] {
        s.apply(lift, Action::SetVelocity(v)).unwrap();
        let offset = s.position(top).unwrap().x - s.position(lift).unwrap().x;
        for k in 0..60 {
            s.step();
            let (t, l) = (bounds(&s, top, [0.3, 0.3]), bounds(&s, lift, LIFT));
            let x = s.position(top).unwrap().x - s.position(lift).unwrap().x;
            assert!((x - offset).abs() < 1e-13, "{v}, frame {k}: offset {x}");
            assert!(
                (t.min.y - (l.max.y + 0.8)).abs() < 1e-12,
                "{v}, frame {k}: {t:?} over {l:?}"
            );
        }
    }
}

/// A lift (still) with a box on it, under a static ceiling whose bottom is at `ceiling_y`:
/// the lift, the ceiling and the box in that id order, or the ceiling first.
fn under_ceiling(ceiling_first: bool, ceiling_y: f64) -> Simulation {
    let ceiling = |t: Tiles| t.tile("ceiling", [4.0, 0.5], [0.0, ceiling_y + 0.5]);
    let mut t = Tiles::new("box", G);
    if ceiling_first {
        t = ceiling(t);
    }
    t = t
        .tile("lift", LIFT, [0.0, 0.0])
        .with(|b| b.kind = BodyKind::Kinematic);
    if !ceiling_first {
        t = ceiling(t);
    }
    Simulation::new(&t.aabb("box", [0.4, 0.4], [0.3, 0.65]).scenario())
}

#[test]
fn a_lift_moving_up_into_a_box_under_a_ceiling_crushes_it() {
    for ceiling_first in [false, true] {
        // The box (0.8 high) on the lift (top at 0.25) has its top at 1.05; the ceiling's
        // bottom is at 2.025, so the lift has 0.975 to go: at 3 units/s (0.05 a frame) the
        // box has no room in the 20th frame of the climb (0.95 < 0.975 < 1.0).
        let mut s = under_ceiling(ceiling_first, 2.025);
        let (lift, rider) = (entity(&s, "lift"), entity(&s, "box"));
        s.step();
        s.step();
        s.apply(lift, Action::SetVelocity(Vec2::new(0.0, 3.0)))
            .unwrap();
        let dt = s.dt();
        let mut top = 0.25;
        // Up to the first crush: after it the box overlaps the ceiling, and what the next
        // passes do with it (push it out by the shortest way) is the game's business.
        for k in 1..=20 {
            let out = s.step();
            top += 3.0 * dt;
            let no_room = top + 0.8 - 2.025 > SLOP;
            assert_eq!(no_room, k == 20, "climb frame {k}");
            if no_room {
                assert_eq!(crushes(&out), [(rider, lift, 1)], "{:?}", out.events);
            } else {
                assert!(
                    crushes(&out).is_empty(),
                    "climb frame {k}: {:?}",
                    out.events
                );
                stands_on_lift(&s, rider, [0.4, 0.4], lift, &format!("climb frame {k}"));
            }
        }
        assert!(s.contains(rider), "the engine removes nothing");
    }
}

#[test]
fn a_lift_pushes_a_box_along_its_motion_and_crushes_it_against_a_wall() {
    // A lift sliding right along the floor (its top below the box's) pushes a box standing
    // on the floor ahead of it, flush against its right face, until the box meets the wall.
    let mut s = Simulation::new(
        &Tiles::new("box", G)
            .tile("floor", [10.0, 0.5], [0.0, -0.5])
            .tile("wall", [0.5, 2.0], [4.5, 2.0])
            .tile("lift", [1.0, 0.5], [-2.0, 0.5])
            .with(|b| {
                b.kind = BodyKind::Kinematic;
                b.velocity = Vec2::new(3.0, 0.0);
            })
            .aabb("box", [0.4, 0.4], [-0.5, 0.4])
            .scenario(),
    );
    let (lift, rider) = (entity(&s, "lift"), entity(&s, "box"));
    // The lift's face starts at x = -1 and moves 0.05 a frame; it meets the box (left side at
    // -0.9) at frame 2, and has pushed it against the wall (at x = 4, the box's left side at
    // 3.2) at frame 84: from frame 85 on the box has no room.
    let mut crushed = None;
    for frame in 0..=120 {
        let out = s.step();
        if let Some(&c) = crushes(&out).first() {
            assert_eq!(c, (rider, lift, 0), "frame {frame}: {:?}", out.events);
            crushed = Some(frame);
            break;
        }
        let (b, l) = (bounds(&s, rider, [0.4, 0.4]), bounds(&s, lift, [1.0, 0.5]));
        if frame >= 2 {
            // Pushed along the lift's motion: flush with its right face, to rounding.
            assert!(
                (b.min.x - l.max.x).abs() < 1e-13,
                "frame {frame}: {b:?} {l:?}"
            );
        }
    }
    assert_eq!(crushed, Some(85));
    assert!(s.contains(rider), "the engine removes nothing");
}

#[test]
fn a_rider_carried_into_a_wall_stops_at_it_and_the_lift_slides_on() {
    // The lift (top at 0.25) passes under a wall whose bottom is at 0.5: the box on it (0.8
    // high) is stopped flush at the wall's left face (x = 3), not crushed, and falls once the
    // lift has slid from under it.
    let mut s = Simulation::new(
        &lift_and_box([0.0, 0.0])
            .tile("wall", [0.5, 2.0], [3.5, 2.5])
            .scenario(),
    );
    let (lift, rider) = (entity(&s, "lift"), entity(&s, "box"));
    s.step();
    s.step();
    s.apply(lift, Action::SetVelocity(Vec2::new(3.0, 0.0)))
        .unwrap();
    let mut stopped = false;
    for frame in 0..120 {
        let out = s.step();
        assert!(crushes(&out).is_empty(), "frame {frame}: {:?}", out.events);
        let b = bounds(&s, rider, [0.4, 0.4]);
        assert!(b.max.x <= 3.0 + SLOP, "frame {frame}: {b:?} in the wall");
        stopped |= (b.max.x - 3.0).abs() <= 1e-12;
    }
    assert!(stopped, "it reached the wall");
    let (b, l) = (bounds(&s, rider, [0.4, 0.4]), bounds(&s, lift, LIFT));
    assert!(l.min.x > b.max.x, "the lift slid on: {l:?}, {b:?}");
    assert!(b.max.y < l.max.y, "and the box fell: {b:?}");
    assert_eq!(s.world().carrier(1), None);
}

#[test]
fn a_rider_moved_by_the_game_rides_nothing_until_it_lands_again() {
    // Taken off a moving lift with `set_position`, the box is not carried by the lift it left:
    // it falls straight down (x unchanged) until it lands on the floor below.
    let mut s = Simulation::new(
        &lift_and_box([0.0, 3.0])
            .tile("floor", [10.0, 0.5], [0.0, -0.5])
            .scenario(),
    );
    let (lift, rider) = (entity(&s, "lift"), entity(&s, "box"));
    s.step();
    s.step();
    s.apply(lift, Action::SetVelocity(Vec2::new(3.0, 0.0)))
        .unwrap();
    s.step();
    assert_eq!(s.world().carrier(1), Some(lift));
    s.set_position(rider, Vec2::new(-5.0, 2.0)).unwrap();
    assert_eq!(s.world().carrier(1), None);
    for frame in 0..60 {
        s.step();
        assert_eq!(s.position(rider).unwrap().x, -5.0, "frame {frame}");
    }
    assert_eq!(s.grounded(rider), Some(true), "on the floor");
}
