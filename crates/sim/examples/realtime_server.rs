//! The core of a game server around the library, what `ricochet serve` does without the CLI:
//! a fixed-timestep loop ("Fix Your Timestep": frame `n` starts at `n * dt` after the start,
//! a late frame is not skipped) that takes inputs from other threads (here, a pretend
//! network thread) and applies them at the next frame boundary, in the order they came. It
//! records each input with its frame, and replays them into a second simulation: the same
//! inputs at the same frames give the same state, bit for bit (`World::digest`).
//!
//! Run it with `cargo run -p ricochet-sim --example realtime_server`.

use std::sync::mpsc;
use std::time::{Duration, Instant};

use ricochet_sim::{Action, BodyDef, Controller, Entity, Shape, Simulation, WorldDef};

/// A small scene: a ship that a client steers.
fn scene() -> Result<(Simulation, Entity), Box<dyn std::error::Error>> {
    let mut sim = Simulation::from_def(WorldDef::default())?;
    let ship = sim.spawn(&BodyDef {
        name: "ship".into(),
        shape: Shape::circle(1.0)?,
        controller: Some(Controller::Ship {
            thrust: 20.0,
            turn_rate: 3.0,
            bullet: String::new(),
            bullet_speed: 0.0,
            muzzle: 0.0,
        }),
        ..BodyDef::default()
    });
    Ok((sim, ship))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let (mut sim, ship) = scene()?;
    // A pretend client: sends inputs whenever it likes, from its own thread.
    let (inputs, arrivals) = mpsc::channel::<Action>();
    let client = std::thread::spawn(move || {
        for action in [
            Action::Thrust(true),
            Action::Turn(0.5),
            Action::Thrust(false),
        ] {
            std::thread::sleep(Duration::from_millis(40));
            let _ = inputs.send(action);
        }
    });
    // 120 frames at 1/60 s, played 4 times faster than real time.
    let dt = Duration::from_secs_f64(1.0 / 60.0 / 4.0);
    let start = Instant::now();
    let mut record: Vec<(u64, Action)> = Vec::new();
    for frame in 0..120u32 {
        if let Some(wait) = (start + dt * frame).checked_duration_since(Instant::now()) {
            std::thread::sleep(wait);
        }
        // Frame boundary: every input that came since, in arrival order.
        for action in arrivals.try_iter() {
            sim.apply(ship, action.clone())?;
            record.push((u64::from(frame), action));
        }
        sim.step();
    }
    client.join().map_err(|_| "the client thread panicked")?;
    let live = sim.world().digest();
    // The replay: the recorded inputs at their frames, no clock, no threads.
    let (mut again, ship) = scene()?;
    let mut pending = record.iter().peekable();
    for frame in 0..120u64 {
        while let Some((_, action)) = pending.next_if(|(f, _)| *f == frame) {
            again.apply(ship, action.clone())?;
        }
        again.step();
    }
    let replayed = again.world().digest();
    println!(
        "{} inputs at frames {:?}; live state {live:016x}, replayed {replayed:016x}",
        record.len(),
        record.iter().map(|(f, _)| *f).collect::<Vec<_>>()
    );
    if live != replayed {
        return Err("the replay differs from the live run".into());
    }
    Ok(())
}
