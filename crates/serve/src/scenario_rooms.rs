//! The rooms `ricochet serve SCENARIO` hosts besides its plain URL: each a fresh
//! simulation of the scenario, run by the scenario's game ([`ScenarioGame`]: no players,
//! its inputs the script's actions addressed by body name).

use ricochet_record::session::SCENARIO_ATTACHMENT;
use ricochet_sim::{Scenario, ScenarioGame, Simulation};

use crate::RoomMaker;

/// Rooms of one scenario.
pub struct ScenarioRooms {
    scenario: Scenario,
    /// The scenario file's text, attached to each room's recording (for `ricochet
    /// replay`), or empty.
    text: String,
}

impl ScenarioRooms {
    /// Rooms of `scenario`, whose file's text is `text` (or empty).
    pub fn new(scenario: Scenario, text: String) -> ScenarioRooms {
        ScenarioRooms { scenario, text }
    }
}

impl RoomMaker for ScenarioRooms {
    type Game = ScenarioGame;

    fn make(&self, _room: &str) -> Result<(Simulation, ScenarioGame), String> {
        Ok((Simulation::new(&self.scenario), ScenarioGame))
    }

    fn input_schema(&self) -> String {
        r#"{"type": "object", "properties": {"action": {"type": "string", "enum": ["destroy", "set_velocity", "apply_impulse", "set_force", "thrust", "turn", "fire", "move", "jump", "spawn"]}, "body": {"type": "string"}}, "required": ["action"]}"#.to_owned()
    }

    fn attachments(&self, _room: &str) -> Vec<(String, String, Vec<u8>)> {
        if self.text.is_empty() {
            return Vec::new();
        }
        vec![(
            SCENARIO_ATTACHMENT.to_owned(),
            "application/toml".to_owned(),
            self.text.as_bytes().to_vec(),
        )]
    }
}
