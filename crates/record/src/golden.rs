//! Golden-log checks for a game's own `cargo test`: a simulation the game builds in code is
//! stepped and recorded, and the log is compared with one recorded before (the golden).
//!
//! ```no_run
//! # fn level1() -> ricochet_sim::Simulation { unimplemented!() }
//! // In a test: fails with the first divergence, as `ricochet diff` prints it.
//! let mut sim = level1();
//! ricochet_record::golden::check("tests/golden/level1.mcap", &mut sim, 600).unwrap();
//! ```
//!
//! `RICOCHET_BLESS=1 cargo test` records the golden instead (or again, after a change that
//! is meant). The log is written to a temporary file renamed onto the golden when it is
//! complete, so an interrupted bless leaves the old golden whole. A check that fails keeps
//! the new log beside the golden (`level1.new.mcap`) for `ricochet diff` or Foxglove; a
//! check that passes removes it. Before the first bless, when the golden's folder does not
//! exist yet, a check creates no folder: the error says there is no golden yet, and keeps
//! this run's log in a new temporary folder (`$TMPDIR/ricochet-golden-XXXXXX/`) that it names.

use std::path::{Path, PathBuf};

use ricochet_log::LogError;
use ricochet_log::diff::{self, DiffError, Divergence};
use ricochet_sim::{Game, Player, ScenarioGame, Simulation};

use crate::session::{GameSession, StepError};

/// Set to `1`, [`check`] records the golden instead of comparing with it.
pub const BLESS_ENV: &str = "RICOCHET_BLESS";

/// Why a golden check failed. Its `Debug` is its message (what `.unwrap()` and `?` out of a
/// test print): the report's lines as lines, not the fields with `\n` escapes.
#[derive(thiserror::Error)]
pub enum GoldenError {
    /// There is no golden log yet.
    #[error(
        "{}: no golden log yet; run the test with RICOCHET_BLESS=1 to record it (this run's log is {})",
        golden.display(),
        new.display()
    )]
    Missing {
        /// The golden's path.
        golden: PathBuf,
        /// Where this run's log was kept: beside the golden, or, when the golden's folder
        /// does not exist, in a new temporary folder (a check creates no golden folder).
        new: PathBuf,
    },
    /// The run's log differs from the golden.
    #[error(
        "{report}the run differs from its golden log; if the change is meant, re-record it with \
         RICOCHET_BLESS=1 (this run's log is {})",
        new.display()
    )]
    Differs {
        /// The first divergence: frame, topic, body, field and both values (A is the golden).
        first: Box<Divergence>,
        /// The report as `ricochet diff GOLDEN NEW` prints it.
        report: String,
        /// Where this run's log was kept.
        new: PathBuf,
    },
    /// A step made a value non-finite: nothing after it can be trusted.
    #[error("frame {frame}: {what}; the simulation overflowed")]
    Overflow {
        /// The frame that overflowed.
        frame: u64,
        /// Which body and value.
        what: String,
    },
    /// Writing the log failed.
    #[error(transparent)]
    Log(#[from] LogError),
    /// The golden could not be read (cut short, damaged, not a Ricochet log).
    #[error(transparent)]
    Diff(#[from] DiffError),
}

impl std::fmt::Debug for GoldenError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        std::fmt::Display::fmt(self, f)
    }
}

/// Steps `sim` for frame 0 and `frames` more (as `ricochet run --frames N` does: the first
/// step of a new simulation is frame 0, its initial state), records every frame on every
/// channel, and compares the log with the golden at `golden`: `Ok(())` when equal
/// message by message, else the first divergence. With `RICOCHET_BLESS=1` in the
/// environment, writes the golden instead (creating its directory).
pub fn check(
    golden: impl AsRef<Path>,
    sim: &mut Simulation,
    frames: u64,
) -> Result<(), GoldenError> {
    check_or_bless(golden.as_ref(), sim, frames, blessing())
}

/// Whether `RICOCHET_BLESS=1` is set.
fn blessing() -> bool {
    std::env::var_os(BLESS_ENV).is_some_and(|v| v == "1")
}

/// [`check`], with the choice to bless given rather than read from the environment.
pub fn check_or_bless(
    golden: &Path,
    sim: &mut Simulation,
    frames: u64,
    bless: bool,
) -> Result<(), GoldenError> {
    // The session owns the simulation it runs: lend it ours, and take it back.
    let placeholder = Simulation::new(&ricochet_sim::Scenario::default());
    let owned = std::mem::replace(sim, placeholder);
    let mut back = None;
    let verdict = compare(golden, bless, |path| {
        let (sim, ran) = run(path, owned, ScenarioGame, frames, &[], false);
        back = Some(sim);
        ran.map(|_| ())
    });
    if let Some(s) = back {
        *sim = s;
    }
    verdict
}

/// What a golden script sends a game at a frame.
#[derive(Debug, Clone, PartialEq)]
pub enum Command<I> {
    /// A player joins with this name (players are numbered 1, 2, ... in the order they join).
    Join(String),
    /// A player leaves.
    Leave(Player),
    /// A player's input ([`Player::HOST`]: from no player).
    Input(Player, I),
}

/// A golden check of a game run: `game` on `sim`, frame 0 and `frames` more, each frame
/// preceded by the script's commands for it (`(frame, command)`, in the script's order
/// within a frame; the script is sorted by frame first, stably). The log holds what a
/// served room's recording holds (`/input` with every command, `/game`), so a room's
/// recording and a golden agree when they got the same commands. Returns the game at the
/// end (to look at its score), else the first divergence; `RICOCHET_BLESS=1` records the
/// golden instead.
pub fn check_game<G: Game>(
    golden: impl AsRef<Path>,
    sim: Simulation,
    game: G,
    frames: u64,
    script: &[(u64, Command<G::Input>)],
) -> Result<G, GoldenError> {
    check_game_or_bless(golden.as_ref(), sim, game, frames, script, blessing())
}

/// [`check_game`], with the choice to bless given rather than read from the environment.
pub fn check_game_or_bless<G: Game>(
    golden: &Path,
    sim: Simulation,
    game: G,
    frames: u64,
    script: &[(u64, Command<G::Input>)],
    bless: bool,
) -> Result<G, GoldenError> {
    compare(golden, bless, |path| {
        run(path, sim, game, frames, script, true).1
    })
}

/// Records the run with `record` into the right place and compares (or blesses): the shared
/// part of [`check`] and [`check_game`]. `record` is called once.
fn compare<R>(
    golden: &Path,
    bless: bool,
    record: impl FnOnce(&Path) -> Result<R, GoldenError>,
) -> Result<R, GoldenError> {
    if bless {
        if let Some(dir) = golden.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|source| LogError::Create {
                path: dir.to_path_buf(),
                source,
            })?;
        }
        return record(golden);
    }
    let folder = match golden.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    // Only a folder that is not there at all: one that is a file, or can't be looked at, is
    // the writer's located error below, not "no golden yet".
    if matches!(folder.try_exists(), Ok(false)) {
        // No golden folder yet (before the first bless): the run's log can't go beside the
        // golden, and a check does not create the folder, so it goes to a temporary folder
        // that is kept and named by the error.
        let tmp = tempfile::Builder::new()
            .prefix("ricochet-golden-")
            .tempdir()
            .map_err(|source| LogError::Create {
                path: std::env::temp_dir(),
                source,
            })?
            .keep();
        let new = tmp.join(new_name(golden));
        if let Err(e) = record(&new) {
            // No message names the folder then: leave nothing behind.
            let _ = std::fs::remove_dir_all(&tmp);
            return Err(e);
        }
        return Err(GoldenError::Missing {
            golden: golden.to_path_buf(),
            new,
        });
    }
    let new = new_path(golden);
    let ran = record(&new)?;
    if !golden.exists() {
        return Err(GoldenError::Missing {
            golden: golden.to_path_buf(),
            new,
        });
    }
    let (a, b) = (diff::open(golden)?, diff::open(&new)?);
    let report = diff::diff_files(&a, &b, 0.0, None)?;
    match report.first {
        None => {
            drop(b);
            // Nothing to look at: the run is the golden.
            let _ = std::fs::remove_file(&new);
            Ok(ran)
        }
        Some(_) => {
            let text = diff::render(&report, golden, &new);
            let first = report.first.expect("matched Some above");
            Err(GoldenError::Differs {
                first: Box::new(first),
                report: text,
                new,
            })
        }
    }
}

/// Where a check keeps the run's log: `NAME.new.mcap` beside the golden `NAME.mcap`.
fn new_path(golden: &Path) -> PathBuf {
    golden.with_file_name(new_name(golden))
}

/// The file name of the run's log: `NAME.new.mcap` for the golden `NAME.mcap`.
fn new_name(golden: &Path) -> String {
    let stem = golden
        .file_stem()
        .map_or_else(|| "golden".into(), |s| s.to_string_lossy());
    format!("{stem}.new.mcap")
}

/// Runs `game` on `sim` for frame 0 to `frames`, the script's commands before their
/// frames, recorded into `path` (a temporary file, renamed when complete). The simulation
/// back, and the game or the error that stopped it.
fn run<G: Game>(
    path: &Path,
    sim: Simulation,
    game: G,
    frames: u64,
    script: &[(u64, Command<G::Input>)],
    record_inputs: bool,
) -> (Simulation, Result<G, GoldenError>) {
    let log = match crate::log_writer(path) {
        Ok(log) => log,
        Err(e) => return (sim, Err(e.into())),
    };
    let mut session = match GameSession::start(sim, game, log, record_inputs) {
        Ok(s) => s,
        // The simulation went with the session: the caller gets a stand-in back.
        Err(e) => {
            return (
                Simulation::new(&ricochet_sim::Scenario::default()),
                Err(e.into()),
            );
        }
    };
    let mut order: Vec<&(u64, Command<G::Input>)> = script.iter().collect();
    order.sort_by_key(|(frame, _)| *frame);
    let mut pending = order.into_iter().peekable();
    let mut failed = None;
    for _ in 0..=frames {
        let next = session.next_frame();
        while let Some((_, command)) = pending.next_if(|(f, _)| *f <= next) {
            let sent = match command {
                Command::Join(name) => session.join(name).map(|_| ()),
                Command::Leave(p) => session.leave(*p).map(|_| ()),
                Command::Input(p, input) => session.input_typed(*p, input).map(|_| ()),
            };
            if let Err(e) = sent {
                failed = Some(GoldenError::from(e));
                break;
            }
        }
        if failed.is_some() {
            break;
        }
        match session.step() {
            Ok(_) => {}
            Err(StepError::Overflow { frame, what }) => {
                // Like `ricochet run`: the frame that overflowed is not written.
                failed = Some(GoldenError::Overflow { frame, what });
                break;
            }
            Err(StepError::Log(e)) => {
                failed = Some(e.into());
                break;
            }
        }
    }
    let (log, sim, game) = session.into_parts();
    if let Err(e) = log.finish() {
        return (sim, Err(failed.unwrap_or(e.into())));
    }
    match failed {
        Some(e) => (sim, Err(e)),
        None => (sim, Ok(game)),
    }
}
