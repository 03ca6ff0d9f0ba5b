//! Ricochet's Tiled loader: a scenario's `[tiled]` table ([`TiledDef`], parsed and checked by
//! `ricochet-sim`'s loader) and the map files it names become static bodies and spawns added
//! to the [`Scenario`].
//!
//! **What it owns**: reading the map files (the only crate that does I/O for a level besides
//! the binary), turning tile layers into [`ricochet_sim::TileRows`] (a few numbers per run of
//! identical tiles, so a 1,000 × 1,000-tile map loads like the dense platformer scene) and
//! objects into static bodies of Ricochet's existing shapes, and located errors naming the map
//! file, the layer, the object or tile, and what to do.
//!
//! **What it never does**: simulate, write files, or read anything but the map and the
//! tilesets and templates it names (paths relative to the file that names them).
//!
//! **Formats**. TMX (`.tmx`, with `.tsx` tilesets and `.tx` templates) is read by the kept
//! [`tiled`] crate (0.16): CSV, base64 (uncompressed, zlib, gzip, zstd), the old XML `<tile>`
//! data, infinite maps (chunks, negative coordinates), external tilesets, templates,
//! per-tile collision groups, flip flags, properties, class and type. Tiled JSON (`.tmj` or
//! `.json` maps, `.tsj` tilesets, `.tj` templates) is not read by that crate: [`json`]
//! converts each JSON file to the equivalent TMX text as the crate asks for it, so both forms
//! go through one reader. The JSON is walked as `serde_json` values; an object with a key the
//! converter does not know is refused (a new shape kind must never become a missing wall),
//! while unknown map, layer and tileset keys (editor settings) are ignored.
//!
//! **Bounds** (memory stays bounded whatever the input): a file read is at most
//! [`MAX_FILE_BYTES`]; compressed tile data is decompressed (checked before the crate does)
//! to at most [`MAX_CELLS`] × 4 bytes per map; a tile layer covers at most [`MAX_CELLS`]
//! cells; a polygon has at most [`MAX_POLYGON_POINTS`] points.
//!
//! `one_way` entries take tiles and objects like `solid` ones and make them static bodies of
//! `one_way_layer` (one-way platforms: `ricochet-sim`'s `stages/one_way.rs`).
//!
//! Polylines of `solid` entries become terrain chains (`ricochet-geom`'s `Shape::chain`,
//! two-sided), one static body each, split into several chains that name each other's end
//! points as ghosts past `MAX_CHAIN_POINTS`; a polyline of a `one_way` entry, or among a
//! tile's collision shapes, is a located error.
//!
//! Not supported yet (a located error, never a silently missing wall): text objects, and maps
//! that are not orthogonal.

mod build;
pub mod json;
mod objects;
mod read;
mod shapes;
mod tiles;

use std::collections::BTreeMap;
use std::path::Path;

use ricochet_geom::{Shape, Vec2};
pub use ricochet_sim::TiledDef;
use ricochet_sim::{Scenario, ScenarioError};

/// The most bytes of one map, tileset or template file.
pub const MAX_FILE_BYTES: u64 = 64 << 20;
/// The most cells a map's tile layer may cover (4,096 × 4,096): its decoded tiles take about
/// 12 bytes a cell in the reader.
pub const MAX_CELLS: u64 = 1 << 24;
/// The most points of one polygon (its convex split is quadratic in them).
pub const MAX_POLYGON_POINTS: usize = 256;
/// An ellipse's axes ratio past which it is refused: its 32-gon stays within 0.5% of the
/// longer semi-axis, which is 5% of the shorter one at this ratio.
pub const MAX_ELLIPSE_RATIO: f64 = 10.0;

/// Why a map could not become a level: the map file, where in it, and what to do.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{file}: {place}: {problem}")]
pub struct TiledError {
    /// The map (or tileset, template) file.
    pub file: String,
    /// Where in it: `layer "Ground", tile (3, 4)`, `layer "Objects", object 12 "spike"`, or
    /// a `[tiled]` field of the scenario.
    pub place: String,
    /// What is wrong and what to do.
    pub problem: String,
}

/// What a piece of the map becomes: a solid, a one-way platform (`one_way` entries, on
/// `[tiled] one_way_layer`), or a terrain chain (a polyline of a `solid` entry).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum PieceKind {
    /// A static solid.
    Solid,
    /// A one-way platform: a static body of `[tiled] one_way_layer`.
    OneWay,
    /// A terrain chain (a polyline of a `solid` entry): a static body of `[tiled] layer`.
    Chain,
}

/// One static body made from a map object or a tile with its own collision shapes.
#[derive(Clone, Debug, PartialEq)]
pub struct TiledPiece {
    /// What it becomes.
    pub kind: PieceKind,
    /// The body's name: the object's name, or its map layer's.
    pub name: String,
    /// The shape, relative to `position`.
    pub shape: Shape,
    /// World position, units (y up).
    pub position: Vec2,
}

/// What a map became, for `ricochet check`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MapSummary {
    /// Static tiles (in tile rows).
    pub tiles: usize,
    /// Static bodies from objects.
    pub solids: usize,
    /// One-way pieces: objects and tiles.
    pub one_way: usize,
    /// Terrain chains (polylines; a polyline longer than a chain's limit is several).
    pub chains: usize,
    /// Bodies spawned, by template.
    pub spawns: BTreeMap<String, usize>,
}

/// Reads the map `def` names (relative to `scenario_path`'s folder) and adds its static tiles,
/// solid bodies and spawns to `scenario`, then checks the result as a scenario.
///
/// # Errors
/// A file that cannot be read or parsed, a map feature not supported, a `solid` layer the map
/// lacks, a shape Ricochet cannot hold, a body outside the world: located in the map.
pub fn add_map(
    scenario: &mut Scenario,
    def: &TiledDef,
    scenario_path: &Path,
) -> Result<MapSummary, TiledError> {
    let dir = scenario_path.parent().unwrap_or(Path::new(""));
    let map_path = dir.join(&def.map);
    let file = map_path.display().to_string();
    let map = read::load_map(&map_path)?;
    let built = build::build(&map, def, &scenario.templates, &file)?;
    let summary = built.summary();
    // Each tile row already has its layer: `layer`, or `one_way_layer` for one-way tiles.
    scenario
        .tiles
        .extend(built.tiles.into_iter().map(|(_, rows)| rows));
    for p in built.pieces {
        scenario.bodies.push(ricochet_sim::BodyDef {
            name: p.name,
            layer: match p.kind {
                PieceKind::OneWay => def.one_way_layer,
                _ => def.layer,
            },
            kind: ricochet_sim::BodyKind::Static,
            shape: p.shape,
            position: p.position,
            ..ricochet_sim::BodyDef::default()
        });
    }
    scenario.bodies.extend(built.spawns);
    scenario.check().map_err(|e: ScenarioError| TiledError {
        file,
        place: e.field,
        problem: format!(
            "{} (the scenario with the map's bodies added: tiles first, then the file's bodies, \
             then the map's objects and spawns)",
            e.problem
        ),
    })?;
    Ok(summary)
}
