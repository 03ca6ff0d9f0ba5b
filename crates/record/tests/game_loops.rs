//! One game value through every loop the record crate owns: its own plain loop
//! ([`GameLoop`]), a recorded session ([`GameSession`]), a golden check
//! ([`golden::check_game_or_bless`]) and a replay ([`replay::replay`]). The same commands at
//! the same frames make the same run: the plain loop's world is the recorded one's, the
//! golden is the recording byte for byte, and the replay is too. Positions come from exact
//! arithmetic (60 units/s for frames of 1/60 s is 1 unit a frame).

use std::collections::BTreeMap;
use std::path::Path;

use ricochet_log::LogFile;
use ricochet_record::golden::{self, Command, GoldenError};
use ricochet_record::replay::{self, ReplayError};
use ricochet_record::session::GameSession;
use ricochet_sim::prelude::*;

/// A ball per player, pushed by its player's inputs.
#[derive(Default)]
struct Pushball {
    balls: BTreeMap<Player, Entity>,
    state: State,
    /// Named otherwise, the same rules: a replay must refuse it.
    name: &'static str,
}

#[derive(Default, serde::Serialize)]
struct State {
    pushes: BTreeMap<String, u32>,
}

#[derive(serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
struct Push {
    push: [f64; 2],
}

impl Game for Pushball {
    type Input = Push;
    type State = State;

    fn name(&self) -> &str {
        if self.name.is_empty() {
            "pushball"
        } else {
            self.name
        }
    }

    fn join(&mut self, sim: &mut Simulation, player: Player, name: &str) -> Result<(), String> {
        if self.balls.len() == 2 {
            return Err("two players at most".to_owned());
        }
        let ball = sim.spawn(&BodyDef {
            name: name.to_owned(),
            position: Vec2::new(10.0 * f64::from(player.0), 0.0),
            ..BodyDef::default()
        });
        self.balls.insert(player, ball);
        self.state.pushes.insert(name.to_owned(), 0);
        Ok(())
    }

    fn leave(&mut self, sim: &mut Simulation, player: Player) {
        if let Some(ball) = self.balls.remove(&player) {
            let _ = sim.despawn(ball);
        }
    }

    fn input(&mut self, sim: &mut Simulation, player: Player, input: Push) -> Result<(), String> {
        let ball = *self.balls.get(&player).ok_or("no ball")?;
        let v = Vec2::new(input.push[0], input.push[1]);
        sim.apply(ball, Action::SetVelocity(v))
            .map_err(|e| e.to_string())?;
        let name = sim
            .world()
            .name(sim.world().index_of(ball).ok_or("gone")?)
            .to_owned();
        *self.state.pushes.entry(name).or_default() += 1;
        Ok(())
    }

    fn state(&self) -> Option<&State> {
        Some(&self.state)
    }
}

fn level() -> Simulation {
    Simulation::from_def(WorldDef::default()).unwrap()
}

fn push(x: f64) -> Push {
    Push { push: [x, 0.0] }
}

/// Ada joins before frame 0, Bob too; Ada is pushed at frame 5, Bob at 8 and leaves at 15;
/// Cy is refused (two players at most); an input from no player is refused.
fn script() -> Vec<(u64, Command<Push>)> {
    vec![
        (0, Command::Join("ada".into())),
        (0, Command::Join("bob".into())),
        (3, Command::Join("cy".into())),
        (5, Command::Input(Player(1), push(60.0))),
        (8, Command::Input(Player(2), push(-120.0))),
        (9, Command::Input(Player::HOST, push(1.0))),
        (15, Command::Leave(Player(2))),
    ]
}

const FRAMES: u64 = 20;

/// The plain loop, in the game's own code: the script by hand.
fn plain() -> GameLoop<Pushball> {
    let mut run = GameLoop::new(level(), Pushball::default());
    for frame in 0..=FRAMES {
        for (f, c) in script() {
            if f != frame {
                continue;
            }
            let _ = match c {
                Command::Join(n) => run.join(&n).map(|_| ()).map_err(|(_, w)| w),
                Command::Leave(p) => run.leave(p),
                Command::Input(p, i) => run.input(p, i),
            };
        }
        run.step().unwrap();
    }
    run
}

/// The same run recorded by a session into `path`.
fn record(path: &Path) -> GameSession<Pushball, ricochet_log::LogWriter> {
    let log = ricochet_record::log_writer(path).unwrap();
    let mut session = GameSession::start(level(), Pushball::default(), log, true).unwrap();
    for frame in 0..=FRAMES {
        for (f, c) in script() {
            if f != frame {
                continue;
            }
            match c {
                Command::Join(n) => drop(session.join(&n).unwrap()),
                Command::Leave(p) => drop(session.leave(p).unwrap()),
                Command::Input(p, i) => drop(session.input_typed(p, &i).unwrap()),
            }
        }
        session.step().unwrap();
    }
    session
}

#[test]
fn the_plain_loop_moves_each_ball_by_its_players_inputs() {
    let run = plain();
    let ada = run.sim().entity_named("ada").unwrap();
    // Pushed at 60 units/s from frame 5: frames 5 to 20 move it 1 unit each.
    assert_eq!(run.sim().position(ada), Some(Vec2::new(10.0 + 16.0, 0.0)));
    // Bob left at frame 15: his ball is gone.
    assert!(run.sim().entity_named("bob").is_none());
    let players: Vec<(Player, &str)> = run.players().collect();
    assert_eq!(players, [(Player(1), "ada")]);
    // Cy was refused but numbered 3; the host's input was refused (no ball).
    assert_eq!(
        run.game().state.pushes,
        BTreeMap::from([("ada".into(), 1), ("bob".into(), 1)])
    );
}

#[test]
fn recorded_golden_and_replayed_runs_are_the_plain_run_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let recorded = dir.path().join("room.mcap");
    let session = record(&recorded);
    // The plain loop and the recorded session reached the same world.
    assert_eq!(session.sim().checksum(), plain().sim().checksum());
    session.into_sink().finish().unwrap();

    // The golden of the same script is the recording, byte for byte.
    let golden = dir.path().join("golden.mcap");
    let game = golden::check_game_or_bless(
        &golden,
        level(),
        Pushball::default(),
        FRAMES,
        &script(),
        true,
    )
    .unwrap();
    assert_eq!(game.state.pushes["ada"], 1);
    assert_eq!(
        std::fs::read(&golden).unwrap(),
        std::fs::read(&recorded).unwrap()
    );
    // And it checks.
    golden::check_game_or_bless(
        &golden,
        level(),
        Pushball::default(),
        FRAMES,
        &script(),
        false,
    )
    .unwrap();

    // The recording replays byte for byte through the same game.
    let log = LogFile::open(&recorded).unwrap();
    let again = dir.path().join("again.mcap");
    let out = ricochet_record::log_writer(&again).unwrap();
    let replayed = replay::replay(&log, level(), Pushball::default(), out).unwrap();
    assert_eq!((replayed.frames, replayed.commands), (FRAMES + 1, 7));
    replayed.sink.finish().unwrap();
    assert_eq!(
        std::fs::read(&again).unwrap(),
        std::fs::read(&recorded).unwrap()
    );

    // `/game` holds the scores as the game kept them, frame by frame: ada's push counts
    // from frame 5.
    let scores: Vec<(u64, u64)> = log
        .topic_messages("/game")
        .unwrap()
        .map(|m| {
            let m = m.unwrap();
            (m.log_time, m.data["pushes"]["ada"].as_u64().unwrap())
        })
        .collect();
    assert_eq!(scores.len() as u64, FRAMES + 1);
    let dt_ns = (1e9_f64 / 60.0).round() as u64;
    for (frame, (t, ada)) in scores.iter().enumerate() {
        assert_eq!(*t, frame as u64 * dt_ns);
        assert_eq!(*ada, u64::from(frame >= 5), "frame {frame}");
    }
}

#[test]
fn a_replay_with_another_game_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let recorded = dir.path().join("room.mcap");
    record(&recorded).into_sink().finish().unwrap();
    let log = LogFile::open(&recorded).unwrap();
    let out = ricochet_record::log_writer(&dir.path().join("x.mcap")).unwrap();
    let other = Pushball {
        name: "other",
        ..Pushball::default()
    };
    match replay::replay(&log, level(), other, out) {
        Err(ReplayError::OtherGame { recorded, given }) => {
            assert_eq!((recorded.as_str(), given.as_str()), ("pushball", "other"));
        }
        Err(e) => panic!("{e}"),
        Ok(_) => panic!("replayed a log of another game"),
    }
}

#[test]
fn a_changed_input_fails_the_golden_at_its_frame() {
    let dir = tempfile::tempdir().unwrap();
    let golden = dir.path().join("golden.mcap");
    golden::check_game_or_bless(
        &golden,
        level(),
        Pushball::default(),
        FRAMES,
        &script(),
        true,
    )
    .unwrap();
    let mut changed = script();
    changed[3] = (5, Command::Input(Player(1), push(30.0)));
    match golden::check_game_or_bless(
        &golden,
        level(),
        Pushball::default(),
        FRAMES,
        &changed,
        false,
    ) {
        Err(GoldenError::Differs { first, .. }) => assert_eq!(first.frame, Some(5), "{first:?}"),
        Err(e) => panic!("{e}"),
        Ok(_) => panic!("a changed input passed the golden"),
    }
}
