//! `ricochet dump LOG.mcap`: a log as JSON lines, one message a line, so that scripts and
//! people can grep it (`mcap cat --json` does the same for any MCAP). Messages are streamed
//! one at a time: memory does not grow with the log.

use std::io::{BufWriter, Write};
use std::ops::RangeInclusive;
use std::path::Path;
use std::process::ExitCode;

use ricochet_log::{LogFile, LogMessage};
use serde::Serialize;

use crate::out::{self, Stream, WriteError};

/// Parses `A..B` (inclusive), `A..`, `..B` or `N` into an inclusive range of frames.
fn parse_frames(text: &str) -> Result<RangeInclusive<u64>, String> {
    let num = |s: &str, default: u64| -> Result<u64, String> {
        if s.is_empty() {
            Ok(default)
        } else {
            s.trim()
                .parse()
                .map_err(|_| format!("--frames {text}: {s:?} is not a frame number"))
        }
    };
    let range = match text.split_once("..") {
        Some((a, b)) => num(a, 0)?..=num(b, u64::MAX)?,
        None => {
            let n = num(text, 0)?;
            n..=n
        }
    };
    if range.start() > range.end() {
        return Err(format!(
            "--frames {text}: the first frame is after the last"
        ));
    }
    Ok(range)
}

/// Nanoseconds per frame: a message's `log_time` over its `frame` field, from the first
/// `/bodies` or `/stats` message past frame 0. `None` when the log has no such message (then
/// every message is at frame 0).
fn step_ns(log: &LogFile) -> Result<Option<u64>, ricochet_log::LogError> {
    for topic in ["/bodies", "/stats", "/contacts"] {
        if !log.channels().any(|c| c.topic == topic) {
            continue;
        }
        for m in log.topic_messages(topic)? {
            let m = m?;
            if let Some(f) = m.data.get("frame").and_then(serde_json::Value::as_u64)
                && f > 0
            {
                return Ok(Some(m.log_time / f));
            }
        }
    }
    Ok(None)
}

/// One printed line, in `mcap cat --json`'s field order.
#[derive(Serialize)]
struct Line<'a> {
    topic: &'a str,
    sequence: u32,
    log_time: u64,
    publish_time: u64,
    data: &'a serde_json::Value,
}

fn line(m: &LogMessage) -> Line<'_> {
    Line {
        topic: &m.topic,
        sequence: m.sequence,
        log_time: m.log_time,
        publish_time: m.publish_time,
        data: &m.data,
    }
}

/// `ricochet dump`: prints the messages of `path` (on `topic` only, in `frames` only).
pub fn run(path: &Path, topic: Option<&str>, frames: Option<&str>) -> anyhow::Result<ExitCode> {
    let range = match frames.map(parse_frames).transpose() {
        Ok(r) => r,
        Err(e) => {
            out::error(&format!("error: {e}"));
            return Ok(ExitCode::from(2));
        }
    };
    let log = match LogFile::open(path) {
        Ok(l) => l,
        Err(e) => {
            out::error(&format!("error: {e}"));
            return Ok(ExitCode::from(2));
        }
    };
    if let Some(t) = topic
        && !log.channels().any(|c| c.topic == t)
    {
        let topics: Vec<&str> = log.channels().map(|c| c.topic.as_str()).collect();
        out::error(&format!(
            "error: --topic {}: {} has no such topic; it has: {}",
            out::escape_controls(t),
            path.display(),
            topics.join(", ")
        ));
        return Ok(ExitCode::from(2));
    }
    let step = if range.is_some() {
        step_ns(&log)?
    } else {
        None
    };
    let messages = match topic {
        Some(t) => log.topic_messages(t)?,
        None => log.messages()?,
    };
    let stdout = std::io::stdout();
    let mut w = BufWriter::new(stdout.lock());
    let failed = |source| WriteError {
        stream: Stream::Stdout,
        source,
    };
    for m in messages {
        let m = m?;
        if let Some(r) = &range {
            let frame = step.map_or(0, |ns| m.log_time.checked_div(ns).unwrap_or(0));
            if frame > *r.end() {
                // Messages come in log-time order: nothing later is in the range.
                break;
            }
            if frame < *r.start() {
                continue;
            }
        }
        serde_json::to_writer(&mut w, &line(&m)).map_err(|e| failed(e.into()))?;
        w.write_all(b"\n").map_err(failed)?;
    }
    w.flush().map_err(failed)?;
    Ok(ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::parse_frames;

    #[test]
    fn frame_ranges_are_inclusive_and_may_be_open() {
        assert_eq!(parse_frames("40..60"), Ok(40..=60));
        assert_eq!(parse_frames("7"), Ok(7..=7));
        assert_eq!(parse_frames("..3"), Ok(0..=3));
        assert_eq!(parse_frames("5.."), Ok(5..=u64::MAX));
        assert!(parse_frames("9..2").is_err());
        assert!(parse_frames("a..b").is_err());
    }
}
