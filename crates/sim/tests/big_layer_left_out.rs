//! A big layer that meets only far smaller ones (1,100 rocks that never meet each other, met
//! by 60 ships) is left out of the broad phase's entries but for its bodies near a ship
//! (`broad_phase/left_out.rs`, `stages/mover_pairs.rs`): the contacts are still every
//! overlapping ship–rock pair, found here by testing every such pair exactly (through every
//! image of a wrapping world). The rocks turn (their bounds grow on their first turn, past
//! the reach the filter last measured) and some are fast and large, so the bodies sticking
//! out of a wrapping world outgrow the seam's guess: both ask for the entries left out.

mod seam_reference;

use ricochet_geom::{Shape, Vec2};
use ricochet_scenes::{layers, moving_body as body, scenario};
use ricochet_sim::broad_phase::BroadPhaseKind;
use ricochet_sim::{BodyKind, FrameOutput, Response, Simulation, WorldBounds, WorldDef};
use seam_reference::{contacts, pentagon, reference};

const SHIP: u8 = 0;
const ROCK: u8 = 1;
const WALL: u8 = 2;
const FRAMES: u64 = 12;

/// The rocks and ships in `bounds` with the broad phase `kind`, and `walls` static bodies
/// that only the ships meet.
fn simulation(kind: BroadPhaseKind, bounds: WorldBounds, walls: usize) -> Simulation {
    let mut rng = ricochet_scenes::Rng::new(11);
    let span = |rng: &mut ricochet_scenes::Rng| {
        // Some a little outside the world, as a body is before `bounds` wraps it.
        Vec2::new(
            rng.range(bounds.min.x - 2.0, bounds.max.x + 2.0),
            rng.range(bounds.min.y - 2.0, bounds.max.y + 2.0),
        )
    };
    let mut bodies = Vec::new();
    for k in 0..1100 {
        let r = if k % 97 == 0 {
            rng.range(4.0, 6.0)
        } else {
            rng.range(0.3, 2.0)
        };
        let shape = if k % 2 == 0 {
            pentagon(r)
        } else {
            Shape::circle(r).unwrap()
        };
        // The large ones fast: sticking out of the world by more each frame than the seam
        // guessed from the last.
        let speed = match k {
            _ if k % 97 == 0 => 400.0,
            _ if k % 13 == 0 => 60.0,
            _ => 4.0,
        };
        let v = Vec2::new(rng.range(-speed, speed), rng.range(-speed, speed));
        let mut b = body(&format!("rock{k}"), ROCK, shape, span(&mut rng), v);
        b.angle = rng.range(0.0, 6.0);
        b.angular_velocity = rng.range(-2.0, 2.0);
        bodies.push(b);
    }
    for k in 0..60 {
        let v = Vec2::new(rng.range(-20.0, 20.0), rng.range(-20.0, 20.0));
        let shape = Shape::circle(rng.range(0.5, 2.5)).unwrap();
        bodies.push(body(&format!("ship{k}"), SHIP, shape, span(&mut rng), v));
    }
    for k in 0..walls {
        let mut b = body(
            &format!("wall{k}"),
            WALL,
            pentagon(0.4),
            span(&mut rng),
            Vec2::ZERO,
        );
        b.kind = BodyKind::Static;
        bodies.push(b);
    }
    let pairs = [
        (SHIP, ROCK, Response::Report),
        (SHIP, WALL, Response::Report),
    ];
    let world = WorldDef {
        layers: layers(&["ship", "rock", "wall"], &pairs),
        // Without a wrap, no bounds: a body leaving them would be removed.
        bounds: Some(bounds).filter(|b| b.wrap),
        broad_phase: kind,
        ..WorldDef::default()
    };
    let mut sim = Simulation::new(&scenario("rocks", world, bodies, FRAMES));
    sim.capture_detect_poses = true;
    sim
}

/// Steps `sim` (frame 0 too) and checks every frame's contacts against every ship–rock and
/// ship–wall pair tested exactly ([`reference`]).
/// Returns the contacts found.
fn check(mut sim: Simulation, bounds: &WorldBounds, label: &str) -> usize {
    let mut found_any = 0;
    for frame in 0..=sim.scenario().frames {
        let out = sim.step();
        // Ships meet rocks and walls; nothing else meets.
        let meets = |a: u8, b: u8| matches!((a.min(b), a.max(b)), (SHIP, ROCK) | (SHIP, WALL));
        let expected = reference(&sim, &out, bounds, meets);
        let found = contacts(&sim, &out);
        assert_eq!(found, expected, "{label}, frame {frame}");
        found_any += found.len();
    }
    found_any
}

fn every_pair_is_found(wrap: bool) {
    let size = Vec2::new(150.0, 110.0);
    let bounds = WorldBounds {
        min: Vec2::new(-20.0, 5.0),
        max: Vec2::new(-20.0, 5.0) + size,
        wrap,
    };
    for kind in [BroadPhaseKind::Auto, BroadPhaseKind::SortAndSweep] {
        let found = check(
            simulation(kind, bounds, 0),
            &bounds,
            &format!("{kind:?}, wrap {wrap}"),
        );
        assert!(found > 100, "{kind:?}: {found} contacts");
    }
}

#[test]
fn a_big_layer_left_out_of_the_entries_still_meets_every_body_it_overlaps() {
    every_pair_is_found(false);
}

#[test]
fn a_big_layer_left_out_of_the_entries_still_meets_every_body_through_the_seam() {
    every_pair_is_found(true);
}

/// A ship crossing the right edge meets, through the seam, a rock at the left edge that is
/// near no ship directly: its entry is left out, and the seam, whose reach grew past its
/// guess that frame, reads every moving body's entry. The rock is paired all the same.
#[test]
fn a_rock_met_only_through_the_seam_is_paired_when_the_seams_reach_grows() {
    let bounds = WorldBounds {
        min: Vec2::ZERO,
        max: Vec2::splat(200.0),
        wrap: true,
    };
    let circle = |r: f64| Shape::circle(r).unwrap();
    // Still rocks on a lattice in the middle, far from both.
    let mut bodies: Vec<_> = (0..1100)
        .map(|k| {
            let at = Vec2::new(
                50.0 + f64::from(k % 50) * 2.0,
                50.0 + f64::from(k / 50) * 2.0,
            );
            body(&format!("rock{k}"), ROCK, circle(0.3), at, Vec2::ZERO)
        })
        .collect();
    let y = 20.0;
    bodies.push(body(
        "edge_rock",
        ROCK,
        circle(0.3),
        Vec2::new(0.5, y),
        Vec2::ZERO,
    ));
    // One unit a frame: it first sticks out of the world near frame 8, when the seam's
    // guess (from a frame with nothing sticking out) is zero.
    let ship = body(
        "ship",
        SHIP,
        circle(2.0),
        Vec2::new(190.0, y),
        Vec2::new(60.0, 0.0),
    );
    bodies.push(ship);
    for kind in [BroadPhaseKind::Auto, BroadPhaseKind::SortAndSweep] {
        let world = WorldDef {
            layers: layers(&["ship", "rock"], &[(SHIP, ROCK, Response::Report)]),
            bounds: Some(bounds),
            broad_phase: kind,
            ..WorldDef::default()
        };
        let mut sim = Simulation::new(&scenario("edge", world, bodies.clone(), 12));
        sim.capture_detect_poses = true;
        let found = check(sim, &bounds, &format!("{kind:?}"));
        assert!(found >= 2, "{kind:?}: {found} contacts through the seam");
    }
}

/// More static bodies than moving ones: `Auto` runs the grid, which reads every entry, so
/// the big layer's are all made after the others' (the choice is known only then).
#[test]
fn a_big_layer_is_made_whole_when_the_call_does_not_filter_it() {
    let bounds = WorldBounds {
        min: Vec2::ZERO,
        max: Vec2::new(150.0, 110.0),
        wrap: true,
    };
    let mut sim = simulation(BroadPhaseKind::Auto, bounds, 1200);
    assert_eq!(sim.step().stats.broad_phase, Some(BroadPhaseKind::Grid));
    let sim = simulation(BroadPhaseKind::Auto, bounds, 1200);
    let found = check(sim, &bounds, "Auto with the grid");
    assert!(found > 100, "{found} contacts");
}

/// A cluster of ships crossing the field fast: the box the bitmap maps moves with them, and
/// the rocks on their way are marked frame after frame.
#[test]
fn ships_in_a_cluster_crossing_the_field_meet_every_rock_on_their_way() {
    let mut rng = ricochet_scenes::Rng::new(5);
    let mut bodies: Vec<_> = (0..1200)
        .map(|k| {
            let at = Vec2::new(rng.range(0.0, 300.0), rng.range(0.0, 60.0));
            let v = Vec2::new(rng.range(-3.0, 3.0), rng.range(-3.0, 3.0));
            let shape = Shape::circle(rng.range(0.3, 1.5)).unwrap();
            body(&format!("rock{k}"), ROCK, shape, at, v)
        })
        .collect();
    for k in 0..40 {
        let at = Vec2::new(rng.range(-30.0, -10.0), rng.range(0.0, 60.0));
        let shape = Shape::circle(rng.range(0.5, 2.0)).unwrap();
        bodies.push(body(
            &format!("ship{k}"),
            SHIP,
            shape,
            at,
            Vec2::new(900.0, 0.0),
        ));
    }
    let world = WorldDef {
        layers: layers(&["ship", "rock", "wall"], &[(SHIP, ROCK, Response::Report)]),
        broad_phase: BroadPhaseKind::SortAndSweep,
        ..WorldDef::default()
    };
    let mut sim = Simulation::new(&scenario("cluster", world, bodies, 24));
    sim.capture_detect_poses = true;
    let bounds = WorldBounds {
        min: Vec2::ZERO,
        max: Vec2::splat(1.0),
        wrap: false,
    };
    let found = check(sim, &bounds, "a cluster crossing");
    assert!(found > 100, "{found} contacts");
}

/// The bench's asteroids (2,000, their bullets swept, so each asteroid's bounds are widened
/// over its motion) find the same contacts, and end every frame in the same state, as
/// brute force, which tests every pair.
#[test]
fn asteroids_with_swept_bullets_step_as_brute_force_does() {
    let scenario = ricochet_scenes::bench::Scene::parse("asteroids-2000")
        .unwrap()
        .build(40);
    let mut auto = Simulation::new(&scenario);
    let mut brute = scenario.clone();
    brute.world.broad_phase = BroadPhaseKind::BruteForce;
    let mut brute = Simulation::new(&brute);
    let mut contacts = 0;
    for frame in 0..=40 {
        let (a, b) = (auto.step(), brute.step());
        let key = |o: &FrameOutput| -> Vec<_> {
            (o.contacts.iter())
                .map(|c| (c.a, c.b, c.depth.to_bits()))
                .collect()
        };
        assert_eq!(key(&a), key(&b), "frame {frame}");
        assert_eq!(
            auto.world().digest(),
            brute.world().digest(),
            "frame {frame}"
        );
        contacts += a.contacts.len();
    }
    assert!(contacts > 20, "{contacts} contacts");
}
