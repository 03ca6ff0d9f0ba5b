//! Rollback netcode with `ggrs` 0.13: a `SyncTestSession` rolls the simulation back every
//! frame and steps it again, and compares the checksums of both runs.
//!
//! The scene is `scenarios/asteroids.toml` with a second ship: the scenario is loaded, its
//! script (one pilot's timed inputs) is dropped, and a copy of its ship, `ship2`, is added,
//! so two players fly. Their inputs are scripted (a pure function of the frame, as if two
//! peers sent them) and reach the simulation through ggrs, one byte per player.
//!
//! What ggrs asks for, and what answers it:
//! - `SaveGameState`: [`Simulation::snapshot`] as bytes ([`Snapshot::to_bytes`]) and
//!   [`Simulation::checksum`] as the frame's checksum;
//! - `LoadGameState`: [`Snapshot::from_bytes`] and [`Simulation::restore`];
//! - `AdvanceFrame`: the two players' inputs sent with [`Simulation::apply`], then one
//!   [`Simulation::step`].
//!
//! With a check distance of 7, every frame from frame 8 on loads the state of 7 frames
//! back and steps those frames again; a resimulated checksum that differs from the first
//! one is a `GgrsError::MismatchedChecksum`.
//!
//! ```console
//! $ cargo run -p ricochet-sim --example rollback
//! $ cargo run -p ricochet-sim --example rollback -- --break
//! ```
//!
//! The first runs 600 frames and exits 0 if ggrs found no desync. The second breaks
//! determinism on purpose (each loaded state gets one velocity component nudged by one
//! ulp, as a restore that lost a bit would) and exits 0 only if ggrs caught it, naming the
//! frame: so CI runs both.

use std::process::ExitCode;

use ggrs::{Config, GgrsError, GgrsRequest, PredictRepeatLast, SessionBuilder};
use ricochet_sim::load_scenario;
use ricochet_sim::prelude::*;

/// Frames the session advances.
const FRAMES: u32 = 600;
/// How many frames back each rollback goes.
const CHECK_DISTANCE: usize = 7;

/// One player's input byte.
const THRUST: u8 = 1;
const LEFT: u8 = 2;
const RIGHT: u8 = 4;
const FIRE: u8 = 8;

/// The session's types: an input byte per player, the snapshot bytes as the saved state.
struct Rollback;

impl Config for Rollback {
    type Input = u8;
    type InputPredictor = PredictRepeatLast;
    type State = Vec<u8>;
    type Address = String;
}

/// What the two players press at `frame`: each turns its own way, fires every 15 (or 20)
/// frames and thrusts for a while, so ships move, bullets fly and rocks split.
fn scripted_input(player: usize, frame: i32) -> u8 {
    let (turn, fire_every, thrust) = if player == 0 {
        (LEFT, 15, 100..130)
    } else {
        (RIGHT, 20, 300..320)
    };
    let mut input = if frame % 90 < 60 { turn } else { 0 };
    if frame % fire_every == 0 {
        input |= FIRE;
    }
    if thrust.contains(&frame) {
        input |= THRUST;
    }
    input
}

/// The asteroids scenario, without its script, with a second ship.
fn two_ship_asteroids() -> Result<Simulation, Box<dyn std::error::Error>> {
    let text = include_str!("../../../scenarios/asteroids.toml");
    let mut scenario = load_scenario(text, "scenarios/asteroids.toml")?;
    scenario.script.clear();
    let ship = scenario
        .bodies
        .iter()
        .find(|b| b.name == "ship")
        .ok_or("scenarios/asteroids.toml has no body named ship")?;
    let second = BodyDef {
        name: "ship2".into(),
        position: Vec2::new(-12.0, 4.0),
        angle: std::f64::consts::PI,
        ..ship.clone()
    };
    scenario.bodies.push(second);
    Ok(Simulation::new(&scenario))
}

/// Counts what the session asked for.
#[derive(Default)]
struct Counts {
    saves: u32,
    loads: u32,
    steps: u32,
}

fn run(broken: bool) -> Result<ExitCode, Box<dyn std::error::Error>> {
    let mut sim = two_ship_asteroids()?;
    let ships = [
        sim.entity_named("ship").ok_or("no ship")?,
        sim.entity_named("ship2").ok_or("no ship2")?,
    ];
    let mut session = SessionBuilder::<Rollback>::new()
        .with_num_players(2)?
        .with_check_distance(CHECK_DISTANCE)
        .start_synctest_session()?;
    let mut counts = Counts::default();
    for _ in 0..FRAMES {
        let frame = session.current_frame();
        for player in 0..2 {
            session.add_local_input(player, scripted_input(player, frame))?;
        }
        let requests = match session.advance_frame() {
            Ok(requests) => requests,
            Err(GgrsError::MismatchedChecksum {
                current_frame,
                mismatched_frames,
            }) => {
                let what = format!(
                    "ggrs MismatchedChecksum at frame {current_frame} (mismatched frames {mismatched_frames:?})"
                );
                if broken {
                    println!("rollback --break: desync caught: {what}");
                    return Ok(ExitCode::SUCCESS);
                }
                eprintln!("rollback: desync: {what}");
                return Ok(ExitCode::FAILURE);
            }
            Err(e) => return Err(e.into()),
        };
        for request in requests {
            match request {
                GgrsRequest::SaveGameState { cell, frame } => {
                    // ggrs's frame and the simulation's count alike: the frame the next
                    // step runs.
                    if sim.frame() != u64::try_from(frame)? {
                        return Err(
                            format!("asked to save frame {frame} at {}", sim.frame()).into()
                        );
                    }
                    let bytes = sim.snapshot().to_bytes();
                    cell.save(frame, Some(bytes), Some(u128::from(sim.checksum())));
                    counts.saves += 1;
                }
                GgrsRequest::LoadGameState { cell, frame } => {
                    let bytes = cell.load().ok_or("ggrs had no state to load")?;
                    sim.restore(&Snapshot::from_bytes(&bytes)?)?;
                    if sim.frame() != u64::try_from(frame)? {
                        return Err(format!("loaded frame {} for {frame}", sim.frame()).into());
                    }
                    if broken {
                        nudge_one_velocity(&mut sim, ships)?;
                    }
                    counts.loads += 1;
                }
                GgrsRequest::AdvanceFrame { inputs } => {
                    for (&ship, (input, _status)) in ships.iter().zip(&inputs) {
                        send(&mut sim, ship, *input)?;
                    }
                    sim.step();
                    counts.steps += 1;
                }
            }
        }
    }
    if broken {
        eprintln!("rollback --break: the nudged restores were NOT caught by ggrs");
        return Ok(ExitCode::FAILURE);
    }
    // "No desync" means something only if frames were rolled back and stepped again.
    if counts.loads == 0 || counts.steps <= FRAMES {
        eprintln!("rollback: ggrs never rolled back: nothing was compared");
        return Ok(ExitCode::FAILURE);
    }
    let ships_left = ships.iter().filter(|&&s| sim.contains(s)).count();
    println!(
        "rollback: {FRAMES} frames of 2 players, check distance {CHECK_DISTANCE}: {} steps ({} of them again after a rollback), {} loads, {} saves, no desync; {} bodies and {ships_left} ship(s) at the end",
        counts.steps,
        counts.steps - FRAMES,
        counts.loads,
        counts.saves,
        sim.world().len(),
    );
    Ok(ExitCode::SUCCESS)
}

/// A player's input byte as actions on its ship (none once the ship is destroyed).
fn send(sim: &mut Simulation, ship: Entity, input: u8) -> Result<(), ControlError> {
    if !sim.contains(ship) {
        return Ok(());
    }
    let left = f64::from(u8::from(input & LEFT != 0));
    let right = f64::from(u8::from(input & RIGHT != 0));
    sim.apply(ship, Action::Turn(left - right))?;
    sim.apply(ship, Action::Thrust(input & THRUST != 0))?;
    if input & FIRE != 0 {
        sim.apply(ship, Action::Fire)?;
    }
    Ok(())
}

/// `--break`: the loaded state differs from the saved one by one ulp of one ship's
/// x velocity (state the checksum covers).
fn nudge_one_velocity(sim: &mut Simulation, ships: [Entity; 2]) -> Result<(), ControlError> {
    if let Some(&ship) = ships.iter().find(|&&s| sim.contains(s)) {
        let v = sim.velocity(ship).unwrap_or(Vec2::ZERO);
        sim.set_velocity(ship, Vec2::new(v.x.next_up(), v.y))?;
    }
    Ok(())
}

fn main() -> ExitCode {
    let broken = match std::env::args().nth(1).as_deref() {
        None => false,
        Some("--break") => true,
        Some(other) => {
            eprintln!("rollback: unknown argument {other:?}; the only one is --break");
            return ExitCode::from(2);
        }
    };
    run(broken).unwrap_or_else(|e| {
        eprintln!("rollback: {e}");
        ExitCode::FAILURE
    })
}
