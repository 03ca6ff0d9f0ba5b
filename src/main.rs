//! `ricochet`: the command line of the Ricochet 2D game-physics simulation server.
//!
//! **Owns:** argument parsing, reading files and stdin, printing results, and exit codes
//! (0 success, 1 the run failed, 2 bad input). **Never:** holds physics or geometry logic of
//! its own: every answer comes from the library crates.

mod collide;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Ricochet: a headless, deterministic 2D game-physics simulation server.
///
/// Write a scenario (a scene plus a script of inputs), run it, replay every frame in Foxglove,
/// and keep golden logs so any change in your game's physics fails a test.
#[derive(Parser, Debug)]
#[command(name = "ricochet", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Collide shape pairs and print one JSON line per pair: "why did these two collide?"
    ///
    /// Reads the shared collision-case format: a {"cases": [...]} document, or JSON lines of
    /// {"id": .., "a": BODY, "b": BODY}, where BODY is
    /// {"shape": SHAPE, "position": [x, y], "angle": radians} and SHAPE is one of
    /// circle {radius}, aabb {half_extents}, obb {half_extents}, capsule {a, b, radius},
    /// polygon {vertices} (convex, counter-clockwise) or compound {parts}.
    ///
    /// Prints {"id", "overlap", "depth", "normal", "point"} per pair. depth > 0 is the
    /// penetration; depth <= 0 is minus the distance. The normal points from a to b: moving
    /// b by depth * normal separates the pair. Bad input is reported by case id and field,
    /// with exit code 2, and nothing is printed to stdout.
    ///
    /// Example: ricochet collide tests/data/collision-cases.json | head -3
    Collide {
        /// The case file, or `-` for standard input.
        file: PathBuf,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Collide { file } => collide::run(&file),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
    }
}
