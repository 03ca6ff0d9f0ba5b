//! `ricochet collide`: the narrow phase on pairs from a file, one JSON line per pair.
//!
//! The input is streamed a case at a time ([`CaseReader`]: at most `MAX_CASE_BYTES` a case),
//! so memory does not grow with its length. Nothing is printed on stdout unless every case is
//! good: the lines wait in a spool (in memory up to [`SPOOL_IN_MEMORY`], then in a temporary
//! file), and at most [`MAX_ERRORS_SHOWN`] errors are printed, then how many there were.

use std::io::{BufRead, BufReader, BufWriter, Seek, Write};
use std::path::Path;
use std::process::ExitCode;

use ricochet_geom::{CaseReader, contact};
use serde::Serialize;

use crate::out::{self, Stream, WriteError};

/// The errors printed before the count: the first ones locate the trouble; 500 MB of bad
/// lines once wrote 499 MB of errors.
pub const MAX_ERRORS_SHOWN: usize = 20;

/// Output lines kept in memory before they go to a temporary file.
const SPOOL_IN_MEMORY: usize = 1 << 20;

/// One output line; fields in this order.
#[derive(Serialize)]
struct Line<'a> {
    id: &'a serde_json::Value,
    overlap: bool,
    depth: f64,
    normal: [f64; 2],
    point: [f64; 2],
}

/// The output lines, held until the whole input is known to be good.
struct Spool {
    memory: Vec<u8>,
    file: Option<BufWriter<std::fs::File>>,
}

impl Spool {
    fn write(&mut self, line: &[u8]) -> std::io::Result<()> {
        if self.file.is_none() && self.memory.len() + line.len() > SPOOL_IN_MEMORY {
            let mut file = BufWriter::new(tempfile::tempfile()?);
            file.write_all(&self.memory)?;
            self.memory = Vec::new();
            self.file = Some(file);
        }
        match &mut self.file {
            Some(f) => f.write_all(line),
            None => {
                self.memory.extend_from_slice(line);
                Ok(())
            }
        }
    }

    /// Copies everything spooled to `to`.
    fn copy_to(self, to: &mut impl Write) -> std::io::Result<()> {
        match self.file {
            None => to.write_all(&self.memory),
            Some(f) => {
                let mut f = f
                    .into_inner()
                    .map_err(std::io::IntoInnerError::into_error)?;
                f.rewind()?;
                std::io::copy(&mut f, to).map(|_| ())
            }
        }
    }
}

/// Reads `file` (`-` is stdin), prints a JSON line per case, returns the exit code. A closed
/// pipe (`| head -1`) stops it quietly; any other failed write is an error.
pub fn run(file: &Path) -> anyhow::Result<ExitCode> {
    let stdin = std::io::stdin();
    let (input, name): (Box<dyn BufRead>, String) = if file == Path::new("-") {
        (Box::new(stdin.lock()), "<stdin>".to_owned())
    } else {
        match std::fs::File::open(file) {
            Ok(f) => (
                Box::new(BufReader::with_capacity(1 << 16, f)),
                file.display().to_string(),
            ),
            Err(e) => {
                out::error(&format!("error: {}: {e}", file.display()));
                return Ok(ExitCode::from(2));
            }
        }
    };
    let name = out::escape_controls(&name);
    let mut spool = Spool {
        memory: Vec::new(),
        file: None,
    };
    let mut errors = 0usize;
    let mut shown = String::new();
    let mut line = Vec::new();
    for case in CaseReader::new(input) {
        match case {
            // Once a case is bad nothing will be printed: the rest are only checked.
            Ok(case) if errors == 0 => {
                let c = contact(&case.a.shape, &case.a.pose, &case.b.shape, &case.b.pose);
                line.clear();
                serde_json::to_writer(
                    &mut line,
                    &Line {
                        id: &case.id,
                        overlap: c.overlaps(),
                        depth: c.depth,
                        normal: [c.normal.x, c.normal.y],
                        point: [c.point.x, c.point.y],
                    },
                )?;
                line.push(b'\n');
                if let Err(e) = spool.write(&line) {
                    out::error(&format!("error: cannot keep the output lines: {e}"));
                    return Ok(ExitCode::from(2));
                }
            }
            Ok(_) => {}
            Err(e) => {
                errors += 1;
                if errors <= MAX_ERRORS_SHOWN {
                    shown += &format!("error: {name}: {}\n", out::escape_controls(&e.to_string()));
                }
            }
        }
    }
    if errors > 0 {
        let more = if errors > MAX_ERRORS_SHOWN {
            format!(" (the first {MAX_ERRORS_SHOWN} shown)")
        } else {
            String::new()
        };
        out::error(&format!(
            "{shown}{errors} bad case(s){more}; nothing was collided. See `ricochet collide \
             --help` for the format."
        ));
        return Ok(ExitCode::from(2));
    }
    let mut stdout = BufWriter::new(std::io::stdout().lock());
    match spool.copy_to(&mut stdout).and_then(|()| stdout.flush()) {
        Ok(()) => Ok(ExitCode::SUCCESS),
        Err(source) => Err(WriteError {
            stream: Stream::Stdout,
            source,
        }
        .into()),
    }
}
