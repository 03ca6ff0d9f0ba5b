//! Collisions across the wrap seam: in a wrapping world, bodies that overlap through an
//! edge (or a corner) collide exactly as they do when the same scene is shifted by half the
//! world, where they overlap directly.

mod seam_reference;

use ricochet_geom::{Shape, Vec2};
use ricochet_scenes::{layers, scenario};
use ricochet_sim::broad_phase::BroadPhaseKind;
use ricochet_sim::{
    BodyDef, BodyKind, ContactRecord, Doomed, FrameOutput, GameEvent, Phase, Response, Simulation,
    WorldBounds, WorldDef,
};
use seam_reference::{contacts, pentagon, reference};

const SHIP: u8 = 0;
const ROCK: u8 = 1;
const BULLET: u8 = 2;
const HULL: u8 = 3;

/// A wrapping world `0..size` with ship, rock, bullet and hull layers: ship–rock `report`,
/// bullet–rock `destroy` both (bullets swept), hull–rock `separate`.
fn world(size: Vec2) -> WorldDef {
    let mut l = layers(
        &["ship", "rock", "bullet", "hull"],
        &[
            (SHIP, ROCK, Response::Report),
            (BULLET, ROCK, Response::Destroy(Doomed::Both)),
            (HULL, ROCK, Response::Separate),
        ],
    );
    l.set_fast(BULLET);
    WorldDef {
        layers: l,
        bounds: Some(WorldBounds {
            min: Vec2::ZERO,
            max: size,
            wrap: true,
        }),
        ..WorldDef::default()
    }
}

use ricochet_scenes::moving_body as body;

fn circle(r: f64) -> Shape {
    Shape::circle(r).unwrap()
}

const SIZE: Vec2 = Vec2::new(100.0, 80.0);

/// The Asteroids-like scene: every overlapping pair overlaps only through an edge or a
/// corner of the world, and every body lies within 15 units of an edge. Each body moves
/// `shift` (wrapped into the world): by half the world, every pair overlaps directly.
fn asteroids(shift: Vec2) -> Simulation {
    let place = |p: Vec2| {
        let q = p + shift;
        Vec2::new(q.x.rem_euclid(SIZE.x), q.y.rem_euclid(SIZE.y))
    };
    let slow = Vec2::new(0.6, -0.3);
    let bodies = vec![
        // Across the left/right edge: a ship and a large polygon rock (report).
        body("ship", SHIP, circle(1.0), Vec2::new(0.2, 10.0), Vec2::ZERO),
        body("rock_x", ROCK, pentagon(3.0), Vec2::new(97.0, 10.5), slow),
        // Across the top/bottom edge: a small ship and a medium circle rock.
        body(
            "ship_y",
            SHIP,
            circle(0.5),
            Vec2::new(30.0, 79.6),
            Vec2::ZERO,
        ),
        body("rock_y", ROCK, circle(1.5), Vec2::new(30.4, 1.2), -slow),
        // Through the corner: a bullet and a small rock, destroyed both.
        body(
            "bullet",
            BULLET,
            circle(0.2),
            Vec2::new(99.7, 79.8),
            Vec2::ZERO,
        ),
        body(
            "rock_c",
            ROCK,
            pentagon(1.0),
            Vec2::new(0.2, 0.3),
            Vec2::ZERO,
        ),
        // A hull pushed out of a rock through the right edge (separate along the normal).
        body("hull", HULL, circle(2.0), Vec2::new(98.5, 70.0), Vec2::ZERO),
        body(
            "rock_h",
            ROCK,
            circle(1.0),
            Vec2::new(0.5, 70.5),
            Vec2::ZERO,
        ),
        // Near edges but overlapping nothing, through the seam or not.
        body("rock_far", ROCK, circle(2.0), Vec2::new(12.0, 70.0), slow),
        body(
            "ship_far",
            SHIP,
            circle(1.0),
            Vec2::new(90.0, 12.0),
            Vec2::ZERO,
        ),
    ];
    let bodies = bodies
        .into_iter()
        .map(|b| BodyDef {
            position: place(b.position),
            ..b
        })
        .collect();
    Simulation::new(&scenario("seam", world(SIZE), bodies, 60))
}

/// The contacts' pair, phase and response (exact) and depth and normal within `tol`.
fn assert_same_contacts(frame: u64, seam: &[ContactRecord], direct: &[ContactRecord]) {
    let tol = 1e-12;
    let names = |c: &[ContactRecord]| {
        c.iter()
            .map(|c| (c.a, c.b, c.phase, c.response))
            .collect::<Vec<_>>()
    };
    assert_eq!(names(seam), names(direct), "frame {frame}: different pairs");
    for (s, d) in seam.iter().zip(direct) {
        assert!(
            (s.depth - d.depth).abs() <= tol,
            "frame {frame}: depth {} vs {}",
            s.depth,
            d.depth
        );
        assert!(
            (s.normal - d.normal).length() <= tol,
            "frame {frame}: normal {} vs {}",
            s.normal,
            d.normal
        );
        assert!((s.resolved - d.resolved).length() <= tol);
        // The logged poses are next to each other: `b`'s is the image near `a`.
        let rel = |c: &ContactRecord| c.pose_b.position - c.pose_a.position;
        assert!((rel(s) - rel(d)).length() <= 1e-9, "frame {frame}");
    }
}

/// The events, with depths within rounding.
fn assert_same_events(frame: u64, seam: &FrameOutput, direct: &FrameOutput) {
    assert_eq!(seam.events.len(), direct.events.len(), "frame {frame}");
    for (s, d) in seam.events.iter().zip(&direct.events) {
        match (s, d) {
            (
                GameEvent::TouchBegin {
                    a,
                    b,
                    normal,
                    depth,
                    ..
                },
                GameEvent::TouchBegin {
                    a: a2,
                    b: b2,
                    normal: n2,
                    depth: d2,
                    ..
                },
            ) => {
                // The points differ by the shift (through the seam, in `a`'s coordinates).
                assert_eq!((a, b), (a2, b2), "frame {frame}");
                assert!((depth - d2).abs() <= 1e-12, "frame {frame}");
                assert!((*normal - *n2).length() <= 1e-9, "frame {frame}");
            }
            _ => assert_eq!(s, d, "frame {frame}"),
        }
    }
    let removed = |o: &FrameOutput| o.removed.iter().map(|r| r.entity).collect::<Vec<_>>();
    assert_eq!(removed(seam), removed(direct), "frame {frame}");
}

#[test]
fn asteroids_through_the_seam_collide_as_the_scene_shifted_by_half_the_world() {
    let mut seam = asteroids(Vec2::ZERO);
    let mut direct = asteroids(SIZE * 0.5);
    let mut phases = Vec::new();
    for frame in 0..=30 {
        let (s, d) = (seam.step(), direct.step());
        assert_same_contacts(frame, &s.contacts, &d.contacts);
        assert_same_events(frame, &s, &d);
        phases.extend(s.contacts.iter().map(|c| (c.phase, c.response)));
    }
    // Every response was met, at least once, through the seam.
    for expected in [
        (Phase::All, Response::Report),
        (Phase::Swept, Response::Destroy(Doomed::Both)),
        (Phase::All, Response::Separate),
    ] {
        assert!(phases.contains(&expected), "{expected:?} in {phases:?}");
    }
    // The bullet and its rock are gone, the ship and the hull are not.
    for (name, alive) in [("bullet", false), ("rock_c", false), ("ship", true)] {
        assert_eq!(seam.world().find(name).is_some(), alive, "{name}");
    }
}

#[test]
fn ship_and_rock_overlap_through_the_seam_of_a_100_wide_world() {
    let w = world(Vec2::splat(100.0));
    let bodies = vec![
        body("ship", SHIP, circle(1.0), Vec2::new(0.5, 50.0), Vec2::ZERO),
        body("rock", ROCK, circle(1.0), Vec2::new(99.5, 50.0), Vec2::ZERO),
    ];
    let mut sim = Simulation::new(&scenario("seam", w, bodies, 1));
    let out = sim.step();
    assert_eq!(out.contacts.len(), 1, "{:?}", out.contacts);
    let c = &out.contacts[0];
    assert_eq!(c.depth, 1.0);
    // From the ship (at 0.5) to the rock's image at 99.5 - 100 = -0.5: along -x.
    assert_eq!(c.normal, Vec2::new(-1.0, 0.0));
    assert_eq!(c.pose_a.position, Vec2::new(0.5, 50.0));
    assert_eq!(c.pose_b.position, Vec2::new(-0.5, 50.0));
    assert_eq!(c.response, Response::Report);
}

#[test]
fn a_bullet_crossing_the_edge_in_a_frame_hits_the_rock_beyond_it() {
    // 10 units a frame from x = 95: the frame ends at 105 (wrapped to 5 after detect),
    // passing the rock at x = 2 (its image at 102) on the way.
    let w = world(Vec2::splat(100.0));
    let bodies = vec![
        body(
            "bullet",
            BULLET,
            circle(0.2),
            Vec2::new(95.0, 50.0),
            Vec2::new(600.0, 0.0),
        ),
        body("rock", ROCK, circle(1.0), Vec2::new(2.0, 50.0), Vec2::ZERO),
    ];
    let mut sim = Simulation::new(&scenario("seam", w, bodies, 2));
    assert!(sim.step().contacts.is_empty());
    let out = sim.step();
    assert_eq!(out.contacts.len(), 1, "{:?}", out.contacts);
    let c = &out.contacts[0];
    assert_eq!(c.phase, Phase::Swept);
    // First touch: the bullet's front (x + 0.2) meets the image's back (102 - 1).
    assert!((c.pose_b.position.x - 102.0).abs() < 1e-12);
    assert!(
        (c.pose_a.position.x - 100.8).abs() < 1e-6,
        "{}",
        c.pose_a.position
    );
    assert_eq!(out.removed.len(), 2);
}

#[test]
fn the_deepest_of_a_direct_and_a_seam_overlap_is_the_contact() {
    // A rock wider than half the world overlaps the ship directly and through the seam.
    let w = world(Vec2::splat(10.0));
    let bodies = vec![
        body("ship", SHIP, circle(1.0), Vec2::new(1.0, 5.0), Vec2::ZERO),
        body("rock", ROCK, circle(4.0), Vec2::new(6.5, 5.0), Vec2::ZERO),
    ];
    let mut sim = Simulation::new(&scenario("seam", w, bodies, 1));
    let out = sim.step();
    assert_eq!(out.contacts.len(), 1);
    // Directly 5.5 apart (depth -0.5); through the seam 4.5 (depth 0.5).
    let c = &out.contacts[0];
    assert_eq!(c.depth, 0.5);
    assert_eq!(c.pose_b.position.x, -3.5);
    // Centred: directly and through the seam 5 apart, a tie: the direct one.
    let bodies = vec![
        body("ship", SHIP, circle(1.0), Vec2::new(1.0, 5.0), Vec2::ZERO),
        body("rock", ROCK, circle(4.5), Vec2::new(6.0, 5.0), Vec2::ZERO),
    ];
    let mut sim = Simulation::new(&scenario("seam", world(Vec2::splat(10.0)), bodies, 1));
    let c = sim.step().contacts[0].clone();
    assert_eq!(c.depth, 0.5);
    assert_eq!(c.pose_b.position.x, 6.0);
}

#[test]
fn a_static_body_across_the_edge_is_met_by_the_images_of_moving_ones() {
    let w = world(Vec2::splat(100.0));
    let mut wall = body("wall", ROCK, circle(2.0), Vec2::new(0.5, 20.0), Vec2::ZERO);
    wall.kind = BodyKind::Static;
    let bodies = vec![
        wall,
        body("ship", SHIP, circle(1.0), Vec2::new(99.0, 20.0), Vec2::ZERO),
    ];
    let mut sim = Simulation::new(&scenario("seam", w, bodies, 1));
    let out = sim.step();
    assert_eq!(out.contacts.len(), 1);
    assert_eq!(out.contacts[0].depth, 1.5);
}

#[test]
fn every_broad_phase_finds_every_pair_through_the_seam_of_a_random_crowd() {
    let size = Vec2::new(60.0, 40.0);
    let bounds = WorldBounds {
        min: Vec2::new(-10.0, 5.0),
        max: Vec2::new(-10.0, 5.0) + size,
        wrap: true,
    };
    let mut rng = ricochet_scenes::Rng::new(7);
    let mut bodies = Vec::new();
    for k in 0..200 {
        let r = rng.range(0.2, 3.0);
        let shape = if k % 3 == 0 { pentagon(r) } else { circle(r) };
        // Some a little outside the world, as a body is before `bounds` wraps it.
        let at = Vec2::new(
            rng.range(bounds.min.x - 2.0, bounds.max.x + 2.0),
            rng.range(bounds.min.y - 2.0, bounds.max.y + 2.0),
        );
        // Fast enough to cross an edge now and then, and to change the reach each frame.
        let v = Vec2::new(rng.range(-40.0, 40.0), rng.range(-40.0, 40.0));
        let mut b = body(&format!("b{k}"), 0, shape, at, v);
        if k % 7 == 0 {
            b.kind = BodyKind::Static;
        }
        b.angle = rng.range(0.0, 6.0);
        bodies.push(b);
    }
    let mut l = layers(&["rock"], &[(0, 0, Response::Report)]);
    l.set(0, 0, Response::Report);
    for kind in [
        BroadPhaseKind::BruteForce,
        BroadPhaseKind::SortAndSweep,
        BroadPhaseKind::Grid,
        BroadPhaseKind::Quadtree,
        BroadPhaseKind::Tree,
        BroadPhaseKind::Auto,
    ] {
        let world = WorldDef {
            layers: l.clone(),
            bounds: Some(bounds),
            broad_phase: kind,
            ..WorldDef::default()
        };
        let mut sim = Simulation::new(&scenario("crowd", world, bodies.clone(), 12));
        sim.capture_detect_poses = true;
        let mut seam = 0;
        for frame in 0..=12 {
            let out = sim.step();
            let expected = reference(&sim, &out, &bounds, |_, _| true);
            let poses = out.detect_poses.as_ref().unwrap();
            let found = contacts(&sim, &out);
            seam += found
                .iter()
                .filter(|c| c.3 != poses[c.1].1.position)
                .count();
            assert_eq!(found, expected, "{kind:?}, frame {frame}");
        }
        assert!(seam > 50, "{kind:?}: {seam} contacts through the seam");
    }
}
