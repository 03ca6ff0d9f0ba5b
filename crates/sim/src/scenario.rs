//! A scenario: the world's settings, the bodies at frame 0, the templates they spawn from,
//! and the script of timed events. Built in code, or loaded from a file by
//! [`crate::load_scenario`] (feature `toml`).

use std::collections::BTreeMap;

use crate::action::Event;
use crate::def::{BodyDef, WorldDef};

/// A checked scenario, ready to simulate.
#[derive(Clone, Debug, PartialEq)]
pub struct Scenario {
    /// Name for logs.
    pub name: String,
    /// World settings.
    pub world: WorldDef,
    /// Default number of steps.
    pub frames: u64,
    /// Body prototypes by name.
    pub templates: BTreeMap<String, BodyDef>,
    /// Bodies at frame 0, in file order (which is their id order).
    pub bodies: Vec<BodyDef>,
    /// Script events sorted by frame (file order within a frame).
    pub script: Vec<Event>,
}

impl Default for Scenario {
    /// An empty scene: the default [`WorldDef`] (1/60 s, no gravity, one layer), 600
    /// frames, no bodies, templates or script.
    fn default() -> Self {
        Scenario {
            name: "scenario".to_owned(),
            world: WorldDef::default(),
            frames: 600,
            templates: BTreeMap::new(),
            bodies: Vec::new(),
            script: Vec::new(),
        }
    }
}
