//! A scene built in code is checked as a scenario file is, and runs as one does (issue #35):
//! `Scenario::check` and `Simulation::try_new` refuse what the loader refuses, with the
//! loader's field and words; a script in any order runs every event, sorted by frame as
//! the loader sorts a file's; a body spawned past the loader's limits still restores from
//! its own snapshot, and `try_spawn` refuses it.

use ricochet_sim::prelude::*;
use ricochet_sim::{MAX_FRAMES, ScenarioError, load_scenario};

/// The scene `player_scene` builds, as a file, ending inside the player's `[[bodies]]`
/// table so that a test can add a field to it, or a table after it.
fn player_toml(frames: u64) -> String {
    format!(
        "layers = [\"a\"]\nframes = {frames}\n[templates.rock]\nlayer = \"a\"\n\
         shape = {{ kind = \"circle\", radius = 0.5 }}\n[[bodies]]\nname = \"player\"\n\
         layer = \"a\"\nshape = {{ kind = \"circle\", radius = 0.5 }}\n"
    )
}

fn player_scene() -> Scenario {
    let rock = BodyDef {
        name: "rock".into(),
        ..BodyDef::default()
    };
    Scenario {
        world: WorldDef {
            layers: Layers::new(vec!["a".into()]),
            ..WorldDef::default()
        },
        templates: [("rock".to_owned(), rock)].into(),
        bodies: vec![BodyDef {
            name: "player".into(),
            ..BodyDef::default()
        }],
        ..Scenario::default()
    }
}

fn input(frame: u64, name: &str, action: Action) -> Event {
    Event {
        frame,
        action: ScriptAction::Body {
            name: name.into(),
            action,
        },
    }
}

/// `scenario` is refused by `try_new` as the same scene written as a file (`toml`) is by the
/// loader: the same field and problem, no line or column (there is no text).
fn refused_as_the_file_is(scenario: &Scenario, toml: &str) -> ScenarioError {
    let code = Simulation::try_new(scenario).expect_err("a scene the loader refuses");
    let file = load_scenario(toml, "scene.toml").expect_err("the file is refused");
    assert_eq!(
        (code.field.as_str(), code.problem.as_str()),
        (file.field.as_str(), file.problem.as_str())
    );
    assert_eq!(scenario.check(), Err(code.clone()));
    assert_eq!((code.line, code.column), (0, 0));
    assert!(code.to_string().starts_with("scenario: "), "{code}");
    code
}

#[test]
fn a_script_naming_no_body_is_refused_before_it_runs() {
    let mut scene = player_scene();
    scene.script = vec![input(3, "plyer", Action::Move(1.0))];
    let toml = format!(
        "{}[[script]]\nframe = 3\naction = \"move\"\nbody = \"plyer\"\ninput = 1.0\n",
        player_toml(600)
    );
    let e = refused_as_the_file_is(&scene, &toml);
    assert_eq!(e.field, "script[0].body");
    assert!(e.problem.contains("\"plyer\""), "{e}");
}

/// Two bodies of the name an event addresses: which one it is for is ambiguous.
#[test]
fn a_script_naming_two_bodies_is_refused() {
    let mut scene = player_scene();
    scene.bodies.push(scene.bodies[0].clone());
    scene.script = vec![input(1, "player", Action::Jump)];
    let toml = format!(
        "{0}[[bodies]]\nname = \"player\"\nlayer = \"a\"\n\
         shape = {{ kind = \"circle\", radius = 0.5 }}\n\
         [[script]]\nframe = 1\naction = \"jump\"\nbody = \"player\"\n",
        player_toml(600)
    );
    let e = refused_as_the_file_is(&scene, &toml);
    assert_eq!(e.field, "script[0].body");
    assert!(e.problem.contains("bodies[0], bodies[1]"), "{e}");
}

#[test]
fn values_past_the_loaders_limits_are_refused_with_its_words() {
    let mut scene = player_scene();
    scene.bodies[0].mass = 1e20;
    let e = refused_as_the_file_is(&scene, &format!("{}mass = 1e20\n", player_toml(600)));
    assert_eq!(e.field, "bodies[0].mass");

    let mut scene = player_scene();
    scene.bodies[0].controller = Some(Controller::Runner {
        run_speed: 1e20,
        jump_speed: 1.0,
    });
    let runner = "controller = { kind = \"runner\", run_speed = 1e20, jump_speed = 1 }\n";
    let e = refused_as_the_file_is(&scene, &format!("{}{runner}", player_toml(600)));
    assert_eq!(e.field, "bodies[0].controller.run_speed");

    let mut scene = player_scene();
    scene.frames = MAX_FRAMES + 1;
    let e = refused_as_the_file_is(&scene, &player_toml(MAX_FRAMES + 1));
    assert_eq!(e.field, "frames");

    // A script event after the last frame would never happen.
    let mut scene = player_scene();
    scene.frames = 10;
    scene.script = vec![input(11, "player", Action::Jump)];
    let toml = format!(
        "{}[[script]]\nframe = 11\naction = \"jump\"\nbody = \"player\"\n",
        player_toml(10)
    );
    assert_eq!(
        refused_as_the_file_is(&scene, &toml).field,
        "script[0].frame"
    );
}

#[test]
fn a_spawn_of_a_template_no_one_has_is_refused() {
    let mut scene = player_scene();
    scene.script = vec![Event {
        frame: 1,
        action: ScriptAction::Spawn {
            body: Box::new(BodyDef::default()),
            template: "rocc".into(),
        },
    }];
    let toml = format!(
        "{}[[script]]\nframe = 1\naction = \"spawn\"\ntemplate = \"rocc\"\nposition = [0, 0]\n",
        player_toml(600)
    );
    assert_eq!(
        refused_as_the_file_is(&scene, &toml).field,
        "script[0].template"
    );
}

/// No false refusal: every shipped scenario, which the loader accepts, passes the check.
#[test]
fn every_scenario_the_loader_accepts_passes_the_check() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios");
    let mut n = 0;
    for entry in std::fs::read_dir(root).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|x| x == "toml") {
            let text = std::fs::read_to_string(&path).unwrap();
            // A Tiled level's bodies come from its map, which this crate does not read: the
            // root package's `tiled::the_shipped_tiled_level_passes_the_check` checks it.
            if text.lines().any(|l| l.trim() == "[tiled]") {
                continue;
            }
            let scenario = load_scenario(&text, &path.display().to_string()).unwrap();
            assert_eq!(scenario.check(), Ok(()), "{}", path.display());
            n += 1;
        }
    }
    assert!(n >= 5, "{n} scenarios");
    assert_eq!(player_scene().check(), Ok(()));
}

/// The frames and velocities of the `velocity` inputs a run of `sim` applies, in order.
fn velocity_inputs(mut sim: Simulation, frames: u64) -> Vec<(u64, f64)> {
    let mut seen = Vec::new();
    for _ in 0..frames {
        let out = sim.step();
        for e in &out.events {
            if let GameEvent::Input {
                input: ScriptInput::Velocity(v),
                ..
            } = e
            {
                seen.push((out.frame, v.x));
            }
        }
    }
    seen
}

/// The case: a platform's events first, the inputs appended after them. Every event
/// runs at its frame, the two of frame 2 in the order given.
#[test]
fn an_unsorted_script_runs_every_event_at_its_frame() {
    let mut scene = player_scene();
    let v = |x| Action::SetVelocity(Vec2::new(x, 0.0));
    scene.script = vec![
        input(5, "player", v(5.0)),
        input(2, "player", v(2.0)),
        input(2, "player", v(3.0)),
    ];
    let expected = [(2, 2.0), (2, 3.0), (5, 5.0)];
    assert_eq!(velocity_inputs(Simulation::new(&scene), 8), expected);
    assert_eq!(
        velocity_inputs(Simulation::from_scenario(scene.clone()), 8),
        expected
    );
    // The same script in the same order in a file: the loader's scenario runs alike.
    let event = |frame, x| {
        format!(
            "[[script]]\nframe = {frame}\naction = \"set_velocity\"\nbody = \"player\"\n\
             velocity = [{x}, 0]\n"
        )
    };
    let toml = format!(
        "{}{}{}{}",
        player_toml(600),
        event(5, 5),
        event(2, 2),
        event(2, 3)
    );
    let loaded = load_scenario(&toml, "scene.toml").unwrap();
    assert_eq!(velocity_inputs(Simulation::new(&loaded), 8), expected);
}

/// A body spawned with a mass and a walker's speed past the loader's limits (which a
/// snapshot's restore checks) still restores from its own snapshot; `try_spawn` refuses it
/// with the loader's words.
#[test]
fn a_body_spawned_past_the_limits_restores_from_its_own_snapshot() {
    let heavy = BodyDef {
        name: "heavy".into(),
        mass: 1e20,
        controller: Some(Controller::Walker { speed: 1e20 }),
        ..BodyDef::default()
    };
    let build = || {
        let mut sim = Simulation::from_def(WorldDef::default()).unwrap();
        sim.spawn(&heavy);
        sim
    };
    let mut sim = build();
    sim.step();
    sim.step();
    let snapshot = Snapshot::from_bytes(&sim.snapshot().to_bytes()).unwrap();
    let mut peer = build();
    assert_eq!(peer.restore(&snapshot), Ok(()));
    assert_eq!(peer.checksum(), sim.checksum());

    let e = build().try_spawn(&heavy).unwrap_err();
    let file =
        load_scenario(&format!("{}mass = 1e20\n", player_toml(600)), "scene.toml").unwrap_err();
    assert_eq!((e.field.as_str(), e.problem), ("spawn.mass", file.problem));
}

/// The same for bodies a simulation creates itself, from a scene it did not check: a body
/// of the scene and a script's spawn of a template, each of mass 1e20.
#[test]
fn bodies_of_an_unchecked_scene_past_the_limits_restore_from_its_snapshot() {
    let mut scene = player_scene();
    scene.bodies[0].mass = 1e20;
    scene.templates.get_mut("rock").unwrap().mass = 1e20;
    scene.script = vec![Event {
        frame: 1,
        action: ScriptAction::Spawn {
            body: Box::new(scene.templates["rock"].clone()),
            template: "rock".into(),
        },
    }];
    let mut sim = Simulation::new(&scene);
    for _ in 0..3 {
        sim.step();
    }
    assert_eq!(sim.world().len(), 2);
    let snapshot = Snapshot::from_bytes(&sim.snapshot().to_bytes()).unwrap();
    let mut peer = Simulation::new(&scene);
    assert_eq!(peer.restore(&snapshot), Ok(()));
    assert_eq!(peer.checksum(), sim.checksum());
}
