//! A session: a game run frame by frame with commands from outside (its players, the
//! clients of `ricochet serve`), recorded with every command, so that a replay
//! ([`crate::replay`], `ricochet replay`) runs it again and writes the same log, byte for
//! byte.
//!
//! The game ([`Game`]) and the frame loop ([`GameLoop`]) are `ricochet-sim`'s; a session
//! adds the recording. Each command is handled at once and lands in the next frame; it is
//! written at that frame, commands of one frame in the order they came, refused ones too
//! (a replay refuses them again, with the same `/events` line). What each frame writes:
//! the frame's commands on `/input`, then the frame (`Recorder::record`), then the game's
//! state on `/game`.
//!
//! `/input` has two forms:
//! - a game without players (the scenario's, [`ScenarioGame`]: `ricochet serve`'s inputs)
//!   writes `ricochet.Input` (`frame`, `text`), as every session always has;
//! - a game with players writes JSON (`ricochet.GameInput`): `{"frame": 3, "player": 1,
//!   "join": "ada"}`, `{"frame": 9, "player": 1, "input": "{\"run\": 1}"}`,
//!   `{"frame": 40, "player": 1, "leave": true}`; its log carries the game's name (the
//!   attachment [`GAME_ATTACHMENT`]), which a replay checks.
//!
//! A scenario's input is JSON, the script's actions addressed by body name
//! (`{"action": "thrust", "body": "ship", "on": true}`, see [`ScenarioGame`]). What still
//! overflows (gravity of 1e308, say) stops the session at its last good frame: the frame
//! that overflowed, and its inputs, are never written, so the log holds frames 0 to N,
//! complete, as `run` leaves it.

use ricochet_log::messages::ricochet::Input;
use ricochet_log::messages::{Schema, fox::Log, fox::log::Level, timestamp};
use ricochet_log::{ChannelId, LogError, MessageSink};
use ricochet_sim::{
    FrameOutput, Game, GameLoop, Overflowed, Player, Scenario, ScenarioGame, Simulation,
};

use crate::Recorder;
use crate::channels::Channels;

pub use ricochet_sim::MAX_INPUT_VALUE;

/// The largest input accepted, bytes.
pub const MAX_INPUT: usize = 4096;

/// The longest player name accepted, bytes.
pub const MAX_PLAYER_NAME: usize = 64;

/// The name of the attachment that holds a session's scenario.
pub const SCENARIO_ATTACHMENT: &str = "scenario.toml";

/// The name of the attachment that names the game a session ran (a game with players;
/// a log without it is the scenario's game).
pub const GAME_ATTACHMENT: &str = "game.txt";

/// The JSON Schema of a game's `/input` (`ricochet.GameInput`).
pub const GAME_INPUT_SCHEMA: &str = r#"{"type":"object","properties":{"frame":{"type":"integer"},"player":{"type":"integer"},"join":{"type":"string"},"leave":{"type":"boolean"},"input":{"type":"string"}},"required":["frame","player"]}"#;

/// Why a step was not recorded.
#[derive(Debug, thiserror::Error)]
pub enum StepError {
    /// Writing the frame failed.
    #[error(transparent)]
    Log(#[from] LogError),
    /// The step made a value non-finite: neither it nor its inputs were written, and the
    /// session steps no more (its simulation can't be trusted).
    #[error("frame {frame}: {what}; the simulation overflowed")]
    Overflow {
        /// The frame that overflowed (the log holds the frames before it).
        frame: u64,
        /// Which body and value.
        what: String,
    },
}

/// A non-finite body for people: `body NAME #id:generation has a non-finite FIELD [x, y]`
/// (the name's control characters escaped).
pub fn describe(sim: &Simulation, bad: &ricochet_sim::NonFinite) -> String {
    let w = sim.world();
    let name = w.index_of(bad.body).map_or("?", |i| w.name(i));
    format!(
        "body {} #{} has a non-finite {} {}",
        ricochet_log::escape_controls(name),
        bad.body,
        bad.field,
        ricochet_geom::Numbers(bad.value)
    )
}

/// A command as a game's `/input` records it.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GameInput {
    /// The frame it lands in.
    pub frame: u64,
    /// Who sent it (0: no player).
    pub player: u32,
    /// A join, with the name.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub join: Option<String>,
    /// A leave.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub leave: bool,
    /// An input, its JSON text as sent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub input: Option<String>,
}

/// A command not yet written: the record, and its refusal's `/events` line.
enum Unwritten {
    Scenario(Input),
    Game(Vec<u8>),
}

/// The scenario's session: what `ricochet serve` runs.
pub type Session<S> = GameSession<ScenarioGame, S>;

/// A game being run, its frames written to `S` with every command.
pub struct GameSession<G: Game, S: MessageSink> {
    run: GameLoop<G>,
    recorder: Recorder<S>,
    /// `/input`, when commands are recorded.
    input: Option<ChannelId>,
    /// `/game`, when the game shows a state.
    game: Option<ChannelId>,
    events: Option<ChannelId>,
    /// The frame the next step makes.
    next: u64,
    /// The next frame's commands, each with its refusal's `/events` line: written just
    /// before the frame, so a frame that overflows leaves no trace.
    unwritten: Vec<(Unwritten, Option<Log>)>,
    /// The step that overflowed, if one did (then nothing more is stepped).
    overflowed: Option<(u64, String)>,
}

impl<S: MessageSink> GameSession<ScenarioGame, S> {
    /// A session of `scenario` writing to `sink`.
    pub fn new(scenario: &Scenario, sink: S) -> Result<Session<S>, LogError> {
        GameSession::start(Simulation::new(scenario), ScenarioGame, sink, true)
    }

    /// A session going on from `sim` (a snapshot), writing to a new `sink` from its next
    /// frame: the first frame written lists every body, as a first frame does.
    pub fn resume(sim: Simulation, sink: S) -> Result<Session<S>, LogError> {
        GameSession::start(sim, ScenarioGame, sink, true)
    }

    /// Takes a scenario input (JSON) for the next step, recorded with it; why it was
    /// refused, if it was (also written to `/events`).
    pub fn input(&mut self, text: &str) -> Result<Result<(), String>, LogError> {
        self.input_text(Player::HOST, text)
    }
}

impl<G: Game, S: MessageSink> GameSession<G, S> {
    /// A run of `game` on `sim` (new, or restored from a snapshot: the first frame written
    /// lists every body, as a first frame does), writing to `sink`, with `/input` when
    /// `record_inputs` (a run that takes no commands, `ricochet run`'s, has none).
    pub fn start(sim: Simulation, game: G, sink: S, record_inputs: bool) -> Result<Self, LogError> {
        let players = game.has_players();
        let mut sink = sink;
        if players {
            // Before any channel: an attachment ends the chunk open, and a chunk of channels
            // alone (no message, so no message index) is one Lichtblick refuses to open.
            sink.attach(GAME_ATTACHMENT, "text/plain", game.name().as_bytes())?;
        }
        let mut recorder = Recorder::new(sink, sim.dt(), Channels::default())?;
        let input = match (record_inputs, players) {
            (false, _) => None,
            (true, false) => Some(
                recorder
                    .sink_mut()
                    .add_protobuf_channel("/input", Schema::ricochet("ricochet.Input"))?,
            ),
            (true, true) => Some(recorder.sink_mut().add_json_channel(
                "/input",
                "ricochet.GameInput",
                GAME_INPUT_SCHEMA,
            )?),
        };
        let state = match game.state() {
            Some(_) => Some(recorder.sink_mut().add_json_channel(
                "/game",
                &format!("{}.State", game.name()),
                game.state_schema(),
            )?),
            None => None,
        };
        let events = recorder.events_channel();
        let next = sim.frame();
        Ok(GameSession {
            run: GameLoop::new(sim, game),
            recorder,
            input,
            game: state,
            events,
            next,
            unwritten: Vec::new(),
            overflowed: None,
        })
    }

    /// Takes `player`'s input as JSON text for the next step, recorded with it; why it was
    /// refused, if it was (also written to `/events`).
    pub fn input_text(
        &mut self,
        player: Player,
        text: &str,
    ) -> Result<Result<(), String>, LogError> {
        let verdict = self.apply_text(player, text);
        let record = GameInput {
            frame: self.next,
            player: player.0,
            join: None,
            leave: false,
            input: Some(text.to_owned()),
        };
        self.keep(record, "input", &verdict)?;
        Ok(verdict)
    }

    /// Takes `player`'s input for the next step (recorded as its JSON).
    pub fn input_typed(
        &mut self,
        player: Player,
        input: &G::Input,
    ) -> Result<Result<(), String>, LogError> {
        let text = serde_json::to_string(input).map_err(LogError::from)?;
        self.input_text(player, &text)
    }

    fn apply_text(&mut self, player: Player, text: &str) -> Result<(), String> {
        if text.len() > MAX_INPUT {
            return Err(format!("{} bytes, more than {MAX_INPUT}", text.len()));
        }
        let input: G::Input = serde_json::from_str(text).map_err(|e| format!("{e}"))?;
        if self.overflowed.is_some() {
            return Err("the session overflowed: it steps no more".to_owned());
        }
        self.run.input(player, input)
    }

    /// A player joins as `name` (landing in the next frame): its number, or the number it
    /// would have had and why it was refused.
    pub fn join(&mut self, name: &str) -> Result<Result<Player, (Player, String)>, LogError> {
        let verdict = if name.len() > MAX_PLAYER_NAME || name.is_empty() {
            // Refused before the game sees it; the number is still used, as a refusal's is.
            let p = self.run.join_refused();
            Err((p, format!("a name of 1 to {MAX_PLAYER_NAME} bytes")))
        } else if self.overflowed.is_some() {
            let p = self.run.join_refused();
            Err((p, "the session overflowed: it steps no more".to_owned()))
        } else {
            self.run.join(name)
        };
        let player = match &verdict {
            Ok(p) | Err((p, _)) => *p,
        };
        let record = GameInput {
            frame: self.next,
            player: player.0,
            join: Some(name.to_owned()),
            leave: false,
            input: None,
        };
        let why = verdict.as_ref().map(|_| ()).map_err(|(_, w)| w.clone());
        self.keep(record, "join", &why)?;
        Ok(verdict)
    }

    /// `player` leaves (landing in the next frame).
    pub fn leave(&mut self, player: Player) -> Result<Result<(), String>, LogError> {
        let verdict = self.run.leave(player);
        let record = GameInput {
            frame: self.next,
            player: player.0,
            join: None,
            leave: true,
            input: None,
        };
        self.keep(record, "leave", &verdict)?;
        Ok(verdict)
    }

    /// Keeps a command's record for the next frame, with its refusal's `/events` line.
    fn keep(
        &mut self,
        record: GameInput,
        what: &str,
        verdict: &Result<(), String>,
    ) -> Result<(), LogError> {
        if self.input.is_none() {
            return Ok(());
        }
        let t = self.next.saturating_mul(self.recorder.dt_ns());
        let line = match (verdict, self.events) {
            (Err(why), Some(_)) => Some(Log {
                timestamp: Some(timestamp(t)),
                level: Level::Warning as i32,
                message: format!("{what} refused: {why}"),
                name: what.to_owned(),
                file: String::new(),
                line: 0,
            }),
            _ => None,
        };
        let kept = if self.run.game().has_players() {
            Unwritten::Game(serde_json::to_vec(&record)?)
        } else {
            Unwritten::Scenario(Input {
                frame: record.frame,
                text: record.input.unwrap_or_default(),
            })
        };
        self.unwritten.push((kept, line));
        Ok(())
    }

    /// Runs one frame and records it with its commands and the game's state. A step that
    /// overflows is not recorded, nor are its commands, and every later call fails the
    /// same way: the log ends with the last good frame.
    pub fn step(&mut self) -> Result<FrameOutput, StepError> {
        if let Some((frame, what)) = &self.overflowed {
            return Err(StepError::Overflow {
                frame: *frame,
                what: what.clone(),
            });
        }
        let out = match self.run.step() {
            Ok(out) => out,
            Err(Overflowed { frame, bad }) => {
                let what = describe(self.run.sim(), &bad);
                self.unwritten.clear();
                self.overflowed = Some((frame, what.clone()));
                return Err(StepError::Overflow { frame, what });
            }
        };
        let t = out.frame.saturating_mul(self.recorder.dt_ns());
        for (kept, line) in std::mem::take(&mut self.unwritten) {
            if let Some(ch) = self.input {
                let sink = self.recorder.sink_mut();
                match kept {
                    Unwritten::Scenario(message) => sink.write(ch, t, message)?,
                    Unwritten::Game(json) => sink.write_encoded(ch, t, json)?,
                }
            }
            if let (Some(line), Some(ch)) = (line, self.events) {
                self.recorder.sink_mut().write(ch, t, line)?;
            }
        }
        self.recorder.record(self.run.sim(), &out)?;
        if let (Some(ch), Some(state)) = (self.game, self.run.game().state()) {
            let json = serde_json::to_vec(state).map_err(LogError::from)?;
            self.recorder.sink_mut().write_encoded(ch, t, json)?;
        }
        self.next = out.frame + 1;
        Ok(out)
    }

    /// The frame that overflowed and what did, if one did.
    pub fn overflowed(&self) -> Option<(u64, &str)> {
        self.overflowed.as_ref().map(|(f, w)| (*f, w.as_str()))
    }

    /// Sends live viewers the whole current state: both scenes and the camera's frame (after
    /// a reset or a seek). Never recorded.
    pub fn refresh_live(&mut self) -> Result<(), LogError> {
        let frame = self.next.saturating_sub(1);
        self.recorder.refresh_live(self.run.sim(), frame)
    }

    /// Sends live viewers the last frame's `/scene` if it was not drawn
    /// ([`Recorder::draw_moving`]). Never recorded.
    pub fn show_moving_live(&mut self) -> Result<(), LogError> {
        let frame = self.next.saturating_sub(1);
        self.recorder.show_moving_live(self.run.sim(), frame)
    }

    /// Sends live clients an `/events` line at the last frame stepped (the answer to a
    /// click): never recorded, so a replay never needs it (see [`MessageSink::write_live`]).
    pub fn event_live(&mut self, line: crate::events::EventLine) -> Result<(), LogError> {
        let Some(ch) = self.events else {
            return Ok(());
        };
        let t = self
            .next
            .saturating_sub(1)
            .saturating_mul(self.recorder.dt_ns());
        let message = Log {
            timestamp: Some(timestamp(t)),
            level: line.level as i32,
            message: line.message,
            name: line.kind.to_owned(),
            file: String::new(),
            line: 0,
        };
        self.recorder.sink_mut().write_live(ch, t, message)
    }

    /// Where the layout's camera looks now: the `view` frame's origin in `world`.
    pub fn view_at(&self) -> ricochet_geom::Vec2 {
        self.recorder.view_at(self.run.sim())
    }

    /// The simulation.
    pub fn sim(&self) -> &Simulation {
        self.run.sim()
    }

    /// The game run (its players, the game's own state).
    pub fn run(&self) -> &GameLoop<G> {
        &self.run
    }

    /// The recorder (to ask for every transform again, say).
    pub fn recorder(&mut self) -> &mut Recorder<S> {
        &mut self.recorder
    }

    /// A frame's length, ns (the log's clock).
    pub fn dt_ns(&self) -> u64 {
        self.recorder.dt_ns()
    }

    /// The frame the next step makes.
    pub fn next_frame(&self) -> u64 {
        self.next
    }

    /// The sink, back.
    pub fn into_sink(self) -> S {
        self.recorder.into_sink()
    }

    /// The sink, the simulation and the game, back.
    pub fn into_parts(self) -> (S, Simulation, G) {
        let (sim, game) = self.run.into_parts();
        (self.recorder.into_sink(), sim, game)
    }
}
