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
    println!(
        "{}: ok: \"{}\", {} bodies, {} templates, {} script events, {} layers, dt {} s, {} frames",
        path.display(),
        s.name,
        s.bodies.len(),
        s.templates.len(),
        s.script.len(),
        s.world.layers.names().len(),
        s.world.dt,
        s.frames
    );
    Ok(ExitCode::SUCCESS)
}
