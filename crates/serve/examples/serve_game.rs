//! A game server that serves its own level, built in code, live to Foxglove (or Lichtblick)
//! over WebSocket, with the players' inputs coming back: what `ricochet serve` does, as a
//! library call. A client publishes JSON inputs on `/input` (`{"action": "thrust", "body":
//! "ship", "on": true}`), applied at the next frame boundary and recorded with `--record`.
//!
//! Run it with `cargo run -p ricochet-serve --example serve_game -- --frames 1200`, then in
//! Foxglove: Open connection, Foxglove WebSocket, ws://localhost:8765, and import the layout
//! foxglove/ricochet-layout.json. Options: `--bind IP:PORT` (127.0.0.1:8765), `--frames N`
//! (stop after frame N; default 600, so CI can run it), `--speed X` (1), `--record OUT.mcap`.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

// The level, shared with the crate's test (tests/serve_game.rs).
#[path = "shared/my_asteroids.rs"]
mod my_asteroids;
use my_asteroids::level;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut options = ricochet_serve::Options {
        frames: Some(600),
        ..Default::default()
    };
    let mut bind = ricochet_serve::DEFAULT_BIND.to_owned();
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let mut value = || args.next().ok_or(format!("{arg} needs a value"));
        match arg.as_str() {
            "--bind" => bind = value()?,
            "--frames" => options.frames = Some(value()?.parse()?),
            "--speed" => options.speed = value()?.parse()?,
            "--record" => options.record = Some(PathBuf::from(value()?)),
            other => return Err(format!("unknown argument {other:?}").into()),
        }
    }
    let listener = ricochet_serve::Listener::bind(bind.parse()?)?;
    eprintln!(
        "serving my-asteroids on ws://{} (Foxglove: Open connection)",
        listener.local_addr()
    );
    // A game would set this from its own shutdown (a signal, a menu); here --frames ends it.
    let stop = AtomicBool::new(false);
    // No scenario file: the level is code (a recording then carries no scenario to replay).
    let served = ricochet_serve::serve(listener, level()?, String::new(), &options, &stop)?;
    println!(
        "served frames 0 to {}, {} dropped for slow clients",
        served.next_frame.saturating_sub(1),
        served.dropped
    );
    Ok(())
}
