//! [`RapierScene`]: rapier's collision-only pipeline holding one collider per body (see the
//! module docs of [`bench`](super)).

use std::collections::BTreeMap;

use rapier2d_f64::math::{Pose as PPose, Rot2};
use rapier2d_f64::prelude::{
    ActiveCollisionTypes, BroadPhaseBvh, ColliderBuilder, ColliderHandle, ColliderSet,
    CollisionPipeline, IslandManager, NarrowPhase, RigidBodySet,
};
use ricochet_geom::{Pose, Primitive, Rot, Shape};
use ricochet_sim::{BodyKind, Entity, Layers, Simulation};

use crate::OracleError;
use crate::convert::{place, to_vector};
use crate::pairs::{LayerFilter, index, penetration};

/// The pose of the rapier collider of `shape` at `pose`: the pose `convert::place` gives the
/// primitive, in world coordinates.
pub(super) fn collider_pose(shape: &Shape, pose: &Pose) -> Result<PPose, OracleError> {
    let to_rot = |r: Rot| Rot2::from_cos_sin_unchecked(r.c, r.s);
    if shape.is_chain() {
        // A chain is one polyline collider in body coordinates (`convert::place`).
        let rot = shape.rotation(pose.angle);
        return Ok(PPose::from_parts(to_vector(pose.position), to_rot(rot)));
    }
    let Shape::Primitive(p) = shape else {
        return Err(OracleError::Conversion(
            "compound shapes are not supported by the benchmark's rapier scene",
        ));
    };
    let rot = shape.rotation(pose.angle);
    let p0 = pose.position;
    Ok(match p {
        Primitive::Circle(c) => PPose::from_translation(to_vector(p0 + rot.apply(c.center))),
        Primitive::Aabb(b) => PPose::from_translation(to_vector(p0 + rot.apply(b.center))),
        Primitive::Obb(b) => {
            let own = if b.angle == 0.0 {
                rot
            } else {
                Rot::from_angle(pose.angle + b.angle)
            };
            PPose::from_parts(to_vector(p0 + rot.apply(b.center)), to_rot(own))
        }
        Primitive::Capsule(_) | Primitive::Polygon(_) | Primitive::Segment(_) => {
            PPose::from_parts(to_vector(p0), to_rot(rot))
        }
    })
}

/// Rapier's collision-only pipeline holding one collider per body of a [`Simulation`]. See
/// the module docs for how it is configured.
pub struct RapierScene {
    pipeline: CollisionPipeline,
    islands: IslandManager,
    pub(super) broad_phase: BroadPhaseBvh,
    pub(super) narrow_phase: NarrowPhase,
    /// Always empty: every collider is parentless.
    pub(super) bodies: RigidBodySet,
    pub(super) colliders: ColliderSet,
    /// Every non-static body: its dense index and its collider.
    moving: Vec<(usize, ColliderHandle)>,
    /// Every body's entity, by dense index (the index in the collider's `user_data`).
    pub(super) entities: Vec<Entity>,
    /// The scene's layers: the pair filter ([`LayerFilter`]) reads them.
    layers: Layers,
}

impl RapierScene {
    /// Rapier colliders for every body of `sim`, at their current poses. Call [`step`] once
    /// before timing anything: the first step builds the broad phase's tree from scratch.
    ///
    /// [`step`]: RapierScene::step
    pub fn new(sim: &Simulation) -> Result<RapierScene, OracleError> {
        let w = sim.world();
        let mut scene = RapierScene {
            pipeline: CollisionPipeline::new(),
            islands: IslandManager::new(),
            broad_phase: BroadPhaseBvh::new(),
            narrow_phase: NarrowPhase::new(),
            bodies: RigidBodySet::new(),
            colliders: ColliderSet::new(),
            moving: Vec::new(),
            entities: w.entity.clone(),
            layers: sim.scenario().world.layers.clone(),
        };
        let filter = LayerFilter::new(&sim.scenario().world.layers);
        for i in 0..w.len() {
            let pose = collider_pose(w.shape(i), &w.pose(i))?;
            // The shape in its own frame: the collider's pose carries the whole placement.
            let (_, shape) = place(w.shape(i), &Pose::default(), ricochet_geom::Vec2::ZERO)?;
            let types = if w.kind[i] == BodyKind::Dynamic {
                ActiveCollisionTypes::default() | ActiveCollisionTypes::FIXED_FIXED
            } else {
                ActiveCollisionTypes::default()
            };
            let builder = ColliderBuilder::new(shape)
                .position(pose)
                .active_collision_types(types);
            let collider = filter.collider(builder, w.layer[i], i).build();
            let handle = scene.colliders.insert(collider);
            if w.kind[i] != BodyKind::Static {
                scene.moving.push((i, handle));
            }
        }
        Ok(scene)
    }

    /// Copies every moving body's pose from `sim` into its collider (not part of the timed
    /// step). Colliders whose pose did not change are left untouched, so rapier skips them.
    ///
    /// Fails when the simulation gained or lost bodies: the bench scenes keep their count.
    pub fn sync(&mut self, sim: &Simulation) -> Result<(), OracleError> {
        let w = sim.world();
        if w.entity != self.entities {
            return Err(OracleError::Conversion(
                "the simulation spawned or removed bodies; the bench needs a stable body set",
            ));
        }
        for &(i, handle) in &self.moving {
            let pose = collider_pose(w.shape(i), &w.pose(i))?;
            // `get_mut` marks the collider modified: touch only the ones that moved.
            if self
                .colliders
                .get(handle)
                .is_some_and(|c| *c.position() != pose)
                && let Some(c) = self.colliders.get_mut(handle)
            {
                c.set_position(pose);
            }
        }
        Ok(())
    }

    /// One step of rapier's collision-only pipeline: broad phase and narrow phase for
    /// everything that moved since the last step. This is the part `ricochet bench` times.
    pub fn step(&mut self) {
        self.pipeline.step(
            0.0,
            &mut self.islands,
            &mut self.broad_phase,
            &mut self.narrow_phase,
            &mut self.bodies,
            &mut self.colliders,
            &LayerFilter::new(&self.layers),
            &(),
        );
    }

    /// How many colliders rapier holds.
    #[must_use]
    pub fn len(&self) -> usize {
        self.entities.len()
    }

    /// Whether rapier holds no collider.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.entities.is_empty()
    }

    /// Every pair rapier's narrow phase finds penetrating after the last [`step`]: some
    /// contact point with `dist < 0`. Keyed `(a, b)` with `a < b`, the value is the pair's
    /// smallest `dist` (minus its depth). Every such pair has a dynamic body (see the module
    /// docs on collision types), so only the moving colliders' pairs are visited.
    ///
    /// [`step`]: RapierScene::step
    #[must_use]
    pub fn penetrating(&self) -> BTreeMap<(Entity, Entity), f64> {
        let mut pairs = BTreeMap::new();
        let entity = |h: ColliderHandle| {
            self.colliders
                .get(h)
                .and_then(|c| self.entities.get(index(c)).copied())
        };
        for &(_, co) in &self.moving {
            for pair in self.narrow_phase.contact_pairs_with(co) {
                let Some(dist) = penetration(pair) else {
                    continue;
                };
                let (Some(ea), Some(eb)) = (entity(pair.collider1), entity(pair.collider2)) else {
                    continue;
                };
                pairs.insert((ea.min(eb), ea.max(eb)), dist);
            }
        }
        pairs
    }
}
