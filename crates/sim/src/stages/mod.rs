//! The stages, one file per concept. Each is a plain function of what it needs: the
//! [`StageCtx`] (the world, the scenario's world settings, the templates, the frame's
//! output), its own state where it keeps some, or just the world. The pipeline
//! (`pipeline.rs`) owns that state and calls them in order; no stage knows the pipeline.

use std::collections::BTreeMap;

use crate::def::{BodyDef, WorldDef};
use crate::output::FrameOutput;
use crate::world::World;

pub(crate) mod bounds;
pub(crate) mod box_contact;
pub(crate) mod carry;
pub(crate) mod cull;
pub(crate) mod detect;
pub(crate) mod far_path;
pub(crate) mod lifetimes;
pub(crate) mod motion;
pub(crate) mod mover_pairs;
pub(crate) mod narrow_groups;
pub(crate) mod obstacles;
pub(crate) mod one_way;
pub(crate) mod pass_order;
pub(crate) mod push;
pub(crate) mod remove;
pub(crate) mod rider;
pub(crate) mod script;
pub(crate) mod separate;
pub(crate) mod sleep;
pub(crate) mod slope;
pub(crate) mod sweep_axis;
pub(crate) mod sweep_normal;
pub(crate) mod swept_pairs;
pub(crate) mod touch;
pub(crate) mod wrap;

/// How far two solid bodies may still overlap after `separate` has pushed them apart, in
/// world units: positions are set exactly flush, so what remains is rounding.
pub const SLOP: f64 = 1e-9;

/// What a stage works on: the bodies, the scenario's world settings (layer matrix, gravity,
/// step, bounds, active region, sleeping) and templates, read-only, and the frame's output.
pub(crate) struct StageCtx<'a> {
    /// The bodies.
    pub world: &'a mut World,
    /// The scenario's world settings; the one layer matrix every stage reads.
    pub def: &'a WorldDef,
    /// Templates by name, for spawns, bullets and split children.
    pub templates: &'a BTreeMap<String, BodyDef>,
    /// What this frame produced so far.
    pub out: &'a mut FrameOutput,
}
