//! `ricochet-coin-rush`: a server of Coin Rush rooms, over the Foxglove WebSocket protocol.
//!
//! `cargo run -p ricochet-coin-rush -- --bind 127.0.0.1:8766` serves a room at each
//! `ws://127.0.0.1:8766/rooms/NAME`, created when its first client comes, each its own
//! simulation, game and recording (`--record DIR`). A client joins with the `/join` service
//! (`{"name": "ada"}` → `{"player": 1}`), sends its inputs as JSON on a `/input` channel it
//! advertises, and reads `/game` and `/scene`; `examples/coin-rush/web` is such a client.
//! Ctrl-C or SIGTERM stops it, every room's recording finished.

use std::net::SocketAddr;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::Context;
use clap::Parser;
use ricochet_coin_rush::CoinRush;
use ricochet_serve::{Listener, RoomMaker, RoomOptions, serve_rooms};
use ricochet_sim::Simulation;

/// Serve rooms of Coin Rush, the example game (loopback by default).
#[derive(Parser)]
#[command(version)]
struct Args {
    /// The address to listen on.
    #[arg(long, default_value = "127.0.0.1:8766")]
    bind: SocketAddr,
    /// Record each room into this folder (one log per room).
    #[arg(long, value_name = "DIR")]
    record: Option<PathBuf>,
}

/// Every room is a new arena and game.
struct Rooms;

impl RoomMaker for Rooms {
    type Game = CoinRush;

    fn make(&self, _room: &str) -> Result<(Simulation, CoinRush), String> {
        CoinRush::new().map_err(|e| e.to_string())
    }

    fn input_schema(&self) -> String {
        ricochet_coin_rush::INPUT_SCHEMA.to_owned()
    }
}

/// Set by Ctrl-C or SIGTERM: the rooms stop and finish their recordings.
static STOP: AtomicBool = AtomicBool::new(false);

fn main() -> ExitCode {
    let args = Args::parse();
    match serve(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Usage(e)) => {
            eprintln!("coin-rush: error: {e}");
            ExitCode::from(2)
        }
        Err(Failure::Run(e)) => {
            eprintln!("coin-rush: error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Why the server did not run: what it was given (exit 2), or what happened (exit 1).
enum Failure {
    Usage(anyhow::Error),
    Run(anyhow::Error),
}

fn serve(args: Args) -> Result<(), Failure> {
    if let Some(dir) = &args.record
        && !dir.is_dir()
    {
        return Err(Failure::Usage(anyhow::anyhow!(
            "--record {}: not a folder (make it first)",
            dir.display()
        )));
    }
    // Before the handler: an address already taken or not this machine's is the caller's.
    let listener = Listener::bind(args.bind).map_err(|e| Failure::Usage(e.into()))?;
    ctrlc::set_handler(|| STOP.store(true, Ordering::SeqCst))
        .context("cannot install the Ctrl-C handler")
        .map_err(Failure::Run)?;
    let options = RoomOptions {
        record: args.record,
        ..RoomOptions::default()
    };
    eprintln!(
        "coin-rush: serving rooms on ws://{}/rooms/NAME (Ctrl-C stops)",
        listener.local_addr()
    );
    let served =
        serve_rooms(listener, Rooms, &options, &STOP).map_err(|e| Failure::Run(e.into()))?;
    eprintln!(
        "coin-rush: stopped: {} rooms opened, {} failed, {} frames",
        served.opened, served.failed, served.frames
    );
    Ok(())
}
