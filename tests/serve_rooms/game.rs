//! The rooms' test game (`serve_rooms.rs`): a ball per player, pushed by
//! `{"push": [vx, vy]}`, and the maker of its rooms, whose room `boom` panics.

use std::collections::BTreeMap;

use ricochet_serve::RoomMaker;
use ricochet_sim::prelude::*;
use ricochet_sim::{Game, Player};

/// A ball per player, pushed by `{"push": [vx, vy]}`.
#[derive(Default)]
pub(super) struct Balls {
    /// The game panics just after this frame's step.
    panic_at: Option<u64>,
    balls: BTreeMap<Player, Entity>,
    pub(super) state: BallsState,
}

#[derive(Default, serde::Serialize)]
pub(super) struct BallsState {
    frame: u64,
    players: u64,
    pub(super) pushes: u64,
}

#[derive(serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Push {
    pub(super) push: [f64; 2],
}

impl Game for Balls {
    type Input = Push;
    type State = BallsState;

    fn name(&self) -> &str {
        "balls"
    }

    fn join(&mut self, sim: &mut Simulation, player: Player, name: &str) -> Result<(), String> {
        if name == "nobody" {
            return Err("nobody may not play".to_owned());
        }
        let ball = sim.spawn(&BodyDef {
            position: Vec2::new(2.0 * f64::from(player.0), 0.0),
            ..BodyDef::default()
        });
        self.balls.insert(player, ball);
        self.state.players += 1;
        Ok(())
    }

    fn leave(&mut self, sim: &mut Simulation, player: Player) {
        if let Some(ball) = self.balls.remove(&player) {
            let _ = sim.despawn(ball);
            self.state.players -= 1;
        }
    }

    fn input(&mut self, sim: &mut Simulation, player: Player, input: Push) -> Result<(), String> {
        let ball = *self.balls.get(&player).ok_or("no ball")?;
        sim.set_velocity(ball, Vec2::new(input.push[0], input.push[1]))
            .map_err(|e| e.to_string())?;
        self.state.pushes += 1;
        Ok(())
    }

    fn after_step(&mut self, _sim: &mut Simulation, out: &FrameOutput) {
        if self.panic_at == Some(out.frame) {
            panic!("the test game panics at frame {}", out.frame);
        }
        self.state.frame = out.frame;
    }

    fn state(&self) -> Option<&BallsState> {
        Some(&self.state)
    }
}

/// Rooms of [`Balls`]; the room named `boom` panics after frame 30.
pub(super) struct Maker;

pub(super) const PANIC_AT: u64 = 30;

pub(super) fn new_game(room: &str) -> (Simulation, Balls) {
    let sim = Simulation::from_def(WorldDef {
        gravity: Vec2::ZERO,
        ..WorldDef::default()
    })
    .unwrap();
    let game = Balls {
        panic_at: (room == "boom").then_some(PANIC_AT),
        ..Balls::default()
    };
    (sim, game)
}

impl RoomMaker for Maker {
    type Game = Balls;

    fn make(&self, room: &str) -> Result<(Simulation, Balls), String> {
        Ok(new_game(room))
    }

    fn input_schema(&self) -> String {
        r#"{"type": "object", "properties": {"push": {"type": "array"}}, "required": ["push"]}"#
            .to_owned()
    }
}
