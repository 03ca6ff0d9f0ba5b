//! Replaying a recorded session: its commands (`/input`) applied again at the frames they
//! landed in, through the same game, writes the same log, byte for byte.
//!
//! ```no_run
//! # fn level() -> ricochet_sim::Simulation { unimplemented!() }
//! # #[derive(Default)] struct MyGame;
//! # impl ricochet_sim::Game for MyGame {
//! #     type Input = (); type State = ();
//! #     fn name(&self) -> &str { "my-game" }
//! #     fn input(&mut self, _: &mut ricochet_sim::Simulation, _: ricochet_sim::Player, _: ()) -> Result<(), String> { Ok(()) }
//! # }
//! use ricochet_log::LogFile;
//! let recorded = LogFile::open("room-lobby.mcap".as_ref()).unwrap();
//! let out = ricochet_record::log_writer("again.mcap".as_ref()).unwrap();
//! let replayed = ricochet_record::replay::replay(&recorded, level(), MyGame::default(), out).unwrap();
//! replayed.sink.finish().unwrap();
//! ```
//!
//! A log recorded by another game is refused ([`ReplayError::OtherGame`], naming it),
//! never replayed wrongly: a game with players records its name ([`GAME_ATTACHMENT`]); a
//! log without one is the scenario's game's.

use ricochet_log::{LogError, LogFile, MessageSink};
use ricochet_sim::{Game, Player, ScenarioGame, Simulation};

use crate::session::{GAME_ATTACHMENT, GameInput, GameSession, StepError};

/// Why a log could not be replayed.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// The log was recorded by another game.
    #[error("recorded by the game {recorded:?}, not {given:?}: replay it with that game's code")]
    OtherGame {
        /// The game that recorded it.
        recorded: String,
        /// The game given.
        given: String,
    },
    /// A recorded command is not one this replay can read.
    #[error("/input message {index}: {why}")]
    BadCommand {
        /// Its place on `/input`, from 0.
        index: usize,
        /// What is wrong with it.
        why: String,
    },
    /// A join got another number than when it was recorded: not the same run.
    #[error("frame {frame}: a join recorded as player {recorded} was player {got} in the replay")]
    Diverged {
        /// The frame.
        frame: u64,
        /// The number recorded.
        recorded: u32,
        /// The number the replay gave.
        got: u32,
    },
    /// Reading the log or writing the new one failed.
    #[error(transparent)]
    Log(#[from] LogError),
    /// A step overflowed (it did not when recorded, or the log would have ended before it).
    #[error(transparent)]
    Step(#[from] StepError),
}

/// What a replay did.
pub struct Replayed<S> {
    /// The new log's sink (finish it).
    pub sink: S,
    /// Frames stepped.
    pub frames: u64,
    /// Commands applied (refused ones included).
    pub commands: usize,
    /// The simulation at the end (what the recorded run's ended as).
    pub sim: Simulation,
}

/// The name of the game that recorded `log`: its [`GAME_ATTACHMENT`], or the scenario's.
pub fn recorded_game(log: &LogFile) -> Result<String, LogError> {
    Ok(match log.attachment(GAME_ATTACHMENT)? {
        Some(bytes) => String::from_utf8_lossy(&bytes).into_owned(),
        None => ScenarioGame::NAME.to_owned(),
    })
}

/// The commands on `log`'s `/input`, in the order they were applied.
pub fn commands(log: &LogFile) -> Result<Vec<GameInput>, ReplayError> {
    let mut all = Vec::new();
    if !log.channels().any(|c| c.topic == "/input") {
        return Ok(all);
    }
    for (index, m) in log.topic_messages("/input")?.enumerate() {
        let m = m?;
        let command = if m.schema_name == "ricochet.Input" {
            // The scenario's form: `ricochet.Input` (frame, text), from no player.
            GameInput {
                frame: m.data["frame"].as_u64().unwrap_or(0),
                player: Player::HOST.0,
                join: None,
                leave: false,
                input: Some(m.data["text"].as_str().unwrap_or("").to_owned()),
            }
        } else {
            serde_json::from_value(m.data.clone()).map_err(|e| ReplayError::BadCommand {
                index,
                why: e.to_string(),
            })?
        };
        all.push(command);
    }
    Ok(all)
}

/// Replays `log` with `game` from `sim` (the simulation the recording started from, at
/// frame 0) into `sink`: every frame the log holds (its `/stats` messages), each with the
/// commands recorded for it.
pub fn replay<G: Game, S: MessageSink>(
    log: &LogFile,
    sim: Simulation,
    game: G,
    sink: S,
) -> Result<Replayed<S>, ReplayError> {
    let recorded = recorded_game(log)?;
    if recorded != game.name() {
        return Err(ReplayError::OtherGame {
            recorded,
            given: game.name().to_owned(),
        });
    }
    let frames = log
        .channels()
        .find(|c| c.topic == "/stats")
        .map_or(0, |c| c.messages);
    let commands = commands(log)?;
    let record_inputs = log.channels().any(|c| c.topic == "/input");
    let mut session = GameSession::start(sim, game, sink, record_inputs)?;
    let mut pending = commands.iter().peekable();
    for _ in 0..frames {
        let next = session.next_frame();
        while let Some(c) = pending.next_if(|c| c.frame == next) {
            // Refused commands are refused again, the same way: nothing to report here.
            apply(&mut session, c)?;
        }
        session.step()?;
    }
    let (sink, sim, _) = session.into_parts();
    Ok(Replayed {
        sink,
        frames,
        commands: commands.len(),
        sim,
    })
}

/// Applies one recorded command.
fn apply<G: Game, S: MessageSink>(
    session: &mut GameSession<G, S>,
    c: &GameInput,
) -> Result<(), ReplayError> {
    let player = Player(c.player);
    if let Some(name) = &c.join {
        let got = match session.join(name)? {
            Ok(p) | Err((p, _)) => p,
        };
        if got != player {
            return Err(ReplayError::Diverged {
                frame: c.frame,
                recorded: c.player,
                got: got.0,
            });
        }
    } else if c.leave {
        let _ = session.leave(player)?;
    } else {
        let _ = session.input_text(player, c.input.as_deref().unwrap_or(""))?;
    }
    Ok(())
}
