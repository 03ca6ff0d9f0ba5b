//! `ricochet replay SESSION.mcap`: steps a recorded session again (`ricochet serve
//! --record`), from the scenario it carries and its `/input` channel, and writes the log
//! anew. The simulation being deterministic, the new log is the recorded one, byte for
//! byte: a live session that showed a bug is a golden log.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use ricochet_log::{LogFile, LogWriter};
use ricochet_sim::load_scenario;

use crate::out;
use crate::session::{SCENARIO_ATTACHMENT, Session};

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
    let frames = file
        .channels()
        .find(|c| c.topic == "/stats")
        .map_or(0, |c| c.messages);
    let mut inputs = Vec::new();
    if file.channels().any(|c| c.topic == "/input") {
        for m in file.topic_messages("/input")? {
            let m = m?;
            let frame = m.data["frame"].as_u64().unwrap_or(0);
            let text = m.data["text"].as_str().unwrap_or("").to_owned();
            inputs.push((frame, text));
        }
    }
    let output = output.unwrap_or_else(|| log.with_extension("replay.mcap"));
    let mut writer = LogWriter::create(&output, crate::record::LIBRARY)?;
    writer.attach(SCENARIO_ATTACHMENT, "application/toml", text.as_bytes())?;
    let mut session = Session::new(&scenario, writer)?;
    let mut pending = inputs.iter().peekable();
    for _ in 0..frames {
        let next = session.next_frame();
        while let Some((_, text)) = pending.next_if(|(f, _)| *f == next) {
            // Refused inputs are refused again, the same way: nothing to report here.
            let _ = session.input(text)?;
        }
        session.step()?;
    }
    session.into_sink().finish()?;
    let same = std::fs::read(log)? == std::fs::read(&output)?;
    out::note(&format!(
        "replayed {frames} frames and {} inputs -> {}: {}",
        inputs.len(),
        output.display(),
        if same {
            "byte-identical to the recording"
        } else {
            "NOT identical to the recording (`ricochet diff` names the first divergence)"
        }
    ))?;
    Ok(ExitCode::from(if same { 0 } else { 1 }))
}
