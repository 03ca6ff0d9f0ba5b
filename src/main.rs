//! `ricochet`: the command line of the Ricochet 2D game-physics simulation server.
//!
//! **Owns:** argument parsing, reading files and stdin, printing results, and exit codes
//! (0 success, 1 the run failed, 2 bad input). Every write to stdout and stderr goes through
//! `out.rs` and is checked: a closed pipe ends a command quietly with its own exit code, any
//! other failed write is exit 1 (2 for `diff`) with a message if stderr still works.
//! **Never:** holds physics or geometry logic of its own: every answer comes from the library
//! crates.

mod accuracy;
mod bench;
mod bench_record;
mod channels;
mod check;
mod cli;
mod collide;
mod diff;
mod dump;
mod events;
mod files;
mod load;
mod out;
mod record;
mod replay;
mod run;
mod serve;
mod session;
mod suite;
mod sweep;
mod validate;

use std::process::ExitCode;

use clap::Parser;

use cli::{Cli, Command};

fn main() -> ExitCode {
    let cli = Cli::parse();
    let command = cli.command.unwrap_or(Command::Run {
        scenario: None,
        output: None,
        frames: None,
        validate: false,
        channels: None,
        threads: None,
        draw_every_frame: false,
    });
    // An error that ends a command is exit code 1 ("the run failed"), except for `diff`, whose
    // 1 means "the logs differ": there it is 2, like an unreadable file.
    let failed = if matches!(command, Command::Diff { .. } | Command::Dump { .. }) {
        2
    } else {
        1
    };
    let result = match command {
        Command::Collide { file } => collide::run(&file),
        Command::Run {
            scenario,
            output,
            frames,
            validate,
            channels,
            threads,
            draw_every_frame,
        } => run::run(
            scenario.as_deref(),
            output,
            frames,
            validate,
            channels.as_deref(),
            threads.map(usize::from),
            draw_every_frame,
        ),
        Command::Serve {
            scenario,
            bind,
            speed,
            frames,
            record,
            record_rooms,
            paused,
        } => serve::run(&serve::Options {
            scenario: scenario.as_deref(),
            bind: &bind,
            speed,
            frames,
            record: record.as_deref(),
            record_rooms: record_rooms.as_deref(),
            paused,
        }),
        Command::Replay { session, output } => replay::run(&session, output),
        Command::Dump { log, topic, frames } => {
            dump::run(&log, topic.as_deref(), frames.as_deref())
        }
        Command::Validate { scenario, frames } => validate::run(&scenario, frames),
        Command::Check { scenario } => check::check(&scenario),
        Command::Test {
            item: Some(item),
            golden,
            out,
            bless,
            ..
        } => suite::run_item(&item, golden.as_deref(), out.as_deref(), bless),
        Command::Test {
            paths,
            golden,
            jobs,
            bless,
            junit,
            shard,
            keep,
            cluster,
            verify,
            fetch_logs,
            ..
        } => suite::run(&suite::Options {
            paths,
            golden,
            jobs: jobs.map(usize::from),
            bless,
            junit,
            shard,
            keep,
            cluster: cluster.map(|scheduler| suite::cluster::Cluster {
                verify,
                fetch_logs,
                ..suite::cluster::Cluster::new(scheduler)
            }),
        }),
        Command::Bench {
            scenes,
            frames,
            csv,
            record: true,
            keep,
            draw_every_frame,
            ..
        } => {
            let _ = csv;
            bench_record::run(&scenes, frames, keep.as_deref(), draw_every_frame)
        }
        Command::Bench {
            scenes,
            frames,
            queries: true,
            ..
        } => bench::run_queries(&scenes, frames),
        Command::Bench {
            scenes,
            frames,
            snapshots: true,
            ..
        } => bench::run_snapshots(&scenes, frames),
        Command::Bench {
            scenes,
            frames,
            broad_phases: true,
            ..
        } => bench::run_broad_phases(&scenes, frames),
        Command::Bench {
            scenes,
            frames,
            csv,
            ..
        } => bench::run(&scenes, frames, csv.as_deref()),
        Command::Sweep(args) => sweep::run(&args),
        Command::Accuracy { csv, svg } => accuracy::run(csv.as_deref(), svg.as_deref()),
        Command::Diff {
            a,
            b,
            tolerance,
            topic,
            json,
        } => diff::run(&a, &b, tolerance, topic.as_deref(), json),
    };
    match result {
        Ok(code) => code,
        // The reader of our output went away (`| head`): nothing more to say.
        Err(e)
            if e.downcast_ref::<out::WriteError>()
                .is_some_and(out::WriteError::is_closed) =>
        {
            ExitCode::SUCCESS
        }
        Err(e) => {
            out::error(&format!("error: {e:#}"));
            ExitCode::from(failed)
        }
    }
}
