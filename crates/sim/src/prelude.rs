//! What a game needs, in one `use`: `use ricochet_sim::prelude::*;` brings the geometry
//! (shapes, vectors, poses, bounds, from `ricochet-geom`, so a game needs no second
//! dependency), the definitions a scene is made of, the inputs, the events and the
//! simulation. Everything else is at the crate root.

pub use ricochet_geom::{Bounds, Pose, Primitive, Shape, ShapeError, Vec2};

pub use crate::action::{Action, Event, ScriptAction};
pub use crate::check::ScenarioError;
pub use crate::control::ControlError;
pub use crate::def::{
    ActiveRegion, BodyDef, BodyKind, Controller, LayerId, Layers, Response, Split, WorldBounds,
    WorldDef,
};
pub use crate::entity::Entity;
pub use crate::event::{FireOutcome, GameEvent, JumpOutcome, Removal, ScriptInput};
pub use crate::game::{Game, GameLoop, Player};
pub use crate::history::{HistoryError, Past};
pub use crate::output::{ContactRecord, FrameOutput, RemovedBody};
pub use crate::pipeline::Simulation;
pub use crate::query::{QueryFilter, RayHit, ShapeHit};
pub use crate::scenario::{Scenario, TileRows};
pub use crate::snapshot::{Snapshot, SnapshotError};
