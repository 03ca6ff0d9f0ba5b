//! `ricochet accuracy`: run time against error, on scenes whose exact answer is known. The
//! scenes are `ricochet_scenes::accuracy`'s; the study (measurement, tables, checks, CSV,
//! chart) is [`ricochet_study::accuracy`]'s, described in `docs/accuracy.md`. This file
//! prints and writes what it returns.

use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::Context;
use ricochet_study::accuracy::{chart, measure, report};

/// Runs the accuracy sweep: prints the tables, writes the CSV and the SVG.
pub fn run(csv: Option<&Path>, svg: Option<&Path>) -> anyhow::Result<ExitCode> {
    let start = Instant::now();
    let study = measure(|part| eprintln!("accuracy: {part}"))?;

    print!("{}", report::KINDS);
    println!();
    print!("{}", report::table(&study.rows));
    println!();
    print!("{}", report::offset_table(&study.offsets));
    println!();
    print!("{}", report::speed_table(&study.speeds));
    println!();

    let checks = report::checks(&study.rows, study.script_matches);
    let mut ok = true;
    println!("checks:");
    for (pass, what) in &checks {
        ok &= *pass;
        println!("  {} {what}", if *pass { "PASS" } else { "FAIL" });
    }

    if let Some(path) = csv {
        std::fs::write(path, report::csv_text(&study.rows))
            .with_context(|| format!("writing {}", path.display()))?;
        println!("wrote {}", path.display());
    }
    if let Some(path) = svg {
        std::fs::write(path, chart::svg_text(&study.rows))
            .with_context(|| format!("writing {}", path.display()))?;
        println!("wrote {}", path.display());
    }
    println!(
        "total wall time {:.1} s ({} build)",
        start.elapsed().as_secs_f64(),
        if cfg!(debug_assertions) {
            "debug"
        } else {
            "release"
        }
    );
    Ok(if ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}
