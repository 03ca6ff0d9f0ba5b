//! Coin Rush: a small multiplayer platformer on Ricochet, built only on its public API
//! (`ricochet_sim::prelude`), and the example of issue #35's [`Game`].
//!
//! Players join a room and get a runner; they run, jump (onto a moving platform, up to
//! the ledges) and pick up coins, which come back [`COIN_RESPAWN`] frames later. A player
//! may zap another: a ray from its runner, checked against the world as that player saw it
//! (the frame it names), stuns the runner it hits for [`STUN_FRAMES`]. A round lasts
//! [`ROUND_FRAMES`]; the scores start again at 0 with the next.
//!
//! The game is deterministic, as a recording's replay needs: no clock, no randomness, no
//! hash-ordered iteration (players in a `BTreeMap`, coins in a fixed array), and whatever
//! it does depends only on the frame, its own state and the commands it gets.
//!
//! ```
//! use ricochet_coin_rush::{CoinRush, Input};
//! use ricochet_sim::prelude::*;
//!
//! let (sim, game) = CoinRush::new()?;
//! let mut run = GameLoop::new(sim, game);
//! let ada = run.join("ada").map_err(|(_, why)| why)?;
//! run.input(ada, Input { run: Some(1.0), ..Input::default() })?;
//! for _ in 0..60 {
//!     run.step().map_err(|o| format!("{o:?}"))?;
//! }
//! let state = run.game().state().ok_or("no state")?;
//! assert_eq!(state.players[0].name, "ada");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod arena;

use std::collections::BTreeMap;

use ricochet_sim::prelude::*;
use serde::{Deserialize, Serialize};

pub use arena::{ArenaError, COINS, SPAWNS};

/// The game's name, recorded in its logs.
pub const NAME: &str = "coin-rush";
/// Players at most in a room: with 62 tiles, the platform and 5 coins, 76 bodies.
pub const MAX_PLAYERS: usize = 8;
/// Frames a coin stays away once picked up (5 s).
pub const COIN_RESPAWN: u64 = 300;
/// Frames a zapped runner stays stunned, from the frame the zap lands in (1 s).
pub const STUN_FRAMES: u64 = 60;
/// Frames between two zaps of one player (0.5 s); a zap sooner does nothing.
pub const ZAP_COOLDOWN: u64 = 30;
/// How far a zap reaches, units.
pub const ZAP_RANGE: f64 = 12.0;
/// How old a frame a zap may name: the last this many frames (about half a second, a
/// client's round trip and its interpolation delay).
pub const ZAP_WINDOW: u64 = 32;
/// Frames in a round (60 s).
pub const ROUND_FRAMES: u64 = 3600;

/// A player's input, as its client sends it (JSON): `{"run": 1}`, `{"jump": true}`,
/// `{"zap": {"dir": [-1, 0], "seen": 118}}`. Every field may be left out: a run input
/// holds until the next one.
#[derive(Debug, Clone, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Input {
    /// Running, -1 (left) to 1 (right); held until changed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub run: Option<f64>,
    /// Jump (if standing on something).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub jump: bool,
    /// Zap along a direction.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub zap: Option<Zap>,
}

/// The JSON Schema of [`Input`] (what a client publishes on `/input`).
pub const INPUT_SCHEMA: &str = r#"{"type":"object","additionalProperties":false,"properties":{"run":{"type":"number","minimum":-1,"maximum":1},"jump":{"type":"boolean"},"zap":{"type":"object","additionalProperties":false,"required":["dir","seen"],"properties":{"dir":{"type":"array","items":{"type":"number"},"minItems":2,"maxItems":2},"seen":{"type":"integer","minimum":0}}}}}"#;

/// A zap: a ray from the player's runner along `dir`, against the world of frame `seen`.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Zap {
    /// The direction (any length but zero).
    pub dir: [f64; 2],
    /// The frame the player saw when it zapped: one of the last [`ZAP_WINDOW`] stepped.
    pub seen: u64,
}

/// What the players see, on `/game` every frame.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct State {
    /// The frame just stepped.
    pub frame: u64,
    /// The round, from 1.
    pub round: u64,
    /// Frames left in the round.
    pub frames_left: u64,
    /// The players, by number.
    pub players: Vec<PlayerState>,
    /// Whether each coin (in [`COINS`] order) is there to pick up.
    pub coins: Vec<bool>,
}

/// One player, as the others see it.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct PlayerState {
    /// Its number.
    pub player: u32,
    /// Its name.
    pub name: String,
    /// Its runner's body id (`INDEX:GENERATION`, as `/scene` names it `body/INDEX:GENERATION`).
    pub body: String,
    /// Coins picked up this round.
    pub score: u32,
    /// Whether it was stunned in this frame.
    pub stunned: bool,
}

/// The JSON Schema of [`State`].
pub const STATE_SCHEMA: &str = r#"{"type":"object","properties":{"frame":{"type":"integer"},"round":{"type":"integer"},"frames_left":{"type":"integer"},"players":{"type":"array","items":{"type":"object","properties":{"player":{"type":"integer"},"name":{"type":"string"},"body":{"type":"string"},"score":{"type":"integer"},"stunned":{"type":"boolean"}}}},"coins":{"type":"array","items":{"type":"boolean"}}}}"#;

/// A player's runner and what the game keeps about it.
struct Runner {
    name: String,
    body: Entity,
    score: u32,
    /// The last run input (what it runs at when a stun ends).
    run: f64,
    /// The first frame it is no longer stunned (0: never was).
    stunned_until: u64,
    /// The first frame it may zap again.
    zap_ready: u64,
}

/// A coin's place: the coin there, or the frame it comes back.
#[derive(Clone, Copy)]
enum Coin {
    There(Entity),
    Back(u64),
}

/// The game: its arena's moving parts, the players and the score.
pub struct CoinRush {
    platform: Entity,
    coins: [Coin; 5],
    runners: BTreeMap<Player, Runner>,
    state: State,
}

impl CoinRush {
    /// A new room: the arena (nothing stepped yet) and the game.
    ///
    /// # Errors
    /// The arena could not be built (never, with its constants).
    pub fn new() -> Result<(Simulation, CoinRush), ArenaError> {
        let arena = arena::build()?;
        let game = CoinRush {
            platform: arena.platform,
            coins: arena.coins.map(Coin::There),
            runners: BTreeMap::new(),
            state: State::default(),
        };
        let mut game = game;
        game.refresh(0);
        Ok((arena.sim, game))
    }

    /// The moving platform.
    #[must_use]
    pub fn platform(&self) -> Entity {
        self.platform
    }

    /// The coin in slot `k` ([`COINS`] order), if it is there.
    #[must_use]
    pub fn coin(&self, k: usize) -> Option<Entity> {
        match self.coins.get(k) {
            Some(Coin::There(e)) => Some(*e),
            _ => None,
        }
    }

    /// `player`'s runner, if it is in the game.
    #[must_use]
    pub fn runner(&self, player: Player) -> Option<Entity> {
        self.runners.get(&player).map(|r| r.body)
    }

    /// The player whose runner is `body`.
    fn owner(&self, body: Entity) -> Option<Player> {
        self.runners
            .iter()
            .find_map(|(p, r)| (r.body == body).then_some(*p))
    }

    /// The state after `frame`.
    fn refresh(&mut self, frame: u64) {
        let s = &mut self.state;
        s.frame = frame;
        s.round = frame / ROUND_FRAMES + 1;
        s.frames_left = ROUND_FRAMES - 1 - frame % ROUND_FRAMES;
        s.players = self
            .runners
            .iter()
            .map(|(p, r)| PlayerState {
                player: p.0,
                name: r.name.clone(),
                body: r.body.to_string(),
                score: r.score,
                stunned: frame < r.stunned_until,
            })
            .collect();
        s.coins = self
            .coins
            .iter()
            .map(|c| matches!(c, Coin::There(_)))
            .collect();
    }

    /// A zap from `player` (checked, not yet done): the runner it stuns, if any.
    fn aim(
        &self,
        sim: &Simulation,
        player: Player,
        shooter: &Runner,
        zap: &Zap,
    ) -> Result<Option<Player>, String> {
        let dir = Vec2::new(zap.dir[0], zap.dir[1]);
        let len = dir.length();
        if !(len.is_finite() && len > 0.0) {
            return Err(format!(
                "zap.dir: a finite direction that is not zero, got [{}, {}]",
                zap.dir[0], zap.dir[1]
            ));
        }
        // The world holds the end of frame `now`: the last one a client can have seen.
        let Some(now) = sim.frame().checked_sub(1) else {
            return Err("zap.seen: no frame has been stepped yet".to_owned());
        };
        let oldest = now.saturating_sub(ZAP_WINDOW - 1);
        if zap.seen > now || zap.seen < oldest {
            return Err(format!(
                "zap.seen: frame {} is not one of the last {ZAP_WINDOW} ({oldest} to {now})",
                zap.seen
            ));
        }
        let frame = sim.frame();
        if frame < shooter.stunned_until || frame < shooter.zap_ready {
            // Stunned, or too soon: a zap that does nothing, not a refusal (a client can't
            // know the exact frame its input lands in).
            return Ok(None);
        }
        let Some(origin) = sim.position(shooter.body) else {
            return Ok(None);
        };
        let filter = QueryFilter::layers(&[arena::RUNNER, arena::GROUND, arena::PLATFORM])
            .exclude(shooter.body);
        let hit = zap_ray(sim, zap.seen, origin, dir / len, &filter)?;
        Ok(hit
            .and_then(|h| self.owner(h.entity))
            .filter(|&p| p != player))
    }
}

/// The ray a zap casts from `origin` along `dir` (unit), up to [`ZAP_RANGE`], against the
/// world as the player saw it at the end of frame `seen` (checked to be in the window).
///
/// # Errors
/// The frame is not kept (with lag compensation: outside the simulation's history).
fn zap_ray(
    sim: &Simulation,
    seen: u64,
    origin: Vec2,
    dir: Vec2,
    filter: &QueryFilter,
) -> Result<Option<RayHit>, String> {
    // Lag compensation: the world `seen` as kept by `keep_history(ZAP_WINDOW)`.
    let then = sim.past(seen).map_err(|e| format!("zap.seen: {e}"))?;
    Ok(then.cast_ray(origin, dir, ZAP_RANGE, filter))
}

impl Game for CoinRush {
    type Input = Input;
    type State = State;

    fn name(&self) -> &str {
        NAME
    }

    fn join(&mut self, sim: &mut Simulation, player: Player, name: &str) -> Result<(), String> {
        if self.runners.len() >= MAX_PLAYERS {
            return Err(format!("the room is full ({MAX_PLAYERS} players)"));
        }
        let n = usize::try_from(player.0.saturating_sub(1)).unwrap_or(0);
        let at = SPAWNS[n % SPAWNS.len()];
        let def = arena::runner(name, at).map_err(|e| e.to_string())?;
        let body = sim.spawn(&def);
        self.runners.insert(
            player,
            Runner {
                name: name.to_owned(),
                body,
                score: 0,
                run: 0.0,
                stunned_until: 0,
                zap_ready: 0,
            },
        );
        self.refresh(self.state.frame);
        Ok(())
    }

    fn leave(&mut self, sim: &mut Simulation, player: Player) {
        if let Some(r) = self.runners.remove(&player) {
            // Gone already only if the game removed it, which it never does.
            let _ = sim.despawn(r.body);
        }
        self.refresh(self.state.frame);
    }

    fn input(&mut self, sim: &mut Simulation, player: Player, input: Input) -> Result<(), String> {
        let Some(shooter) = self.runners.get(&player) else {
            return Err(format!("{player} has no runner"));
        };
        if let Some(run) = input.run
            && !(run.is_finite() && (-1.0..=1.0).contains(&run))
        {
            return Err(format!("run: from -1 to 1, got {run}"));
        }
        // Everything is checked before anything changes: a refused input changes nothing.
        let stun = match &input.zap {
            Some(zap) => self.aim(sim, player, shooter, zap)?,
            None => None,
        };
        let frame = sim.frame();
        let Some(r) = self.runners.get_mut(&player) else {
            return Err(format!("{player} has no runner"));
        };
        let body = r.body;
        let stunned = frame < r.stunned_until;
        if let Some(run) = input.run {
            r.run = run;
            if !stunned {
                sim.apply(body, Action::Move(run))
                    .map_err(|e| e.to_string())?;
            }
        }
        if input.jump && !stunned {
            sim.apply(body, Action::Jump).map_err(|e| e.to_string())?;
        }
        if input.zap.is_some() && !stunned && frame >= r.zap_ready {
            r.zap_ready = frame + ZAP_COOLDOWN;
        }
        if let Some(target) = stun
            && let Some(t) = self.runners.get_mut(&target)
        {
            t.stunned_until = frame + STUN_FRAMES;
            sim.apply(t.body, Action::Move(0.0))
                .map_err(|e| e.to_string())?;
        }
        Ok(())
    }

    fn before_step(&mut self, sim: &mut Simulation) {
        let frame = sim.frame();
        if frame >= 1 {
            // Frame 0 moves nothing: the platform's round trip starts at frame 1.
            let to = Vec2::new(arena::platform_x(frame), arena::PLATFORM_START.y);
            // The platform is never removed: this can't fail.
            let _ = sim.set_target_pose(self.platform, Pose::new(to, 0.0));
        }
        if frame > 0 && frame.is_multiple_of(ROUND_FRAMES) {
            for r in self.runners.values_mut() {
                r.score = 0;
            }
        }
        for (slot, &at) in self.coins.iter_mut().zip(COINS.iter()) {
            if let Coin::Back(when) = *slot
                && when <= frame
                && let Ok(def) = arena::coin(at)
            {
                *slot = Coin::There(sim.spawn(&def));
            }
        }
        for r in self.runners.values() {
            if r.stunned_until == frame && frame > 0 {
                // The stun ends: the runner runs as its player last asked.
                let _ = sim.apply(r.body, Action::Move(r.run));
            }
        }
    }

    fn after_step(&mut self, sim: &mut Simulation, out: &FrameOutput) {
        for event in &out.events {
            let GameEvent::TouchBegin { a, b, .. } = event else {
                continue;
            };
            // A coin and a runner: which is which (a touch names the lower id first).
            let slot = self
                .coins
                .iter()
                .position(|c| matches!(c, Coin::There(e) if e == a || e == b));
            let (Some(slot), Some(player)) = (slot, self.owner(*a).or(self.owner(*b))) else {
                continue;
            };
            if let Coin::There(coin) = self.coins[slot] {
                let _ = sim.despawn(coin);
            }
            self.coins[slot] = Coin::Back(out.frame + COIN_RESPAWN);
            if let Some(r) = self.runners.get_mut(&player) {
                r.score += 1;
            }
        }
        self.refresh(out.frame);
    }

    fn state(&self) -> Option<&State> {
        Some(&self.state)
    }

    fn state_schema(&self) -> &str {
        STATE_SCHEMA
    }
}
