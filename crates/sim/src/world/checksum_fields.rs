//! [`Simulation::checksum`] tested field by field (issue #22): changing any one field of the
//! state a step reads changes it, and changing `user_data` does not (but changes the
//! snapshot's bytes).
//!
//! A unit test inside the crate, not a `tests/` file: most of these fields (`still`,
//! `rest_frames`, the turned bit, the touching pairs, the id generations...) have no public
//! setter, and a hidden public hook for each would be API for tests only. Two guards keep
//! the list whole: [`change`] destructures `Rows`, so a new column does not compile until it
//! is handled here; and [`the_list_covers_the_table`] reads the table in the `snapshot`
//! module docs, so a field added there without a test fails.

use ricochet_geom::{Pose, Shape, Vec2};

use super::World;
use super::local_bounds::LocalBounds;
use super::rows::Rows;
use crate::action::Action;
use crate::def::{BodyDef, BodyKind, Controller, Split};
use crate::pipeline::Simulation;
use crate::scenario::Scenario;
use crate::stages::touch::TouchState;

/// Every field of the state a step reads, by the name the module docs' table gives it
/// (`shape`, `name`, `has_row` and `generations` are the table's unquoted words).
const FIELDS: &[&str] = &[
    "Simulation::frame",
    "cursor",
    "pending",
    "targets",
    "targeted",
    "focus",
    "touch.touching",
    "touch.static_generation",
    "entity",
    "layer",
    "kind",
    "position",
    "angle",
    "shape",
    "name",
    "has_row",
    "generations",
    "mass",
    "velocity",
    "angular_velocity",
    "force",
    "gravity_scale",
    "lifetime",
    "controller",
    "inputs",
    "grounded",
    "on_static",
    "carrier",
    "still",
    "split",
    "frozen",
    "asleep",
    "rest_frames",
    "local_bounds",
];

fn triangle() -> Shape {
    Shape::polygon(&[
        Vec2::new(1.0, 0.0),
        Vec2::new(-0.7, 0.6),
        Vec2::new(-0.7, -0.6),
    ])
    .expect("a counter-clockwise triangle")
}

/// Two moving bodies (a triangle, whose bounds turning changes, and a ball), a wall of
/// scenery and two bodies removed, all in the baseline; a third moving body spawned after
/// it (written whole, not as a change) in the first freed slot. Stepped once, so nothing is the baseline's.
fn scene() -> Simulation {
    let body = |name: &str, shape: Shape, x: f64| BodyDef {
        name: name.to_owned(),
        shape,
        position: Vec2::new(x, 0.0),
        velocity: Vec2::new(1.0, 0.5),
        ..BodyDef::default()
    };
    let scenario = Scenario {
        bodies: vec![
            body("ship", triangle(), 0.0),
            body("rock", Shape::circle(1.0).expect("radius"), 10.0),
            BodyDef {
                name: "wall".to_owned(),
                kind: BodyKind::Static,
                shape: Shape::aabb(Vec2::new(1.0, 5.0)).expect("extents"),
                position: Vec2::new(-20.0, 0.0),
                ..BodyDef::default()
            },
            body("gone", Shape::circle(1.0).expect("radius"), 30.0),
            body("gone too", Shape::circle(1.0).expect("radius"), 40.0),
        ],
        ..Scenario::default()
    };
    let mut sim = Simulation::new(&scenario);
    sim.world.despawn(4);
    sim.world.despawn(3);
    sim.step();
    sim.spawn(&body("late", triangle(), 50.0));
    sim.step();
    sim
}

/// Changes `field` of the simulation, of body `i` for a body's field.
fn change(sim: &mut Simulation, field: &str, i: usize) {
    let other = sim.world.entity[(i + 1) % 2];
    let w = &mut sim.world;
    let r = w.row_of(i);
    let Rows {
        entity: _,         // the row's body: layout, not state
        start_position: _, // a cache `start_frame` sets
        user_data: _,      // game data: `user_data_is_not_in_the_checksum`
        mass,
        velocity,
        angular_velocity,
        force,
        gravity_scale,
        lifetime,
        controller,
        inputs,
        grounded,
        on_static,
        carrier,
        still,
        split,
        frozen,
        asleep,
        rest_frames,
        local_bounds,
        // A cache, not state: kept right below when a lifetime is given.
        no_lifetime_below,
        // A count, not state: kept right below when the scale changes.
        scaled,
    } = &mut w.rows;
    match field {
        "mass" => mass[r] += 1.0,
        "velocity" => velocity[r].y = -velocity[r].y,
        "angular_velocity" => angular_velocity[r] += 0.25,
        "force" => force[r].x = -0.0,
        "gravity_scale" => {
            *scaled -= usize::from(super::rows::is_scaled(gravity_scale[r]));
            gravity_scale[r] = 2.0;
            *scaled += 1;
        }
        "lifetime" => {
            lifetime[r] = Some(9);
            *no_lifetime_below = (*no_lifetime_below).min(r);
        }
        "controller" => controller[r] = Some(Controller::Walker { speed: 1.0 }),
        "inputs" => inputs[r].run = 0.5,
        "grounded" => grounded[r] = !grounded[r],
        "on_static" => on_static[r] = !on_static[r],
        "carrier" => carrier[r] = Some(other),
        "still" => still[r] = !still[r],
        "split" => split[r].push(Split {
            template: "rock".to_owned(),
            offset: Vec2::ZERO,
            velocity: Vec2::ZERO,
        }),
        "frozen" => frozen[r] = !frozen[r],
        "asleep" => asleep[r] = !asleep[r],
        "rest_frames" => rest_frames[r] += 1,
        // A triangle's bounds: exact at its angle, or the any-angle square once it turned.
        "local_bounds" => {
            let turned = local_bounds.get(r).has_turned(w.angle[i]);
            local_bounds.set(r, LocalBounds::restored(&triangle(), w.angle[i], !turned));
        }
        _ => change_other(sim, field, i),
    }
}

/// The fields outside `Rows`.
fn change_other(sim: &mut Simulation, field: &str, i: usize) {
    let e = sim.world.entity[i];
    let w = &mut sim.world;
    match field {
        "Simulation::frame" => sim.frame += 1,
        "cursor" => sim.cursor += 1,
        "pending" => sim.pending.push((e, Action::Jump)),
        "targets" => sim.targets.push((e, Pose::new(Vec2::ZERO, 0.0))),
        "targeted" => sim.targeted.push(e),
        "focus" => sim.focus = Some(e),
        "touch.touching" => {
            let layers = &sim.scenario.world.layers;
            let pair = (sim.world.entity[0], sim.world.entity[1]);
            let seen = sim.touch.static_generation();
            sim.touch = TouchState::restored(layers, vec![pair], seen);
        }
        // The one bit kept of it: whether a static body changed since `touch` last ran.
        "touch.static_generation" => {
            let layers = &sim.scenario.world.layers;
            let g = sim.world.static_generation;
            let moved = sim.touch.static_generation() != g;
            let seen = if moved { g } else { g.wrapping_sub(1) };
            sim.touch = TouchState::restored(layers, sim.touch.touching().to_vec(), seen);
        }
        "entity" => w.entity[i].generation += 1,
        "layer" => w.layer[i] = 1,
        "kind" => w.kind[i] = BodyKind::Kinematic,
        "position" => w.position[i].x += 0.5,
        "angle" => w.angle[i] = -0.0,
        "shape" => w.set_shape(i, &Shape::circle(0.25).expect("radius")),
        "name" => {
            w.set_name(i, "wall");
        }
        "has_row" => {
            let wall = w.find("wall").expect("the wall");
            w.row_of(wall);
        }
        "generations" => {
            let mut g = w.ids.generations().to_vec();
            g[4] += 1; // the free slot's next generation
            w.ids = crate::entity::EntityAllocator::from_parts(g, w.entity.iter().map(|e| e.index));
        }
        _ => panic!("no test changes {field}"),
    }
}

/// The bodies each field is changed on: the triangle (in the baseline, written as a change)
/// and the late triangle (written whole).
fn bodies(sim: &Simulation) -> [usize; 2] {
    let w: &World = &sim.world;
    [w.find("ship").expect("ship"), w.find("late").expect("late")]
}

#[test]
fn changing_any_field_of_the_state_changes_the_checksum() {
    for field in FIELDS {
        for k in 0..2 {
            let mut sim = scene();
            let i = bodies(&sim)[k];
            let before = sim.checksum();
            change(&mut sim, field, i);
            assert_ne!(
                sim.checksum(),
                before,
                "{field} changed on body {i}, the checksum did not"
            );
        }
    }
}

#[test]
fn user_data_is_not_in_the_checksum_but_is_in_the_snapshot() {
    for i in bodies(&scene()) {
        let mut sim = scene();
        let (sum, bytes) = (sim.checksum(), sim.snapshot().to_bytes());
        sim.world.set_user_data(i, 7);
        assert_eq!(sim.checksum(), sum);
        assert_ne!(sim.snapshot().to_bytes(), bytes);
    }
}

/// Every name in a row of the `snapshot` module docs' table marked "in `checksum`" yes.
#[test]
fn the_list_covers_the_table() {
    let docs = include_str!("../snapshot/mod.rs");
    let mut missing = Vec::new();
    for line in docs.lines().filter(|l| l.starts_with("//! | ")) {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        if cells.len() < 5 || cells[4] != "yes" {
            continue;
        }
        let names = cells[1].split('`').skip(1).step_by(2);
        for name in names {
            if !FIELDS.contains(&name) {
                missing.push(name.to_owned());
            }
        }
    }
    assert!(
        missing.is_empty(),
        "fields of the table with no test: {missing:?}"
    );
}
