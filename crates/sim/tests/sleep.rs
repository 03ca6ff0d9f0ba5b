//! The `sleep` stage (`crates/sim/src/stages/sleep.rs`): resting bodies fall asleep without
//! changing any state, and wake when something touches them. See `common/mod.rs` for how the
//! expected values are found.

mod common;

use common::*;
use ricochet_geom::Vec2;
use ricochet_scenes::tiles::Tiles;
use ricochet_sim::{Action, Event, GameEvent, Phase, ScriptAction, Simulation, Stage};

#[test]
fn sleeping_that_never_triggers_changes_nothing() {
    let mut plain = sim(&busy_scene("", ""));
    let mut sleepy = sim(&busy_scene("sleep_after = 1000", ""));
    let mut totals = Totals::default();
    let mut moving_frames = 0;
    run_side_by_side(&mut plain, &mut sleepy, 300, |a, b, _, s| {
        totals.add(a);
        assert_eq!(b.stats.asleep, 0, "frame {}: a body fell asleep", b.frame);
        assert!(
            (0..s.world().len()).all(|i| !s.world().asleep(i)),
            "frame {}",
            b.frame
        );
        if b.frame > 0 {
            assert!(
                b.stats.stages_run.contains(Stage::Sleep),
                "frame {}",
                b.frame
            );
        }
        assert_eq!(
            stats_without_stages(&a.stats),
            stats_without_stages(&b.stats),
            "frame {}",
            a.frame
        );
        moving_frames += usize::from(b.frame > 0 && b.stats.kinetic_energy > 0.0);
    });
    totals.assert_busy();
    // Things move the whole run (the ghost never stops).
    assert_eq!(moving_frames, 300, "frames 1 to 300 all have motion");
}

/// A static floor (top at y = 0, 20 wide) under gravity `[0, -20]`, for boxes solid to it
/// and to each other.
fn boxes_on_a_floor() -> Tiles {
    Tiles::new("box", -20.0)
        .solid()
        .tile("floor", [10.0, 1.0], [0.0, -1.0])
}

/// Boxes dropped onto a static floor (top at y = 0) under gravity `[0, -20]`: `lone` on its
/// own, and `low` with `high` falling onto it (a stack of two); boxes are solid to each
/// other. More bodies can be added to the builder.
fn boxes(sleep_after: Option<u32>) -> Tiles {
    boxes_on_a_floor()
        .sleep_after(sleep_after)
        .aabb("lone", [0.5, 0.5], [-4.3, 3.1])
        .aabb("low", [0.7, 0.35], [2.15, 1.7])
        .aabb("high", [0.4, 0.6], [2.4, 3.9])
}

/// Asserts what the docs promise a sleeper: zero velocity, `grounded` kept, not integrated.
fn assert_sleepers_rest(sim: &Simulation, frame: u64) {
    let w = sim.world();
    for i in 0..w.len() {
        if w.asleep(i) {
            assert_eq!(
                w.velocity(i),
                ricochet_geom::Vec2::ZERO,
                "frame {frame}: {}",
                w.name(i)
            );
            assert!(
                w.grounded(i),
                "frame {frame}: {} sleeps ungrounded",
                w.name(i)
            );
            assert!(
                !w.active().contains(&(i as u32)),
                "frame {frame}: {}",
                w.name(i)
            );
        }
    }
    assert_eq!(
        (0..w.len()).filter(|&i| w.asleep(i)).count(),
        w.sleeping(),
        "frame {frame}"
    );
}

#[test]
fn resting_boxes_fall_asleep_without_changing_any_state() {
    let mut plain = Simulation::new(&boxes(None).scenario());
    let mut sleepy = Simulation::new(&boxes(Some(10)).scenario());
    // The lone box and the bottom of the stack rest on the static floor and sleep; the top
    // of the stack rests on a dynamic box, so it never sleeps (it would float if that box
    // moved away).
    let n_boxes = 2;
    let (mut contacts_plain, mut contacts_sleepy) = (0, 0);
    let mut all_asleep = 0;
    for frame in 0..=300u64 {
        let a = plain.step();
        let b = sleepy.step();
        // Skipping a body at a fixed point of the step changes nothing: not one bit.
        assert_eq!(
            plain.world().digest(),
            sleepy.world().digest(),
            "frame {frame}: digests differ\nplain: {:?} {:?}\nsleepy: {:?} {:?}",
            plain.world().position,
            (0..plain.world().len())
                .map(|i| plain.world().velocity(i))
                .collect::<Vec<_>>(),
            sleepy.world().position,
            (0..sleepy.world().len())
                .map(|i| sleepy.world().velocity(i))
                .collect::<Vec<_>>(),
        );
        assert_eq!(
            a.stats.asleep, 0,
            "frame {frame}: nothing sleeps without sleep_after"
        );
        assert_eq!(b.stats.asleep, sleepy.world().sleeping(), "frame {frame}");
        assert_sleepers_rest(&sleepy, frame);
        contacts_plain += a.contacts.len();
        contacts_sleepy += b.contacts.len();
        all_asleep += usize::from(b.stats.asleep == n_boxes);
    }
    assert!(
        all_asleep > 0,
        "the two boxes on the floor were never both asleep"
    );
    assert_eq!(sleepy.world().sleeping(), n_boxes, "all asleep at the end");
    // Every box resting in the plain run is pushed out of what holds it once a frame.
    assert!(
        contacts_sleepy < contacts_plain,
        "sleeping skipped no resting contact: {contacts_sleepy} vs {contacts_plain}"
    );
    assert!(
        contacts_plain - contacts_sleepy >= all_asleep * n_boxes,
        "{contacts_plain} - {contacts_sleepy} contacts; all asleep for {all_asleep} frames"
    );
}

/// A small box that falls from high above `lone` (top at y = 1 once it rests) and lands on
/// it long after `lone` fell asleep.
fn with_dropper(scene: Tiles) -> Simulation {
    Simulation::new(&scene.aabb("dropper", [0.3, 0.3], [-4.1, 80.0]).scenario())
}

#[test]
fn a_sleeping_box_wakes_when_something_lands_on_it() {
    let mut plain = with_dropper(boxes(None));
    let mut sleepy = with_dropper(boxes(Some(10)));
    let (lone, dropper) = (index(&sleepy, "lone"), index(&sleepy, "dropper"));
    let (e_lone, e_dropper) = (sleepy.world().entity[lone], sleepy.world().entity[dropper]);
    // Free fall from rest, semi-implicit Euler: after n moves it has fallen
    // n(n+1)/2 g dt². It overlaps `lone` once its bottom (y - 0.3) passes 1: after 78.7.
    let dt = 1.0 / 60.0;
    let landing = (1..)
        .find(|&n: &u64| (n * (n + 1)) as f64 / 2.0 * 20.0 * dt * dt > 80.0 - 0.3 - 1.0)
        .unwrap();
    assert_eq!(
        landing, 168,
        "n(n+1) > 78.7 * 360 = 28332 first for n = 168"
    );
    let mut landed_at = None;
    let mut asleep_before = false;
    for frame in 0..=300u64 {
        let a = plain.step();
        let b = sleepy.step();
        assert_eq!(
            plain.world().digest(),
            sleepy.world().digest(),
            "frame {frame}: digests differ\nplain: {:?} {:?}\nsleepy: {:?} {:?}",
            plain.world().position,
            (0..plain.world().len())
                .map(|i| plain.world().velocity(i))
                .collect::<Vec<_>>(),
            sleepy.world().position,
            (0..sleepy.world().len())
                .map(|i| sleepy.world().velocity(i))
                .collect::<Vec<_>>(),
        );
        assert!(a.contacts.len() >= b.contacts.len(), "frame {frame}");
        assert_sleepers_rest(&sleepy, frame);
        let hit = b
            .contacts
            .iter()
            .any(|c| (c.a, c.b) == (e_lone, e_dropper) && c.phase == Phase::Y);
        if hit && landed_at.is_none() {
            landed_at = Some(frame);
            assert!(asleep_before, "frame {frame}: lone was not asleep when hit");
            assert!(
                !sleepy.world().asleep(lone),
                "frame {frame}: lone still asleep after the landing"
            );
            assert!(
                b.events.iter().any(|e| matches!(e,
                    GameEvent::TouchBegin { a, b, .. } if (*a, *b) == (e_lone, e_dropper))),
                "{:?}",
                b.events
            );
        }
        asleep_before = sleepy.world().asleep(lone);
    }
    assert_eq!(
        landed_at,
        Some(landing),
        "the dropper lands when free fall says"
    );
    // Both settle again: the two boxes on the floor end asleep; the stack's top and the
    // dropper rest on dynamic boxes, so they never sleep.
    assert_eq!(sleepy.world().sleeping(), 2);
}

/// Steps a scene with and without `sleep_after = 10` and asserts the digests agree on every
/// frame.
fn sleeping_changes_nothing(scene: Tiles, frames: u64) -> (Simulation, Simulation) {
    let mut plain = Simulation::new(&scene.clone().scenario());
    let mut sleepy = Simulation::new(&scene.sleep_after(Some(10)).scenario());
    for frame in 0..=frames {
        plain.step();
        let out = sleepy.step();
        assert_eq!(
            plain.world().digest(),
            sleepy.world().digest(),
            "frame {frame}: digests differ (asleep {:?}, active {:?})\nplain:  {:?}\nsleepy: {:?}",
            (0..sleepy.world().len())
                .map(|i| sleepy.world().asleep(i))
                .collect::<Vec<_>>(),
            sleepy.world().active(),
            plain.world().position,
            sleepy.world().position,
        );
        assert_eq!(out.stats.asleep, sleepy.world().sleeping(), "frame {frame}");
    }
    (plain, sleepy)
}

#[test]
fn a_woken_body_is_simulated_from_the_next_frame() {
    // `sitter` rests on the ledge, 0.01 from its right edge (x = 2), and falls asleep; the
    // gravity-free `bowler` rolls into it at frame 43 and pushes it half the depth (0.055)
    // past the edge. Without sleeping it rolls off the corner and falls from frame 44.
    let scene = Tiles::new("ball", -20.0)
        .solid()
        .tile("ledge", [25.0, 1.0], [-23.0, -1.0])
        .ball("sitter", 0.5, [1.99, 0.5])
        .ball("bowler", 0.5, [-20.4, 0.5])
        .with(|b| {
            b.velocity = Vec2::new(30.0, 0.0);
            b.gravity_scale = 0.0;
        });
    let (plain, sleepy) = sleeping_changes_nothing(scene, 80);
    assert!(plain.world().position[index(&plain, "sitter")].y < 0.2);
    assert_eq!(sleepy.world().active(), active_as_documented(&sleepy));
}

#[test]
fn a_box_asleep_on_a_box_falls_when_that_box_slides_away() {
    // Two unit boxes stacked flush on the floor; both rest from frame 1 and sleep from
    // frame 10. At frame 60 the script sends `low` sliding right at 3 units/s; from frame
    // 79 it no longer holds `top` up (x overlap 0.5 - 0.5000000000000002 < 0), and without
    // sleeping `top` falls from then on.
    let scene = boxes_on_a_floor()
        .aabb("low", [0.5, 0.5], [0.0, 0.5])
        .aabb("top", [0.5, 0.5], [0.0, 1.5])
        .event(Event {
            frame: 60,
            action: ScriptAction::Body {
                name: "low".to_owned(),
                action: Action::SetVelocity(Vec2::new(3.0, 0.0)),
            },
        });
    let (plain, sleepy) = sleeping_changes_nothing(scene, 120);
    // Without sleeping, `top` lands on the floor (y = 0.5).
    assert_eq!(plain.world().position[index(&plain, "top")].y, 0.5);
    assert_eq!(sleepy.world().position[index(&sleepy, "top")].y, 0.5);
}
