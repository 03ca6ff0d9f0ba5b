//! `ricochet accuracy`: run time against error, on scenes whose exact answer is known. The
//! scenes are `ricochet_scenes::accuracy`'s; the study (measurement, tables, checks, CSV,
//! chart) is [`ricochet_study::accuracy`]'s, described in `docs/accuracy.md`. This file
//! prints and writes what it returns.

use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;

use std::fmt::Write as _;

use crate::{files, out};
use ricochet_study::accuracy::{chart, measure, report};

/// Runs the accuracy sweep: prints the tables, writes the CSV and the SVG.
pub fn run(csv: Option<&Path>, svg: Option<&Path>) -> anyhow::Result<ExitCode> {
    // A path that can't be written fails now, not after the study.
    for path in [csv, svg].into_iter().flatten() {
        files::check_writable(path)?;
    }
    let start = Instant::now();
    let mut progress_error = None;
    let study = measure(|part| {
        if let Err(e) = out::note(&format!("accuracy: {part}")) {
            progress_error.get_or_insert(e);
        }
    })?;
    if let Some(e) = progress_error {
        return Err(e.into());
    }

    let mut text = String::new();
    for part in [
        report::KINDS.to_owned(),
        report::table(&study.rows),
        report::offset_table(&study.offsets),
        report::speed_table(&study.speeds),
    ] {
        text.push_str(&part);
        text.push('\n');
    }
    let checks = report::checks(&study.rows, study.script_matches);
    let mut ok = true;
    text.push_str("checks:\n");
    for (pass, what) in &checks {
        ok &= *pass;
        let _ = writeln!(text, "  {} {what}", if *pass { "PASS" } else { "FAIL" });
    }
    out::print(&text)?;

    if let Some(path) = csv {
        files::write(path, report::csv_text(&study.rows).as_bytes())?;
        out::print(&format!("wrote {}\n", path.display()))?;
    }
    if let Some(path) = svg {
        files::write(path, chart::svg_text(&study.rows).as_bytes())?;
        out::print(&format!("wrote {}\n", path.display()))?;
    }
    out::print(&format!(
        "total wall time {:.1} s ({} build)\n",
        start.elapsed().as_secs_f64(),
        if cfg!(debug_assertions) {
            "debug"
        } else {
            "release"
        }
    ))?;
    Ok(if ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}
