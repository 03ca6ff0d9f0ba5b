//! A game that steps its own simulation, built in code, and records it as the log
//! `ricochet run` writes: a ball thrown under gravity, kicked at frame 60. Then it reads the log back and checks
//! every frame's ball against the integrator's documented arithmetic (`v += g dt; x += v dt`,
//! IEEE f64; a script's velocity is set at the start of its frame, before the step), so the log is shown to hold the game's frames, bit for bit.
//!
//! The same level as a scenario file, `examples/shared/thrown_ball.toml`, run by `ricochet
//! run`, gives the same bytes (`.ci/run` compares them).
//!
//! `--golden PATH` compares the run with a golden log instead (`RICOCHET_BLESS=1` records it):
//! what a game's own `cargo test` does with `ricochet_record::golden::check`.
//!
//! Run it with `cargo run -p ricochet-record --example record_game -- --out ball.mcap`, then
//! open ball.mcap in Foxglove, or `ricochet dump ball.mcap --topic /bodies --frames 0..3`.

use std::path::PathBuf;

use ricochet_record::{Channels, Recorder, golden};
use ricochet_sim::{Simulation, Vec2};

// The level, shared with the crate's golden test (tests/golden.rs).
#[path = "shared/thrown_ball.rs"]
mod thrown_ball;
use thrown_ball::{FRAMES, GRAVITY, KICK, KICK_FRAME, THROW, level};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let (mut out, mut golden_path) = (PathBuf::from("record_game.mcap"), None);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--out" => out = args.next().ok_or("--out needs a path")?.into(),
            "--golden" => {
                golden_path = Some(PathBuf::from(args.next().ok_or("--golden needs a path")?))
            }
            other => {
                return Err(
                    format!("unknown argument {other:?}; use --out PATH or --golden PATH").into(),
                );
            }
        }
    }
    let scenario = level()?;
    let mut sim = Simulation::new(&scenario);
    if let Some(path) = golden_path {
        golden::check(&path, &mut sim, FRAMES)?;
        let blessed = std::env::var_os(golden::BLESS_ENV).is_some_and(|v| v == "1");
        let verdict = if blessed {
            "recorded (blessed)"
        } else {
            "the run matches it"
        };
        println!("{}: {verdict}", path.display());
        return Ok(());
    }

    // The game loop: step, record. Frame 0 is the initial state.
    let mut log = Recorder::create(&out, scenario.world.dt, Channels::default())?;
    for _ in 0..=FRAMES {
        let frame = sim.step();
        log.record(&sim, &frame)?;
    }
    log.finish()?;

    // Read it back: the ball's state at every frame, rebuilt from /bodies.
    let messages = ricochet_log::read_log_file(&out)?;
    let mut states = ricochet_log::BodyStates::default();
    let frames: Vec<serde_json::Value> = messages
        .iter()
        .filter(|m| m.topic == "/bodies")
        .map(|m| states.apply(&m.data))
        .collect();
    if frames.len() as u64 != FRAMES + 1 {
        return Err(format!("{} /bodies messages, want {}", frames.len(), FRAMES + 1).into());
    }
    // The documented integrator, semi-implicit Euler, computed here on its own.
    let dt = scenario.world.dt;
    let (mut p, mut v) = (Vec2::new(0.0, 0.0), THROW);
    for (n, bodies) in frames.iter().enumerate() {
        if n as u64 == KICK_FRAME {
            v = KICK;
        }
        if n > 0 {
            v = Vec2::new(v.x, v.y + GRAVITY * dt);
            p = Vec2::new(p.x + v.x * dt, p.y + v.y * dt);
        }
        let ball = bodies["bodies"]
            .as_array()
            .and_then(|b| b.iter().find(|b| b["name"] == "ball"))
            .ok_or_else(|| format!("frame {n}: no ball in /bodies"))?;
        let got = |field: &str, i: usize| ball[field][i].as_f64().unwrap_or(f64::NAN).to_bits();
        let want = [p.x, p.y, v.x, v.y].map(f64::to_bits);
        let have = [
            got("position", 0),
            got("position", 1),
            got("velocity", 0),
            got("velocity", 1),
        ];
        if have != want {
            return Err(format!(
                "frame {n}: the log's ball {ball} is not the integrator's {p:?} {v:?}"
            )
            .into());
        }
    }
    println!(
        "{}: {} frames recorded; the ball at every frame is the integrator's, bit for bit (y = {:.3} at frame {FRAMES})",
        out.display(),
        FRAMES + 1,
        p.y
    );
    Ok(())
}
