//! A game: the rules a game runs around the physics, and the one frame loop every mode
//! shares (a game's own loop, the recorder, golden checks, the live server, replays).
//!
//! A game implements [`Game`]: its players join and leave, send inputs (the game's own
//! typed input, parsed from JSON by whoever carries it), and its rules run before and after
//! each step, spawning, moving or removing bodies and keeping the score. [`GameLoop`] holds
//! a [`Simulation`] and a game value and is the only place that calls them, in one order:
//!
//! 1. between two frames, joins, leaves and inputs, each handled at once, in the order
//!    they come (they land in the next frame, as [`Simulation::apply`] does);
//! 2. [`Game::before_step`];
//! 3. [`Simulation::step`];
//! 4. [`Game::after_step`], with the frame's output (not run when the step overflowed).
//!
//! The loop numbers players 1, 2, ... in the order they join ([`Player::HOST`], 0, is the
//! game's own code or a client that never joined): with the same commands at the same
//! frames, a run is the same run, which is what a recording replays.
//!
//! What `ricochet run` and `ricochet serve` do with a scenario file is one such game,
//! [`ScenarioGame`]: the scenario's script (run inside the step) and its built-in actions
//! as inputs.

#[cfg(feature = "toml")]
mod scenario;

use std::collections::BTreeMap;

use serde::Serialize;
use serde::de::DeserializeOwned;

use crate::control::NonFinite;
use crate::output::FrameOutput;
use crate::pipeline::Simulation;

#[cfg(feature = "toml")]
pub use scenario::{MAX_INPUT_VALUE, ScenarioGame};

/// A player of a game run: numbered from 1 in the order they joined it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub struct Player(pub u32);

impl Player {
    /// Not a player: the game's own code, or a client that sends inputs without joining (a
    /// Foxglove panel on a scenario's server).
    pub const HOST: Player = Player(0);
}

impl std::fmt::Display for Player {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "player {}", self.0)
    }
}

/// A game's rules. Every method gets the simulation to read and change: what a method does
/// to it lands in the next step, like any input between two steps.
///
/// A game must be deterministic like the simulation: what it does may depend only on its
/// own state, the simulation and the calls it gets (no clock, no unseeded randomness, no
/// `HashMap` iteration), so that a recording replays.
pub trait Game {
    /// A player's input, as the game's clients send it (JSON). Serialize it as it parses:
    /// a recording keeps an input as its JSON text.
    type Input: DeserializeOwned + Serialize;
    /// What the players see of the game (scores, lives, the round's clock): written as JSON
    /// on `/game` in every frame, live and recorded.
    type State: Serialize;

    /// The game's name, recorded in its logs: a replay with another game refuses the log.
    fn name(&self) -> &str;

    /// Whether players join it. A game without players (the scenario's) records its inputs
    /// as `ricochet.Input` on `/input`, as `ricochet serve` always has, and refuses joins.
    fn has_players(&self) -> bool {
        true
    }

    /// `player` joins as `name`: give it a body, or refuse (the room is full, say).
    ///
    /// # Errors
    /// Why the player may not join (sent back to the client, and recorded).
    fn join(&mut self, sim: &mut Simulation, player: Player, name: &str) -> Result<(), String> {
        let _ = (sim, player, name);
        Err("this game has no players".to_owned())
    }

    /// `player` left (or its connection closed): remove its body, say.
    fn leave(&mut self, sim: &mut Simulation, player: Player) {
        let _ = (sim, player);
    }

    /// An input from `player` ([`Player::HOST`] for one from no player).
    ///
    /// # Errors
    /// Why it was refused: it must then change nothing (sent back, and recorded).
    fn input(
        &mut self,
        sim: &mut Simulation,
        player: Player,
        input: Self::Input,
    ) -> Result<(), String>;

    /// Just before each step (a platform's next pose, a coin that respawns).
    fn before_step(&mut self, sim: &mut Simulation) {
        let _ = sim;
    }

    /// Just after each step, with what it produced (a coin picked up, a score).
    fn after_step(&mut self, sim: &mut Simulation, out: &FrameOutput) {
        let _ = (sim, out);
    }

    /// What the players see now, if the game shows anything (`None`: no `/game` channel).
    fn state(&self) -> Option<&Self::State> {
        None
    }

    /// The JSON Schema of [`Game::State`], for Foxglove's panels.
    fn state_schema(&self) -> &str {
        r#"{"type":"object"}"#
    }
}

/// A step that made a value non-finite: nothing after it can be trusted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("frame {frame}: {bad}; the simulation overflowed")]
pub struct Overflowed {
    /// The frame that overflowed.
    pub frame: u64,
    /// The body and value.
    pub bad: NonFinite,
}

/// A game run: its simulation, its rules and its players, stepped one frame at a time.
pub struct GameLoop<G: Game> {
    sim: Simulation,
    game: G,
    players: BTreeMap<Player, String>,
    /// The number the next player to join gets.
    next_player: u32,
}

impl<G: Game> GameLoop<G> {
    /// A run of `game` on `sim` (a new simulation, or one restored from a snapshot).
    pub fn new(sim: Simulation, game: G) -> GameLoop<G> {
        GameLoop {
            sim,
            game,
            players: BTreeMap::new(),
            next_player: 1,
        }
    }

    /// A player joins as `name`: it gets the next number whether the game accepts it or
    /// not (so that the numbers depend only on the order of joins).
    ///
    /// # Errors
    /// The number it would have had, and why the game refused it.
    pub fn join(&mut self, name: &str) -> Result<Player, (Player, String)> {
        let player = Player(self.next_player);
        self.next_player = self.next_player.saturating_add(1);
        if !self.game.has_players() {
            return Err((player, "this game has no players".to_owned()));
        }
        match self.game.join(&mut self.sim, player, name) {
            Ok(()) => {
                self.players.insert(player, name.to_owned());
                Ok(player)
            }
            Err(why) => Err((player, why)),
        }
    }

    /// Uses the next player's number for a join refused before the game saw it (a bad
    /// name, say): the numbers depend only on the order of joins.
    pub fn join_refused(&mut self) -> Player {
        let player = Player(self.next_player);
        self.next_player = self.next_player.saturating_add(1);
        player
    }

    /// `player` leaves.
    ///
    /// # Errors
    /// It is not in the game.
    pub fn leave(&mut self, player: Player) -> Result<(), String> {
        if self.players.remove(&player).is_none() {
            return Err(format!("{player} is not in the game"));
        }
        self.game.leave(&mut self.sim, player);
        Ok(())
    }

    /// An input from `player` (a joined one, or [`Player::HOST`]).
    ///
    /// # Errors
    /// The player is not in the game, or the game refused the input.
    pub fn input(&mut self, player: Player, input: G::Input) -> Result<(), String> {
        if player != Player::HOST && !self.players.contains_key(&player) {
            return Err(format!("{player} is not in the game"));
        }
        self.game.input(&mut self.sim, player, input)
    }

    /// Runs one frame: the game's rules before, the step, the game's rules after.
    ///
    /// # Errors
    /// The step made a value non-finite; the game's `after_step` did not run.
    pub fn step(&mut self) -> Result<FrameOutput, Overflowed> {
        self.game.before_step(&mut self.sim);
        let out = self.sim.step();
        if let Some(bad) = self.sim.first_non_finite_after(&out) {
            return Err(Overflowed {
                frame: out.frame,
                bad,
            });
        }
        self.game.after_step(&mut self.sim, &out);
        Ok(out)
    }

    /// The players in the game, by number, with their names.
    pub fn players(&self) -> impl Iterator<Item = (Player, &str)> {
        self.players.iter().map(|(p, n)| (*p, n.as_str()))
    }

    /// The simulation (to query it, or read a body).
    pub fn sim(&self) -> &Simulation {
        &self.sim
    }

    /// The simulation, to change between steps (what a game's own loop may do; a recorded
    /// run changes it only through the game's methods, which a replay calls again).
    pub fn sim_mut(&mut self) -> &mut Simulation {
        &mut self.sim
    }

    /// The game.
    pub fn game(&self) -> &G {
        &self.game
    }

    /// The frame the next step runs.
    pub fn frame(&self) -> u64 {
        self.sim.frame()
    }

    /// The simulation and the game, back.
    pub fn into_parts(self) -> (Simulation, G) {
        (self.sim, self.game)
    }
}
