//! `ricochet collide`: the narrow phase on pairs from a file, one JSON line per pair.

use std::io::{BufWriter, Read, Write};
use std::path::Path;
use std::process::ExitCode;

use anyhow::Context;
use ricochet_geom::{contact, parse_case_file};
use serde::Serialize;

use crate::out::{self, Stream, WriteError};

/// One output line; fields in this order.
#[derive(Serialize)]
struct Line<'a> {
    id: &'a serde_json::Value,
    overlap: bool,
    depth: f64,
    normal: [f64; 2],
    point: [f64; 2],
}

/// Reads `file` (`-` is stdin), prints a JSON line per case, returns the exit code. A closed
/// pipe (`| head -1`) stops it quietly; any other failed write is an error.
pub fn run(file: &Path) -> anyhow::Result<ExitCode> {
    let text = if file == Path::new("-") {
        let mut s = String::new();
        std::io::stdin()
            .read_to_string(&mut s)
            .context("reading standard input")?;
        s
    } else {
        match std::fs::read_to_string(file) {
            Ok(s) => s,
            Err(e) => {
                out::error(&format!("error: {}: {e}", file.display()));
                return Ok(ExitCode::from(2));
            }
        }
    };
    let cases = match parse_case_file(&text) {
        Ok(cases) => cases,
        Err(errors) => {
            let name = if file == Path::new("-") {
                "<stdin>".to_owned()
            } else {
                file.display().to_string()
            };
            let mut report = String::new();
            for e in &errors {
                report += &format!("error: {name}: {e}\n");
            }
            report += &format!(
                "{} bad case(s); nothing was collided. See `ricochet collide --help` for the format.",
                errors.len()
            );
            out::error(&report);
            return Ok(ExitCode::from(2));
        }
    };
    let mut stdout = BufWriter::new(std::io::stdout().lock());
    let mut write = || -> std::io::Result<()> {
        for case in &cases {
            let c = contact(&case.a.shape, &case.a.pose, &case.b.shape, &case.b.pose);
            let line = Line {
                id: &case.id,
                overlap: c.overlaps(),
                depth: c.depth,
                normal: [c.normal.x, c.normal.y],
                point: [c.point.x, c.point.y],
            };
            serde_json::to_writer(&mut stdout, &line)?;
            stdout.write_all(b"\n")?;
        }
        stdout.flush()
    };
    match write() {
        Ok(()) => Ok(ExitCode::SUCCESS),
        Err(source) => Err(WriteError {
            stream: Stream::Stdout,
            source,
        }
        .into()),
    }
}
