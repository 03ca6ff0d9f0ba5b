//! Each named rule fires on a scene built for it, and only there; a deliberately broken
//! narrow phase (a contact record edited before `check_frame`) is caught.

use ricochet_geom::{Primitive, Shape, Vec2};
use ricochet_oracle::{FrameReport, Referee, Tolerances, rules};
use ricochet_scenes::{layers, scenario};
use ricochet_sim::{
    BodyDef, BodyKind, Doomed, FrameOutput, Phase, Response, Scenario, Simulation, WorldDef,
    load_scenario,
};

/// Runs `toml` for frames `0..=frames`, checking each; returns the reports.
fn run(toml: &str, frames: u64) -> Vec<FrameReport> {
    let scenario = load_scenario(toml, "test.toml").unwrap_or_else(|e| panic!("{e}"));
    check(&scenario, frames)
}

/// Runs `scenario` for frames `0..=frames`, checking each; returns the reports.
fn check(scenario: &Scenario, frames: u64) -> Vec<FrameReport> {
    let mut sim = Simulation::new(scenario);
    sim.capture_detect_poses = true;
    let mut referee = Referee::new(scenario, Tolerances::default());
    (0..=frames)
        .map(|_| {
            let out = sim.step();
            referee.check_frame(&sim, &out)
        })
        .collect()
}

fn count(r: &FrameReport, rule: &str) -> u64 {
    r.explained.get(rule).copied().unwrap_or(0)
}

fn assert_clean(reports: &[FrameReport]) {
    for r in reports {
        assert_eq!(r.mismatches, 0, "frame {}: {:#?}", r.frame, r.details);
    }
}

#[test]
fn static_and_kinematic_bodies_overlapping_are_explained_as_static_static() {
    let reports = run(
        r#"
        layers = ["a"]
        collide = [{ a = "a", b = "a", response = "report" }]
        [[bodies]]
        layer = "a"
        kind = "static"
        shape = { kind = "circle", radius = 1 }
        [[bodies]]
        layer = "a"
        kind = "kinematic"
        shape = { kind = "aabb", half_extents = [1, 1] }
        position = [1, 0]
        [[bodies]]
        layer = "a"
        shape = { kind = "circle", radius = 0.5 }
        position = [10, 0]
        "#,
        3,
    );
    assert_clean(&reports);
    for r in &reports {
        assert_eq!(count(r, rules::STATIC_STATIC), 1, "{r:#?}");
        assert_eq!(r.explained.len(), 1, "{r:#?}");
    }
}

/// The ball (id 0, radius 0.5) 0.3 deep in the left side of the wall (id 1, a static 2×2
/// box at the origin), `separate`, and `third` (id 2), a static body of the wall's layer.
fn ball_in_wall(third: BodyDef) -> Scenario {
    let ball = BodyDef {
        name: "ball".to_owned(),
        shape: Shape::circle(0.5).unwrap(),
        position: Vec2::new(-1.2, 0.0),
        ..BodyDef::default()
    };
    let wall = BodyDef {
        name: "wall".to_owned(),
        layer: 1,
        kind: BodyKind::Static,
        shape: Shape::aabb(Vec2::ONE).unwrap(),
        ..BodyDef::default()
    };
    let third = BodyDef {
        layer: 1,
        kind: BodyKind::Static,
        ..third
    };
    let world = WorldDef {
        layers: layers(&["ball", "wall"], &[(0, 1, Response::Separate)]),
        ..WorldDef::default()
    };
    scenario("ball-in-wall", world, vec![ball, wall, third], 600)
}

#[test]
fn a_push_that_ends_a_later_contact_is_explained_as_moved_in_pass() {
    // The ball (id 0) sits 0.3 deep in the wall (id 1) and just touches the ledge (id 2).
    // Pair (0, 1) comes first and pushes the ball 0.3 to the left, clear of the ledge, so
    // Ricochet tests (0, 2) at the pushed pose and finds nothing; rapier, at the detect
    // poses, finds both.
    let reports = check(
        &ball_in_wall(BodyDef {
            name: "ledge".to_owned(),
            shape: Shape::obb(Vec2::new(0.55, 0.075)).unwrap(),
            position: Vec2::new(-0.55, 0.525),
            ..BodyDef::default()
        }),
        0,
    );
    assert_clean(&reports);
    assert_eq!(
        count(&reports[0], rules::MOVED_IN_PASS),
        1,
        "{:#?}",
        reports[0]
    );
    assert_eq!(reports[0].pairs_confirmed, 1);
}

#[test]
fn a_push_that_starts_a_later_contact_is_explained_as_moved_in_pass() {
    // Pushed left out of the wall, the ball lands in the rock (id 2), which it did not
    // touch at the detect poses (0.005 apart) though their bounds overlapped, so the broad
    // phase listed the pair: Ricochet logs (0, 2) at the pushed pose, rapier has no such
    // pair at the detect poses.
    let reports = check(
        &ball_in_wall(BodyDef {
            name: "rock".to_owned(),
            shape: Shape::circle(0.9).unwrap(),
            position: Vec2::new(-2.59, 0.55),
            ..BodyDef::default()
        }),
        0,
    );
    assert_clean(&reports);
    let r = &reports[0];
    assert_eq!(count(r, rules::MOVED_IN_PASS), 1, "{r:#?}");
    assert_eq!(r.pairs_confirmed, 1);
    assert_eq!(r.contacts_compared, 2);
}

#[test]
fn an_overlap_within_slop_is_explained_as_touching() {
    // 5e-10 deep: rapier reports penetration, Ricochet's `separate` ignores anything up to
    // SLOP = 1e-9.
    let reports = run(
        r#"
        layers = ["ball", "wall"]
        collide = [{ a = "ball", b = "wall", response = "separate" }]
        [[bodies]]
        layer = "ball"
        shape = { kind = "circle", radius = 0.5 }
        position = [-1.4999999995, 0]
        [[bodies]]
        layer = "wall"
        kind = "static"
        shape = { kind = "obb", half_extents = [1, 1] }
        "#,
        0,
    );
    assert_clean(&reports);
    assert_eq!(count(&reports[0], rules::TOUCHING), 1, "{:#?}", reports[0]);
    assert_eq!(reports[0].contacts_compared, 0);
}

#[test]
fn more_layers_than_rapier_groups_still_filter_by_the_matrix() {
    // 40 layers: past rapier's 32 collision groups, the referee filters with a hook.
    let names: Vec<String> = (0..40).map(|i| format!("\"l{i}\"")).collect();
    let toml = format!(
        r#"
        layers = [{}]
        collide = [{{ a = "l35", b = "l38", response = "report" }}]
        [[bodies]]
        layer = "l35"
        shape = {{ kind = "circle", radius = 1 }}
        [[bodies]]
        layer = "l38"
        shape = {{ kind = "circle", radius = 1 }}
        position = [1, 0]
        [[bodies]]
        layer = "l35"
        shape = {{ kind = "circle", radius = 1 }}
        position = [0, 1]
        "#,
        names.join(", ")
    );
    let reports = run(&toml, 2);
    assert_clean(&reports);
    for r in &reports {
        // (0, 1) and (1, 2) report; (0, 2) is l35/l35, ignored by both engines.
        assert_eq!(r.pairs_confirmed, 2, "{r:#?}");
        assert!(r.explained.is_empty(), "{r:#?}");
    }
}

/// The shapes scenario at a frame with at least `min` `all` contacts, as the simulation
/// left it.
fn shapes_frame(min: usize) -> (ricochet_sim::Scenario, Simulation, FrameOutput) {
    let path = format!("{}/../../scenarios/shapes.toml", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap();
    let scenario = load_scenario(&text, &path).unwrap();
    let mut sim = Simulation::new(&scenario);
    sim.capture_detect_poses = true;
    loop {
        let out = sim.step();
        let deep = out
            .contacts
            .iter()
            .filter(|c| c.phase == Phase::All && c.depth > 0.05)
            .count();
        if deep >= min {
            return (scenario, sim, out);
        }
        assert!(sim.frame() < 600, "no frame with {min} deep contacts");
    }
}

/// Index of the first `all` contact deeper than 0.05 (so a 1% error is far past tolerance).
fn deep(out: &FrameOutput) -> usize {
    out.contacts
        .iter()
        .position(|c| c.phase == Phase::All && c.depth > 0.05)
        .unwrap()
}

#[test]
fn the_unbroken_frame_passes() {
    let (scenario, sim, out) = shapes_frame(3);
    let r = Referee::new(&scenario, Tolerances::default()).check_frame(&sim, &out);
    assert_eq!(r.mismatches, 0, "{:#?}", r.details);
    assert_eq!(r.contacts_compared as usize, out.contacts.len());
}

#[test]
fn a_flipped_normal_is_caught() {
    let (scenario, sim, mut out) = shapes_frame(3);
    let i = deep(&out);
    out.contacts[i].normal = -out.contacts[i].normal;
    let r = Referee::new(&scenario, Tolerances::default()).check_frame(&sim, &out);
    assert_eq!(r.mismatches, 1, "{:#?}", r.details);
    assert!(r.details[0].contains("normal"), "{}", r.details[0]);
}

#[test]
fn a_depth_one_percent_too_deep_is_caught() {
    let (scenario, sim, mut out) = shapes_frame(3);
    let i = deep(&out);
    out.contacts[i].depth *= 1.01;
    let r = Referee::new(&scenario, Tolerances::default()).check_frame(&sim, &out);
    assert_eq!(r.mismatches, 1, "{:#?}", r.details);
    assert!(r.details[0].contains("depth"), "{}", r.details[0]);
}

#[test]
fn a_normal_turned_by_a_microradian_is_caught() {
    let (scenario, sim, mut out) = shapes_frame(3);
    let i = deep(&out);
    let n = out.contacts[i].normal;
    let (s, c) = (1e-6_f64, libm::cos(1e-6));
    out.contacts[i].normal = Vec2::new(c * n.x - s * n.y, s * n.x + c * n.y);
    let r = Referee::new(&scenario, Tolerances::default()).check_frame(&sim, &out);
    assert_eq!(r.mismatches, 1, "{:#?}", r.details);
}

#[test]
fn a_missed_contact_is_caught() {
    // A narrow phase that loses a pair: the record is gone from the log, rapier still has it.
    let (scenario, sim, mut out) = shapes_frame(3);
    let i = deep(&out);
    let lost = out.contacts.remove(i);
    let r = Referee::new(&scenario, Tolerances::default()).check_frame(&sim, &out);
    assert_eq!(r.mismatches, 1, "{:#?}", r.details);
    assert!(
        r.details[0].contains("Ricochet logged no contact"),
        "{} (lost #{} #{})",
        r.details[0],
        lost.a,
        lost.b
    );
}

#[test]
fn an_invented_contact_is_caught() {
    // A narrow phase that reports a pair that does not touch: move one record's poses apart.
    let (scenario, sim, mut out) = shapes_frame(3);
    let i = deep(&out);
    out.contacts[i].pose_b.position += Vec2::new(100.0, 0.0);
    let r = Referee::new(&scenario, Tolerances::default()).check_frame(&sim, &out);
    assert!(r.mismatches >= 1, "{:#?}", r.details);
}

#[test]
fn concentric_circles_accept_any_normal_as_a_tie() {
    // Two circles on the same centre: every direction is a minimum translation. A record
    // whose normal is turned to any other direction is explained as a tie, not a mismatch.
    let toml = r#"
        layers = ["a"]
        collide = [{ a = "a", b = "a", response = "report" }]
        [[bodies]]
        layer = "a"
        shape = { kind = "circle", radius = 1 }
        position = [3, 4]
        [[bodies]]
        layer = "a"
        shape = { kind = "circle", radius = 0.5 }
        position = [3, 4]
    "#;
    let scenario = load_scenario(toml, "t.toml").unwrap();
    let mut sim = Simulation::new(&scenario);
    sim.capture_detect_poses = true;
    let mut out = sim.step();
    assert_eq!(out.contacts.len(), 1);
    out.contacts[0].normal = Vec2::new(0.6, -0.8);
    let r = Referee::new(&scenario, Tolerances::default()).check_frame(&sim, &out);
    assert_eq!(r.mismatches, 0, "{:#?}", r.details);
    assert_eq!(count(&r, rules::TIED_NORMAL), 1, "{r:#?}");
}

#[test]
fn a_box_centred_on_a_box_ties_between_x_and_y() {
    // Equal overlaps on both axes: +x and +y are both minimum translations, -x is not.
    let toml = r#"
        layers = ["a"]
        collide = [{ a = "a", b = "a", response = "report" }]
        [[bodies]]
        layer = "a"
        shape = { kind = "aabb", half_extents = [1, 1] }
        [[bodies]]
        layer = "a"
        shape = { kind = "aabb", half_extents = [1, 1] }
        position = [0.5, 0.5]
    "#;
    let scenario = load_scenario(toml, "t.toml").unwrap();
    let mut sim = Simulation::new(&scenario);
    sim.capture_detect_poses = true;
    let out = sim.step();
    let mut referee = Referee::new(&scenario, Tolerances::default());
    let mut check = |normal: Vec2| {
        let mut o = out.clone();
        o.contacts[0].normal = normal;
        referee.check_frame(&sim, &o)
    };
    // Parry picks one of +x and +y; the other is a tie, neither is a mismatch.
    let (x, y) = (check(Vec2::X), check(Vec2::Y));
    assert_eq!(x.mismatches + y.mismatches, 0, "{x:#?} {y:#?}");
    assert_eq!(
        count(&x, rules::TIED_NORMAL) + count(&y, rules::TIED_NORMAL),
        1
    );
    // -x would push b the wrong way: not a tie.
    let wrong = check(Vec2::NEG_X);
    assert_eq!(wrong.mismatches, 1, "{wrong:#?}");
    assert_eq!(count(&wrong, rules::TIED_NORMAL), 0);
}

/// A fast layer of bullets against static targets, `destroy = "a"`: the bullet goes, the
/// target stays. Bullets fly 10 units a frame.
fn swept_scene(bodies: Vec<BodyDef>) -> Scenario {
    let mut l = layers(
        &["bullet", "target"],
        &[(0, 1, Response::Destroy(Doomed::First))],
    );
    l.set_fast(0);
    let world = WorldDef {
        layers: l,
        ..WorldDef::default()
    };
    scenario("swept", world, bodies, 600)
}

/// A bullet of `shape` at `at`, moving at `velocity`.
fn bullet(shape: Shape, at: Vec2, velocity: Vec2) -> BodyDef {
    BodyDef {
        shape,
        position: at,
        velocity,
        ..BodyDef::default()
    }
}

/// A static target of `shape` at `at`.
fn target(shape: Shape, at: Vec2) -> BodyDef {
    BodyDef {
        name: "target".to_owned(),
        layer: 1,
        kind: BodyKind::Static,
        shape,
        position: at,
        ..BodyDef::default()
    }
}

#[test]
fn swept_hits_of_every_kind_are_first_touches() {
    let v = Vec2::new;
    let p = |p: Result<Primitive, _>| Shape::Primitive(p.unwrap());
    let mut capsule = bullet(
        Shape::capsule(v(-0.3, 0.0), v(0.3, 0.0), 0.05).unwrap(),
        v(-10.0, 5.0),
        v(600.0, 30.0),
    );
    capsule.angle = 0.4;
    let triangle = [v(0.3, 0.0), v(-0.2, 0.15), v(-0.2, -0.15)];
    let roof = [v(0.0, 0.2), v(0.5, 1.0), v(-0.5, 1.0)];
    let compound = Shape::compound(vec![
        Primitive::aabb(Vec2::ZERO, v(1.0, 0.2)).unwrap(),
        Primitive::polygon(&roof).unwrap(),
    ])
    .unwrap();
    let bodies = vec![
        bullet(Shape::circle(0.1).unwrap(), v(-10.0, 0.0), v(600.0, 0.0)),
        capsule,
        bullet(
            Shape::polygon(&triangle).unwrap(),
            v(5.0, -15.0),
            v(0.0, 600.0),
        ),
        bullet(
            p(Primitive::obb(Vec2::ZERO, v(0.3, 0.05), 0.3)),
            v(15.0, 10.0),
            v(-600.0, 0.0),
        ),
        target(
            p(Primitive::obb(Vec2::ZERO, v(0.1, 2.0), 0.2)),
            v(-3.0, 0.0),
        ),
        target(
            Shape::capsule(v(0.0, -1.0), v(0.0, 1.0), 0.3).unwrap(),
            v(-2.0, 5.3),
        ),
        target(compound, v(5.0, -7.0)),
        target(Shape::aabb(v(0.5, 0.5)).unwrap(), v(9.0, 10.2)),
    ];
    let reports = check(&swept_scene(bodies), 2);
    assert_clean(&reports);
    // Frame 1: every bullet hits its target, at the first touch.
    assert_eq!(reports[1].swept_confirmed, 4, "{:#?}", reports[1]);
    assert!(reports[1].explained.is_empty(), "{:#?}", reports[1]);
}

#[test]
fn a_bullet_through_two_targets_stops_at_the_first() {
    // Both targets lie on this frame's 10-unit path; the bullet dies on the first, and
    // parry's touch with the second is explained as `first-hit`.
    let ball = |r: f64| Shape::circle(r).unwrap();
    let reports = check(
        &swept_scene(vec![
            bullet(ball(0.1), Vec2::new(-5.0, 0.0), Vec2::new(600.0, 0.0)),
            target(ball(0.5), Vec2::new(-1.0, 0.0)),
            target(ball(0.5), Vec2::new(2.0, 0.0)),
        ]),
        1,
    );
    assert_clean(&reports);
    assert_eq!(reports[1].swept_confirmed, 1, "{:#?}", reports[1]);
    assert_eq!(count(&reports[1], rules::FIRST_HIT), 1, "{:#?}", reports[1]);
}

/// A bullet of radius 0.5 flying along y = 10 from x = -10 to 0 in frame 1, past a target of
/// radius 0.5 at `(x, 11 - overlap)`: the path grazes it, `overlap` deep at most.
fn graze(x: f64, overlap: f64) -> Vec<FrameReport> {
    check(&graze_scene(x, overlap), 1)
}

/// The scene of [`graze`].
fn graze_scene(x: f64, overlap: f64) -> Scenario {
    let ball = Shape::circle(0.5).unwrap();
    swept_scene(vec![
        bullet(ball.clone(), Vec2::new(-10.0, 10.0), Vec2::new(600.0, 0.0)),
        target(ball, Vec2::new(x, 11.0 - overlap)),
    ])
}

#[test]
fn a_tangent_graze_is_explained_as_touching() {
    // 1e-12 deep at the middle of the path: within tolerance of touching. Ricochet's swept
    // test (which searches the closest approach when the path grazes) may log it, and then
    // parry confirms it; if it doesn't, the difference is `touching`. Either way, no mismatch.
    let reports = graze(-5.0, 1e-12);
    assert_clean(&reports);
    let r = &reports[1];
    assert_eq!(r.swept_confirmed + count(r, rules::TOUCHING), 1, "{r:#?}");
}

#[test]
fn a_graze_that_ends_overlapping_is_logged_at_the_first_touch_or_explained() {
    // The path reaches 1e-6 deep only at its very end: a grazing approach, where
    // conservative advancement alone would crawl.
    let reports = graze(0.001, 1e-6);
    assert_clean(&reports);
    let r = &reports[1];
    assert_eq!(
        r.swept_confirmed + count(r, rules::TOI_FALLBACK),
        1,
        "{r:#?}"
    );
}

#[test]
fn a_missed_swept_hit_is_caught() {
    // The bullet passes 0.03 deep through the target; delete Ricochet's swept record and
    // the referee must report the hit parry's shape cast finds.
    let scenario = graze_scene(-5.0, 0.03);
    let mut sim = Simulation::new(&scenario);
    sim.capture_detect_poses = true;
    let mut referee = Referee::new(&scenario, Tolerances::default());
    let out0 = sim.step();
    assert_eq!(referee.check_frame(&sim, &out0).mismatches, 0);
    let mut out = sim.step();
    let before = out.contacts.len();
    out.contacts.retain(|c| c.phase != Phase::Swept);
    assert_eq!(before, out.contacts.len() + 1, "Ricochet logged the hit");
    let r = referee.check_frame(&sim, &out);
    assert_eq!(r.mismatches, 1, "{r:#?}");
    assert!(
        r.details[0].contains("shape cast touches"),
        "{}",
        r.details[0]
    );
}

#[test]
fn a_body_destroyed_by_another_movers_hit_still_makes_its_own() {
    // X (fast) crosses Y's path and destroys it at t = 0.45; X was that hit's mover, not Y,
    // so Y is not stopped and its own hit on Z at t = 0.6 is logged too. The referee must
    // confirm both, not call the second one "after its mover was destroyed".
    let reports = run(
        r#"
        layers = ["a", "b"]
        fast_layers = ["a"]
        collide = [
          { a = "a", b = "b", response = "destroy" },
          { a = "b", b = "b", response = "destroy", sweep = true },
        ]
        [[bodies]]
        name = "x"
        layer = "a"
        shape = { kind = "circle", radius = 0.1 }
        position = [-2.5, -5]
        velocity = [0, 600]
        [[bodies]]
        name = "y"
        layer = "b"
        shape = { kind = "circle", radius = 0.5 }
        position = [-5, 0]
        velocity = [300, 0]
        [[bodies]]
        name = "z"
        layer = "b"
        kind = "static"
        shape = { kind = "circle", radius = 0.5 }
        position = [-1, 0]
        "#,
        1,
    );
    assert_clean(&reports);
    assert_eq!(reports[1].swept_confirmed, 2, "{:#?}", reports[1]);
}
