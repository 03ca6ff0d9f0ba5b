//! `ricochet collide`: the narrow phase on pairs from a file, one JSON line per pair.

use std::io::{BufWriter, Read, Write};
use std::path::Path;
use std::process::ExitCode;

use anyhow::Context;
use ricochet_geom::{contact, parse_case_file};
use serde::Serialize;

/// One output line; fields in this order.
#[derive(Serialize)]
struct Line<'a> {
    id: &'a serde_json::Value,
    overlap: bool,
    depth: f64,
    normal: [f64; 2],
    point: [f64; 2],
}

/// Reads `file` (`-` is stdin), prints a JSON line per case, returns the exit code.
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
                eprintln!("error: {}: {e}", file.display());
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
            for e in &errors {
                eprintln!("error: {name}: {e}");
            }
            eprintln!(
                "{} bad case(s); nothing was collided. See `ricochet collide --help` for the format.",
                errors.len()
            );
            return Ok(ExitCode::from(2));
        }
    };
    let mut out = BufWriter::new(std::io::stdout().lock());
    for case in &cases {
        let c = contact(&case.a.shape, &case.a.pose, &case.b.shape, &case.b.pose);
        let line = Line {
            id: &case.id,
            overlap: c.overlaps(),
            depth: c.depth,
            normal: [c.normal.x, c.normal.y],
            point: [c.point.x, c.point.y],
        };
        let line = serde_json::to_string(&line).context("encoding a result")?;
        if writeln!(out, "{line}").is_err() {
            // The reader went away (`| head`): not an error of ours.
            return Ok(ExitCode::SUCCESS);
        }
    }
    if out.flush().is_err() {
        return Ok(ExitCode::SUCCESS);
    }
    Ok(ExitCode::SUCCESS)
}
