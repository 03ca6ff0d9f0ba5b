//! Loading a scenario: from a file, or the built-in demo when none is given. Bad input is
//! printed as `file:line:column: field: problem` and becomes exit code 2.

use std::path::Path;
use std::process::ExitCode;

use ricochet_sim::{Scenario, load_scenario};

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
    match load_scenario(&text, &name) {
        Ok(s) => Ok((s, text)),
        Err(e) => {
            crate::out::error(&format!("error: {e}"));
            Err(ExitCode::from(2))
        }
    }
}
