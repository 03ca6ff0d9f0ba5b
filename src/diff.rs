//! `ricochet diff A.mcap B.mcap`: the comparison is `ricochet_log::diff`'s; this file reads
//! the options, prints the report and picks the exit code.

use std::path::Path;
use std::process::ExitCode;

pub use ricochet_log::diff::*;

use crate::out;

/// `ricochet diff`: exit code 0 equal, 1 they differ, 2 a log can't be compared (unreadable,
/// cut short, damaged, not a Ricochet log, an unknown `--topic`, a bad `--tolerance`).
pub fn run(
    a: &Path,
    b: &Path,
    tolerance: f64,
    topic: Option<&str>,
    json: bool,
) -> anyhow::Result<ExitCode> {
    if !(tolerance.is_finite() && tolerance >= 0.0) {
        out::error(&format!(
            "error: --tolerance must be a finite number >= 0, got {}",
            ricochet_geom::Number(tolerance)
        ));
        return Ok(ExitCode::from(2));
    }
    // The report's head is printed as soon as the first difference is known (the counts
    // need both logs read to the end); the JSON report is printed whole at the end.
    let mut told: Option<Result<(), out::WriteError>> = None;
    let mut tell = |d: &Divergence| {
        if !json {
            told = Some(out::print(&render_head(Some(d), tolerance, a, b)));
        }
    };
    let report = open(a)
        .and_then(|la| open(b).map(|lb| (la, lb)))
        .and_then(|(la, lb)| diff_files_with(&la, &lb, tolerance, topic, &mut tell));
    let report = match report {
        Ok(r) => r,
        Err(e) => {
            out::error(&format!("error: {e}"));
            return Ok(ExitCode::from(2));
        }
    };
    let code = if report.equal {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    };
    let printed = match told {
        None if json => out::print(&(serde_json::to_string_pretty(&report)? + "\n")),
        None => out::print(&render(&report, a, b)),
        Some(Ok(())) => out::print(&render_counts(&report)),
        Some(Err(e)) => Err(e),
    };
    match printed {
        // The reader went away (`| head`): the verdict is still the exit code.
        Err(e) if e.is_closed() => Ok(code),
        Err(e) => Err(e.into()),
        Ok(()) => Ok(code),
    }
}
