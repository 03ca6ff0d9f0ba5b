//! The numerical-stability stress suite. Every test asserts an invariant (never a golden
//! number): far from the origin, extreme sizes and masses, a deep stack, a long run, extreme
//! timesteps, degenerate geometry, and properties of random small scenes.

use ricochet_geom::{Shape, Vec2, contact};
use ricochet_scenes::{layers, scenario};
use ricochet_sim::{
    BodyKind, FrameOutput, Phase, Response, SLOP, Simulation, World, WorldDef, load_scenario,
};

use crate::util::root;

fn sim(text: &str) -> Simulation {
    Simulation::new(&load_scenario(text, "stress.toml").unwrap_or_else(|e| panic!("{e}\n{text}")))
}

fn scenario_file(name: &str) -> String {
    std::fs::read_to_string(root().join("scenarios").join(name)).unwrap()
}

fn run(s: &mut Simulation, frames: u64) -> Vec<FrameOutput> {
    (0..=frames).map(|_| s.step()).collect()
}

fn assert_finite(w: &World) {
    for i in 0..w.len() {
        assert!(
            w.position[i].is_finite() && w.velocity(i).is_finite() && w.angle[i].is_finite(),
            "body {i}: {} {}",
            w.position[i],
            w.velocity(i)
        );
    }
}

/// The worst overlap left between two solid bodies at the end of a frame.
fn worst_solid_overlap(s: &Simulation) -> f64 {
    let w = s.world();
    let layers = &s.scenario().world.layers;
    let mut worst: f64 = 0.0;
    for i in 0..w.len() {
        for j in i + 1..w.len() {
            if layers.response(w.layer[i], w.layer[j]) != ricochet_sim::Response::Separate
                || (w.kind[i] != BodyKind::Dynamic && w.kind[j] != BodyKind::Dynamic)
            {
                continue;
            }
            worst = worst.max(contact(w.shape(i), &w.pose(i), w.shape(j), &w.pose(j)).depth);
        }
    }
    worst
}

use ricochet_scenes::moving_body as body;

/// The stress version of the shapes scene, moved by `offset`.
fn shifted_scene(offset: f64) -> Simulation {
    let v = Vec2::new;
    let polygon = Shape::polygon(&[
        v(-1.0, -1.0),
        v(1.0, -1.0),
        v(1.3, 0.5),
        v(0.0, 1.2),
        v(-1.2, 0.4),
    ])
    .unwrap();
    let capsule = Shape::capsule(v(-1.5, 0.0), v(1.5, 0.0), 0.4).unwrap();
    let obb = Shape::obb(v(0.8, 0.3)).unwrap();
    let mut bodies = vec![
        body("body", 0, polygon, v(offset - 6.0, offset), v(2.0, 0.5)),
        body(
            "body",
            1,
            capsule,
            v(offset + 6.0, offset + 0.3),
            v(-1.5, 0.0),
        ),
        body("body", 1, obb, v(offset + 9.0, offset), v(-2.5, 0.2)),
    ];
    bodies[0].angular_velocity = 1.1;
    bodies[1].angular_velocity = -0.7;
    let world = WorldDef {
        layers: layers(&["a", "b"], &[(0, 1, Response::Report)]),
        ..WorldDef::default()
    };
    Simulation::new(&scenario("shifted", world, bodies, 600))
}

/// Far from the origin: positions are stored to ulp(offset) = 2.2e-16 * offset, so after n
/// frames of `x += v dt` (one rounding each) relative motion may drift by n ulps.
#[test]
fn the_same_scene_far_from_the_origin_gives_the_same_contacts_and_relative_motion() {
    let frames = 300u64;
    let reference = run(&mut shifted_scene(0.0), frames);
    for offset in [1e4, 1e6] {
        let mut s = shifted_scene(offset);
        let outs = run(&mut s, frames);
        let tol = frames as f64 * 4.0 * f64::EPSILON * offset;
        for (r, o) in reference.iter().zip(&outs) {
            let pairs = |f: &FrameOutput| f.contacts.iter().map(|c| (c.a, c.b)).collect::<Vec<_>>();
            // A contact within tol of touching may flicker: compare only the clear ones.
            let clear = |f: &FrameOutput| {
                f.contacts
                    .iter()
                    .filter(|c| c.depth > tol)
                    .map(|c| (c.a, c.b))
                    .collect::<Vec<_>>()
            };
            assert!(
                clear(r).iter().all(|p| pairs(o).contains(p)),
                "frame {}: {:?} vs {:?}",
                r.frame,
                pairs(r),
                pairs(o)
            );
            assert!(
                clear(o).iter().all(|p| pairs(r).contains(p)),
                "frame {}",
                r.frame
            );
            for c in &o.contacts {
                if let Some(rc) = r.contacts.iter().find(|x| (x.a, x.b) == (c.a, c.b)) {
                    assert!(
                        (rc.depth - c.depth).abs() <= tol,
                        "depth {} vs {} (tol {tol})",
                        rc.depth,
                        c.depth
                    );
                }
            }
        }
        let mut r = shifted_scene(0.0);
        run(&mut r, frames);
        for i in 0..s.world().len() {
            let rel = s.world().position[i] - Vec2::splat(offset);
            assert!(
                (rel - r.world().position[i]).abs().max_element() <= tol,
                "offset {offset}: body {i} {rel} vs {}",
                r.world().position[i]
            );
        }
    }
}

#[test]
fn sizes_from_a_millimetre_to_a_kilometre_and_mass_ratios_of_ten_thousand() {
    let mut s = sim(&scenario_file("stress/extreme-sizes.toml"));
    for frame in 0..=600 {
        s.step();
        assert_finite(s.world());
        let worst = worst_solid_overlap(&s);
        assert!(worst <= 1e-6, "frame {frame}: overlap {worst}");
    }
    let w = s.world();
    let at = |name: &str| w.position[w.find(name).unwrap()];
    assert!((at("grain").y - 0.001).abs() <= 1e-9, "{}", at("grain"));
    assert!((at("boulder").y - 1.0).abs() <= 1e-9, "{}", at("boulder"));
    // The pebble is a circle: separated along the normal, it rests within a step's fall.
    assert!(
        (at("pebble").y - 0.001).abs() <= 10.0 / 3600.0,
        "{}",
        at("pebble")
    );
}

#[test]
fn a_stack_of_fifty_boxes_rests_for_ten_thousand_frames_without_creep_or_jitter() {
    let mut s = sim(&scenario_file("stress/stack-50.toml"));
    assert_eq!(s.world().len(), 51);
    let mut settled: Option<Vec<Vec2>> = None;
    for frame in 0..=10_000u64 {
        s.step();
        let worst = worst_solid_overlap(&s);
        assert!(worst <= SLOP, "frame {frame}: overlap {worst}");
        if frame >= 120 {
            let now: Vec<Vec2> = s.world().position.clone();
            match &settled {
                None => settled = Some(now),
                Some(then) => {
                    let drift = then
                        .iter()
                        .zip(&now)
                        .map(|(a, b)| (*a - *b).length())
                        .fold(0.0, f64::max);
                    assert!(drift <= SLOP, "frame {frame}: the stack moved by {drift}");
                }
            }
            for i in 1..s.world().len() {
                assert!(
                    s.world().grounded(i),
                    "frame {frame}: {} is not grounded",
                    s.world().name(i)
                );
            }
        }
    }
    // Box k rests with its centre at k + 0.5.
    for i in 1..s.world().len() {
        let k: f64 = s.world().name(i)[3..].parse().unwrap();
        assert!(
            (s.world().position[i].y - (k + 0.5)).abs() <= 1e-9,
            "{}: {}",
            s.world().name(i),
            s.world().position[i]
        );
    }
}

#[test]
fn a_million_frames_of_asteroids_stay_finite_bounded_and_flat_in_memory() {
    let text = scenario_file("asteroids.toml");
    let scenario = load_scenario(&text, "asteroids.toml").unwrap();
    let bounds = scenario.world.bounds.unwrap();
    let mut s = Simulation::new(&scenario);
    let mut peak = 0;
    for frame in 0..=1_000_000u64 {
        s.step();
        if frame % 10_000 == 0 {
            assert_finite(s.world());
            for p in &s.world().position {
                assert!(
                    p.x >= bounds.min.x
                        && p.x < bounds.max.x
                        && p.y >= bounds.min.y
                        && p.y < bounds.max.y,
                    "frame {frame}: {p} left the wrapped world"
                );
            }
        }
        peak = peak.max(s.world().len());
    }
    assert!(peak <= 60, "bodies never pile up: at most {peak}");
    // Nothing that grows per frame is kept: the world's columns hold only live bodies.
    assert!(
        s.world().position.capacity() <= 64,
        "{}",
        s.world().position.capacity()
    );
}

#[test]
fn tiny_and_huge_timesteps_are_handled() {
    let text = scenario_file("platformer.toml");
    for dt in ["1e-6", "0.1"] {
        let changed = text.replacen("hz = 60", &format!("dt = {dt}"), 1);
        assert_ne!(changed, text, "platformer.toml sets hz = 60");
        let mut s = sim(&changed);
        for frame in 0..=2_000 {
            s.step();
            assert_finite(s.world());
            let worst = worst_solid_overlap(&s);
            assert!(worst <= SLOP, "dt {dt}, frame {frame}: overlap {worst}");
        }
    }
}

#[test]
fn coincident_bodies_and_corner_on_corner_hits_get_finite_normals_and_a_fixed_choice() {
    // `wall` (static) and `twin` coincide; `corner` hits both corner on corner; `still`
    // (a probe, reported) sits at their common centre.
    let (v, square) = (Vec2::new, |h: f64| Shape::aabb(Vec2::splat(h)).unwrap());
    let mut wall = body("wall", 0, square(1.0), Vec2::ZERO, Vec2::ZERO);
    wall.kind = BodyKind::Static;
    let bodies = vec![
        wall,
        body("twin", 0, square(1.0), Vec2::ZERO, Vec2::ZERO),
        body("corner", 0, square(0.5), v(1.6, 1.6), v(-6.0, -6.0)),
        body(
            "still",
            1,
            Shape::circle(0.5).unwrap(),
            Vec2::ZERO,
            Vec2::ZERO,
        ),
    ];
    let world = WorldDef {
        layers: layers(
            &["solid", "probe"],
            &[(0, 0, Response::Separate), (1, 0, Response::Report)],
        ),
        ..WorldDef::default()
    };
    let scene = scenario("coincident", world, bodies, 600);
    let mut a = Simulation::new(&scene);
    let mut b = Simulation::new(&scene);
    for _ in 0..=30 {
        let (oa, ob) = (a.step(), b.step());
        assert_eq!(oa, ob, "the same choice every run");
        for c in &oa.contacts {
            assert!(
                c.normal.is_finite() && (c.normal.length() - 1.0).abs() < 1e-12,
                "{c:?}"
            );
            assert!(c.depth.is_finite());
        }
        assert_finite(a.world());
    }
    // The twin started exactly inside the wall and was pushed out along one axis.
    let twin = a.world().position[a.world().find("twin").unwrap()];
    assert!(
        twin.x.abs() >= 2.0 - SLOP || twin.y.abs() >= 2.0 - SLOP,
        "{twin}"
    );
}

/// Issue #20, "pushed through static floors": 3,000 circles (radius 0.5) start at one point
/// just above a static floor 2 units thick (top at y = 0), `separate`ing from each other and
/// from the floor, the floor last in id order (every circle's push from the others comes
/// before its floor pair). Before the fix some reached y = -41 and fell forever. Statics win:
/// after every frame no circle overlaps the floor by more than `SLOP` (geometry: the centre
/// never below `0.5 - SLOP`).
#[test]
fn a_pile_of_3000_circles_started_at_one_point_never_sinks_into_the_floor() {
    let mut bodies: Vec<_> = (0..3000)
        .map(|k| {
            let name = format!("ball{k}");
            let circle = Shape::circle(0.5).unwrap();
            body(&name, 1, circle, Vec2::new(0.0, 0.6), Vec2::ZERO)
        })
        .collect();
    let floor_shape = Shape::aabb(Vec2::new(100.0, 1.0)).unwrap();
    let mut floor = body("floor", 0, floor_shape, Vec2::new(0.0, -1.0), Vec2::ZERO);
    floor.kind = BodyKind::Static;
    bodies.push(floor);
    let world = WorldDef {
        gravity: Vec2::new(0.0, -10.0),
        layers: layers(
            &["floor", "ball"],
            &[(1, 0, Response::Separate), (1, 1, Response::Separate)],
        ),
        ..WorldDef::default()
    };
    let mut s = Simulation::new(&scenario("pile", world, bodies, 60));
    let mut highest = 0.0f64;
    for frame in 0..=60 {
        s.step();
        let w = s.world();
        let f = w.find("floor").unwrap();
        highest = 0.0;
        for i in 0..w.len() {
            if w.kind[i] != BodyKind::Dynamic {
                continue;
            }
            let c = contact(w.shape(i), &w.pose(i), w.shape(f), &w.pose(f));
            assert!(
                c.depth <= SLOP + 1e-12 && w.position[i].y >= 0.5 - SLOP - 1e-12,
                "frame {frame}: circle {i} at {} overlaps the floor by {}",
                w.position[i],
                c.depth
            );
            highest = highest.max(w.position[i].y);
        }
        assert_finite(w);
    }
    // Not vacuous: the circles pushed each other apart, many onto others.
    assert!(highest > 2.0, "the pile spread: highest centre {highest}");
}

mod properties {
    use proptest::prelude::*;

    use super::*;

    /// A few static floor tiles and some dynamic boxes and circles falling onto them.
    fn scene() -> impl Strategy<Value = String> {
        let body = (
            -8.0f64..8.0,
            0.5f64..8.0,
            -4.0f64..4.0,
            0.1f64..1.0,
            any::<bool>(),
        );
        proptest::collection::vec(body, 1..6).prop_map(|bodies| {
            let mut t = String::from(
                r#"
                hz = 60
                layers = ["tile", "thing"]
                world.gravity = [0, -10]
                [[collide]]
                a = "thing"
                b = "tile"
                response = "separate"
                [[collide]]
                a = "thing"
                b = "thing"
                response = "report"
                [[bodies]]
                layer = "tile"
                kind = "static"
                shape = { kind = "aabb", half_extents = [6, 0.5] }
                position = [-6, -0.5]
                [[bodies]]
                layer = "tile"
                kind = "static"
                shape = { kind = "aabb", half_extents = [6, 0.5] }
                position = [6, -0.5]
                "#,
            );
            for (x, y, vx, size, is_box) in bodies {
                let shape = if is_box {
                    format!("{{ kind = \"aabb\", half_extents = [{size}, {size}] }}")
                } else {
                    format!("{{ kind = \"circle\", radius = {size} }}")
                };
                t += &format!("[[bodies]]\nlayer = \"thing\"\nshape = {shape}\nposition = [{x:?}, {y:?}]\nvelocity = [{vx:?}, 0]\n");
            }
            t
        })
    }

    fn mirrored(text: &str) -> String {
        // Mirror x: positions and velocities; the shapes here are symmetric.
        text.lines()
            .map(|l| {
                for key in ["position = [", "velocity = ["] {
                    if let Some(rest) = l.trim_start().strip_prefix(key) {
                        let (x, tail) = rest.split_once(',').unwrap();
                        let x: f64 = x.trim().parse().unwrap();
                        return format!("{key}{:?},{tail}", -x);
                    }
                }
                l.to_owned()
            })
            .collect::<Vec<_>>()
            .join("\n")
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 64, failure_persistence: None, ..ProptestConfig::default() })]

        #[test]
        fn two_runs_give_identical_output(text in scene()) {
            let (mut a, mut b) = (sim(&text), sim(&text));
            for _ in 0..=120 {
                prop_assert_eq!(a.step(), b.step());
            }
        }

        #[test]
        fn mirroring_the_scene_mirrors_the_motion(text in scene()) {
            let (mut a, mut b) = (sim(&text), sim(&mirrored(&text)));
            for frame in 0..=120 {
                a.step();
                b.step();
                for i in 0..a.world().len() {
                    let (p, q) = (a.world().position[i], b.world().position[i]);
                    prop_assert!((p.x + q.x).abs() <= 1e-9 && (p.y - q.y).abs() <= 1e-9, "frame {}: {} vs {}", frame, p, q);
                }
            }
        }

        #[test]
        fn separation_never_leaves_solids_overlapping_and_nothing_is_nan(text in scene()) {
            let mut s = sim(&text);
            for frame in 0..=180 {
                let out = s.step();
                assert_finite(s.world());
                for c in &out.contacts {
                    prop_assert!(c.depth.is_finite() && c.normal.is_finite() && c.point.is_finite());
                    prop_assert!(c.phase != Phase::Swept, "nothing here is fast");
                }
                // Frame 0 is the scene as written (bodies may start inside a tile); from frame
                // 1 on, boxes resolve per axis exactly and circles along the normal.
                let worst = worst_solid_overlap(&s);
                prop_assert!(frame == 0 || worst <= 1e-6, "frame {}: overlap {}", frame, worst);
            }
        }
    }
}
