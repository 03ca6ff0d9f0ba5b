//! Loading a scenario: from a file, or the built-in demo when none is given. Bad input is
//! printed as `file:line:column: field: problem` and becomes exit code 2.

use std::path::Path;
use std::process::ExitCode;

use ricochet_sim::{Scenario, load_scenario_and_map};
use ricochet_tiled::MapSummary;

/// The built-in demo: `scenarios/asteroids.toml`, embedded.
pub const DEFAULT_SCENARIO: &str = include_str!("../scenarios/asteroids.toml");
/// The name errors and the default output file use for the built-in demo.
pub const DEFAULT_NAME: &str = "scenarios/asteroids.toml";

/// Reads and checks a scenario, printing the error and returning exit code 2 when bad.
pub fn load(path: Option<&Path>) -> Result<Scenario, ExitCode> {
    load_text(path).map(|(scenario, _)| scenario)
}

/// [`load`], with the file's text.
pub fn load_text(path: Option<&Path>) -> Result<(Scenario, String), ExitCode> {
    load_all(path).map(|(scenario, text, _)| (scenario, text))
}

/// [`load`], with the file's text and, when the scenario takes its level from a Tiled map
/// (`[tiled]`), what the map became: its bodies are added to the scenario here.
pub fn load_all(path: Option<&Path>) -> Result<(Scenario, String, Option<MapSummary>), ExitCode> {
    let (text, name) = match path {
        None => (DEFAULT_SCENARIO.to_owned(), DEFAULT_NAME.to_owned()),
        Some(p) => match std::fs::read_to_string(p) {
            Ok(t) => (t, p.display().to_string()),
            Err(e) => {
                crate::out::error(&format!("error: {}: {e}", p.display()));
                return Err(ExitCode::from(2));
            }
        },
    };
    let (mut scenario, tiled) = match load_scenario_and_map(&text, &name) {
        Ok(s) => s,
        Err(e) => {
            crate::out::error(&format!("error: {e}"));
            return Err(ExitCode::from(2));
        }
    };
    let summary = match (tiled, path) {
        (Some(def), Some(p)) => match ricochet_tiled::add_map(&mut scenario, &def, p) {
            Ok(summary) => Some(summary),
            Err(e) => {
                crate::out::error(&format!("error: {e}"));
                return Err(ExitCode::from(2));
            }
        },
        // The built-in demo has no map.
        _ => None,
    };
    Ok((scenario, text, summary))
}

/// A scenario file's text read from `path`, with its `[tiled]` map's bodies added when it
/// has one: what `ricochet test` steps. Errors are the loader's, as text.
pub fn scenario_with_map(text: &str, path: &Path) -> Result<Scenario, String> {
    let (mut scenario, tiled) =
        load_scenario_and_map(text, &path.display().to_string()).map_err(|e| e.to_string())?;
    if let Some(def) = tiled {
        ricochet_tiled::add_map(&mut scenario, &def, path).map_err(|e| e.to_string())?;
    }
    Ok(scenario)
}
