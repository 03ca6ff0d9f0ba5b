//! `ricochet check`: load and validate a scenario without running it.

use std::path::Path;
use std::process::ExitCode;

use crate::load::load_all;

/// `ricochet check`: load and validate, print a one-line description.
pub fn check(path: &Path) -> anyhow::Result<ExitCode> {
    let (s, map) = match load_all(Some(path)) {
        Ok((s, _, map)) => (s, map),
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
    // Terrain chains, from the file or a map: bodies, and segments they hold.
    let chains: Vec<usize> = s
        .bodies
        .iter()
        .filter(|b| b.shape.is_chain())
        .map(|b| b.shape.primitives().len())
        .collect();
    if !chains.is_empty() {
        crate::out::print(&format!(
            "  terrain chains: {} bodies, {} segments\n",
            chains.len(),
            chains.iter().sum::<usize>()
        ))?;
    }
    if let Some(m) = map {
        let spawns: Vec<String> = m.spawns.iter().map(|(t, n)| format!("{n} {t}")).collect();
        crate::out::print(&format!(
            "  tiled map: {} static tiles, {} solid bodies, {} one-way pieces, {} chains, spawns: {}\n",
            m.tiles,
            m.solids,
            m.one_way,
            m.chains,
            if spawns.is_empty() {
                "none".to_owned()
            } else {
                spawns.join(", ")
            }
        ))?;
    }
    Ok(ExitCode::SUCCESS)
}
