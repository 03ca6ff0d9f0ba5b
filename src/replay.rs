//! `ricochet replay SESSION.mcap`: steps a recorded session again (`ricochet serve
//! --record`), from the scenario it carries and its `/input` channel, and writes the log
//! anew. The simulation being deterministic, the new log is the recorded one, byte for
//! byte: a live session that showed a bug is a golden log.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use ricochet_log::{LogFile, LogWriter};
use ricochet_record::replay;
use ricochet_sim::{ScenarioGame, Simulation, load_scenario};

use crate::out;
use crate::session::SCENARIO_ATTACHMENT;

/// Replays `log` into `output` (default: `NAME.replay.mcap` beside it). Exit code 0 when the
/// replay is byte-identical to the recording, 1 when not, 2 when `log` is no session (no
/// scenario attachment, or more than one).
pub fn run(log: &Path, output: Option<PathBuf>) -> anyhow::Result<ExitCode> {
    let file = match LogFile::open(log) {
        Ok(f) => f,
        Err(e) => {
            out::error(&format!("error: {e}"));
            return Ok(ExitCode::from(2));
        }
    };
    // A game's room records the game's name: only its own code replays it.
    let game = replay::recorded_game(&file)?;
    if game != ScenarioGame::NAME {
        out::error(&format!(
            "error: {}: recorded by the game {:?}, which `ricochet replay` does not have (it \
             replays scenario sessions): replay it with the game's own code \
             (`ricochet_record::replay::replay`)",
            log.display(),
            out::escape_controls(&game)
        ));
        return Ok(ExitCode::from(2));
    }
    // A session carries the one scenario it was played from: with two, which one the
    // recording shows is unknown, and replaying either could pass or fail falsely.
    let scenarios = file
        .attachment_names()
        .filter(|n| *n == SCENARIO_ATTACHMENT)
        .count();
    if scenarios > 1 {
        out::error(&format!(
            "error: {}: {scenarios} {SCENARIO_ATTACHMENT} attachments: a session recorded by              `ricochet serve --record` carries exactly one, so which one it was played from              is unknown",
            log.display()
        ));
        return Ok(ExitCode::from(2));
    }
    let Some(text) = file.attachment(SCENARIO_ATTACHMENT)? else {
        out::error(&format!(
            "error: {}: no {SCENARIO_ATTACHMENT} attachment: not a session recorded by \
             `ricochet serve --record`",
            log.display()
        ));
        return Ok(ExitCode::from(2));
    };
    let text = String::from_utf8(text).context("the scenario attachment is not UTF-8")?;
    let name = format!("{}:{SCENARIO_ATTACHMENT}", log.display());
    let scenario = match load_scenario(&text, &name) {
        Ok(s) => s,
        Err(e) => {
            out::error(&format!("error: {e}"));
            return Ok(ExitCode::from(2));
        }
    };
    let output = output.unwrap_or_else(|| log.with_extension("replay.mcap"));
    let mut writer = LogWriter::create(&output, crate::record::LIBRARY)?;
    writer.attach(SCENARIO_ATTACHMENT, "application/toml", text.as_bytes())?;
    let replayed = replay::replay(&file, Simulation::new(&scenario), ScenarioGame, writer)?;
    replayed.sink.finish()?;
    let (frames, inputs) = (replayed.frames, replayed.commands);
    let same = std::fs::read(log)? == std::fs::read(&output)?;
    out::note(&format!(
        "replayed {frames} frames and {inputs} inputs -> {}: {}",
        output.display(),
        if same {
            "byte-identical to the recording"
        } else {
            "NOT identical to the recording (`ricochet diff` names the first divergence)"
        }
    ))?;
    Ok(ExitCode::from(if same { 0 } else { 1 }))
}
