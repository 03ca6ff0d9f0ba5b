//! `ricochet check`: load and validate a scenario without running it.

use std::path::Path;
use std::process::ExitCode;

use crate::load::load;

/// `ricochet check`: load and validate, print a one-line description.
pub fn check(path: &Path) -> anyhow::Result<ExitCode> {
    let s = match load(Some(path)) {
        Ok(s) => s,
        Err(code) => return Ok(code),
    };
    // A closed pipe or a failed write is the caller's (`main`) to report.
    crate::out::print(&format!(
        "{}: ok: \"{}\", {} bodies, {} templates, {} script events, {} layers, dt {} s, {} frames\n",
        path.display(),
        crate::out::escape_controls(&s.name),
        s.bodies.len(),
        s.templates.len(),
        s.script.len(),
        s.world.layers.names().len(),
        s.world.dt,
        s.frames
    ))?;
    Ok(ExitCode::SUCCESS)
}
