//! `ricochet-portable [--threads N] [--logs DIR] [--no-scenes] SCENARIO.toml...`: steps each scenario file
//! (up to [`MAX_FILE_FRAMES`] frames), then the built-in scenes, printing the gate's text
//! (see the library docs) on stdout. `scripts/determinism-gate.sh` runs it natively, under
//! qemu-aarch64 and under Node's WASI and compares the outputs.
//!
//! `--logs DIR` (feature `logs`) also writes each scenario file's log to `DIR/NAME.mcap`
//! exactly as `ricochet test` records it, to compare with `recordings/` byte for byte.
//!
//! `--threads N` steps on N threads where the build has `ricochet-sim`'s `parallel` feature
//! (natively; the default is 1); the output must not change.
//!
//! Exit codes: 0, or 2 with a message for a file that can't be read or loaded.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use ricochet_portable::{MAX_FILE_FRAMES, builtin_scenes, run};
use ricochet_sim::load_scenario_and_map;

fn main() -> ExitCode {
    match main_inner() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("ricochet-portable: {e}");
            ExitCode::from(2)
        }
    }
}

fn main_inner() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let (mut logs, mut scenes, mut files, mut threads) = (None, true, Vec::new(), 1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--logs" => {
                logs = Some(PathBuf::from(
                    args.next().ok_or("--logs needs a directory")?,
                ))
            }
            "--no-scenes" => scenes = false,
            "--threads" => {
                let n = args.next().ok_or("--threads needs a count")?;
                threads = n
                    .parse()
                    .map_err(|e| format!("--threads {n:?}: not a count: {e}"))?;
            }
            _ if arg.starts_with("--") => {
                return Err(format!(
                    "unknown option {arg:?}; usage: [--threads N] [--logs DIR] [--no-scenes] SCENARIO.toml..."
                ));
            }
            _ => files.push(PathBuf::from(arg)),
        }
    }
    let stdout = std::io::stdout();
    let mut text = String::new();
    for path in &files {
        let source =
            std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let (mut scenario, tiled) = load_scenario_and_map(&source, &path.display().to_string())
            .map_err(|e| e.to_string())?;
        if let Some(def) = tiled {
            ricochet_tiled::add_map(&mut scenario, &def, path).map_err(|e| e.to_string())?;
        }
        let name = path.file_stem().map_or_else(
            || path.display().to_string(),
            |s| s.to_string_lossy().into_owned(),
        );
        let frames = scenario.frames.min(MAX_FILE_FRAMES);
        text.clear();
        match &logs {
            Some(dir) => record(dir, &name, &scenario, (frames, threads), &mut text)?,
            None => run(&name, &scenario, (frames, threads), &mut text, |_, _| {}),
        }
        stdout
            .lock()
            .write_all(text.as_bytes())
            .map_err(|e| format!("stdout: {e}"))?;
    }
    if scenes {
        for (name, scenario) in builtin_scenes() {
            text.clear();
            run(
                &name,
                &scenario,
                (scenario.frames, threads),
                &mut text,
                |_, _| {},
            );
            stdout
                .lock()
                .write_all(text.as_bytes())
                .map_err(|e| format!("stdout: {e}"))?;
        }
    }
    Ok(())
}

/// Runs `scenario` as [`run`] does, recording every frame to `DIR/NAME.mcap` as `ricochet
/// test` does (default channels, frame 0 the initial state).
#[cfg(feature = "logs")]
fn record(
    dir: &Path,
    name: &str,
    scenario: &ricochet_sim::Scenario,
    frames: (u64, usize),
    text: &mut String,
) -> Result<(), String> {
    use ricochet_record::{Channels, Recorder};
    let path = dir.join(format!("{name}.mcap"));
    let mut log = Recorder::create(&path, scenario.world.dt, Channels::default())
        .map_err(|e| format!("{}: {e}", path.display()))?;
    let mut failed = None;
    run(name, scenario, frames, text, |sim, out| {
        if failed.is_none() {
            failed = log.record(sim, out).err();
        }
    });
    if let Some(e) = failed {
        return Err(format!("{}: {e}", path.display()));
    }
    log.finish().map_err(|e| format!("{}: {e}", path.display()))
}

/// Without the `logs` feature there is no recorder: `--logs` is refused by name.
#[cfg(not(feature = "logs"))]
fn record(
    _dir: &Path,
    _name: &str,
    _scenario: &ricochet_sim::Scenario,
    _frames: (u64, usize),
    _text: &mut String,
) -> Result<(), String> {
    Err("--logs needs the `logs` feature (cargo build --features logs)".into())
}
