//! A scenario: the world's settings, the bodies at frame 0 (rows of identical static tiles,
//! then one definition per body), the templates they spawn from, and the script of timed
//! events. Built in code, or loaded from a file by
//! [`crate::load_scenario`] (feature `toml`).

use std::collections::BTreeMap;

use crate::action::Event;
use ricochet_geom::{Shape, Vec2};

use crate::def::{BodyDef, LayerId, WorldDef};

/// A scenario, ready to simulate: a loaded one is checked; one built in code is checked
/// the same way by [`Scenario::check`] (or [`crate::Simulation::try_new`]).
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
    /// Static tiles at frame 0, spawned first (ids from 0 on), in order: a level's tiles
    /// as a few numbers per row instead of a [`BodyDef`] each. A scenario file's come from its
    /// Tiled map (`[tiled]`), added by `ricochet-tiled`.
    pub tiles: Vec<TileRows>,
    /// Bodies at frame 0, in file order (which is their id order), after the tiles.
    pub bodies: Vec<BodyDef>,
    /// Script events, in any order: a [`crate::Simulation`] built from the scenario sorts
    /// them by frame, keeping the given order of the events of one frame (as the loader
    /// does, with a file's order). No event is dropped for being out of order.
    pub script: Vec<Event>,
}

impl Default for Scenario {
    /// An empty scene: the default [`WorldDef`] (1/60 s, no gravity, one layer), 600
    /// frames, no tiles, bodies, templates or script.
    fn default() -> Self {
        Scenario {
            name: "scenario".to_owned(),
            world: WorldDef::default(),
            frames: 600,
            templates: BTreeMap::new(),
            tiles: Vec::new(),
            bodies: Vec::new(),
            script: Vec::new(),
        }
    }
}

/// A scenario's `[tiled]` table, checked against the scenario (its layer exists, its spawn
/// templates exist, its scale is positive) but not against the map, which
/// `ricochet-tiled` reads: this crate does no I/O.
#[derive(Clone, Debug, PartialEq)]
pub struct TiledDef {
    /// The map file as written, relative to the scenario file.
    pub map: String,
    /// World units per tile width (> 0).
    pub units_per_tile: f64,
    /// `solid` entries: `LAYER`, `LAYER?PROP` or `LAYER?PROP=VALUE`.
    pub solid: Vec<String>,
    /// `one_way` entries, same syntax.
    pub one_way: Vec<String>,
    /// The scenario layer the map's static bodies go to.
    pub layer: LayerId,
    /// The scenario layer the map's one-way platforms go to (`layer` when `one_way` is
    /// empty): the platform layer of a `one_way` layer pair.
    pub one_way_layer: LayerId,
    /// Object class, type or name → template name (a template the scenario has).
    pub spawn: BTreeMap<String, String>,
}

/// Rows of identical static bodies (a tile map's tiles): the `k`-th tile of a row starting
/// at `start` is the body `BodyDef { name, layer, kind: Static, shape, position: start +
/// step * k, ..BodyDef::default() }`. 24 bytes a row, however many tiles it holds.
#[derive(Clone, Debug, PartialEq)]
pub struct TileRows {
    /// Every tile's name.
    pub name: String,
    /// Every tile's layer.
    pub layer: LayerId,
    /// Every tile's shape.
    pub shape: Shape,
    /// From one tile of a row to the next.
    pub step: Vec2,
    /// Each row: its first tile's position and how many tiles it has.
    pub rows: Vec<(Vec2, u32)>,
}

impl TileRows {
    /// How many tiles.
    #[must_use]
    pub fn len(&self) -> usize {
        self.rows.iter().map(|&(_, n)| n as usize).sum()
    }

    /// Whether there are no tiles.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The tiles as definitions, in spawn order (what [`crate::World::spawn_tiles`] spawns).
    pub fn defs(&self) -> impl Iterator<Item = BodyDef> + '_ {
        self.rows.iter().flat_map(move |&(start, count)| {
            (0..count).map(move |k| BodyDef {
                name: self.name.clone(),
                layer: self.layer,
                kind: crate::BodyKind::Static,
                shape: self.shape.clone(),
                position: start + self.step * f64::from(k),
                ..BodyDef::default()
            })
        })
    }
}

impl Scenario {
    /// How many bodies frame 0 has: the tiles and the bodies.
    #[must_use]
    pub fn body_count(&self) -> usize {
        self.tiles.iter().map(TileRows::len).sum::<usize>() + self.bodies.len()
    }
}
