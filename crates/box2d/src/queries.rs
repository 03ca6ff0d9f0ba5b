//! The Box2D side of `ricochet bench --queries`: scene queries on a [`Box2dScene`]'s world,
//! as a Box2D user asks them (`b2World_CastRayClosest`, `b2World_OverlapAABB`,
//! `b2World_OverlapShape`, through boxdd's `Query`).
//!
//! - The filter is every category and every mask bit: Box2D's default query filter has
//!   category 1 only, which a shape whose mask leaves out layer 0 would refuse
//!   (`b2ShouldQueryCollide` tests both ways).
//! - A ray is `b2World_CastRayClosest` from `origin` along `direction * max_distance` (`f32`
//!   in Box2D; the origin stays `f64` in its large-world mode). Box2D's closest-hit callback
//!   skips a shape the ray starts inside (fraction 0): the bench draws its ray origins outside
//!   every body, so that this and the solid casts of Ricochet and rapier give the same answer.
//! - `b2World_OverlapAABB` is what its name says and no more: every shape whose *tree box*
//!   meets the query box (a moving shape's tree box is its box fattened by Box2D's
//!   `B2_AABB_MARGIN`, 0.1 length units), with no exact test: a superset of the shapes that
//!   overlap. [`Box2dQueries::overlap_box`] is Box2D's exact answer to the same question:
//!   `b2World_OverlapShape` with the box as a four-point proxy (GJK distance at most
//!   `0.1 × linear slop`, 5e-4, counts).
//!
//! Results are Box2D's `ShapeId`s; [`Box2dScene::entity`] reads the entity back from the
//! shape's user data, apart from the timed call (Ricochet's and rapier's answers name the body
//! directly; Box2D's user would keep the `ShapeId`).

use boxdd::{Aabb, Position, Query, QueryFilter, ShapeId, ShapeProxy};
use ricochet_geom::{Bounds, Vec2};
use ricochet_sim::Entity;

use crate::Box2dError;
use crate::scene::{Box2dScene, box2d};

/// One ray's closest hit, as Box2D reports it.
#[derive(Clone, Copy, Debug)]
pub struct Box2dRayHit {
    /// The shape hit ([`Box2dScene::entity`] names its body).
    pub shape: ShapeId,
    /// How far along the (unit) direction: Box2D's `f32` fraction times `max_distance`.
    pub distance: f64,
    /// The surface normal at the hit, pointing out of the shape.
    pub normal: Vec2,
}

/// A read-only query capability on a [`Box2dScene`]'s world (one per batch of queries:
/// boxdd checks the world's borrow once, when it is made).
pub struct Box2dQueries<'a> {
    query: Query<'a>,
}

/// Every category and every mask bit (see the module docs).
fn every_layer() -> QueryFilter {
    QueryFilter::new().category(u64::MAX).mask(u64::MAX)
}

/// A Ricochet vector as Box2D's local `f32` vector.
fn local(v: Vec2) -> [f32; 2] {
    [v.x as f32, v.y as f32]
}

impl Box2dScene {
    /// The query capability of this scene's world. Call after [`step`](Box2dScene::step):
    /// the first step builds the trees.
    pub fn queries(&self) -> Result<Box2dQueries<'_>, Box2dError> {
        let query = self.world.query().map_err(box2d("a query capability"))?;
        Ok(Box2dQueries { query })
    }

    /// The entity whose Box2D shape this is (its user data).
    pub fn entity(&mut self, shape: ShapeId) -> Result<Entity, Box2dError> {
        // Index 0's shape is compared first, then the tag is read: any index does.
        self.entity_of(0, shape)
    }
}

impl Box2dQueries<'_> {
    /// The closest shape the ray from `origin` along `direction` (unit length) meets within
    /// `max_distance` (`b2World_CastRayClosest`).
    pub fn cast_ray(
        &self,
        origin: Vec2,
        direction: Vec2,
        max_distance: f64,
    ) -> Result<Option<Box2dRayHit>, Box2dError> {
        let hit = self
            .query
            .cast_ray_closest(
                Position::new(origin.x, origin.y),
                local(direction * max_distance),
                every_layer(),
            )
            .map_err(box2d("a ray cast"))?;
        Ok(hit.map(|h| Box2dRayHit {
            shape: h.shape_id,
            distance: f64::from(h.fraction) * max_distance,
            normal: Vec2::new(f64::from(h.normal.x), f64::from(h.normal.y)),
        }))
    }

    /// Every shape whose tree box meets `bounds` (`b2World_OverlapAABB`: no exact test, see
    /// the module docs), in Box2D's order.
    pub fn overlap_aabb(&self, bounds: Bounds) -> Result<Vec<ShapeId>, Box2dError> {
        let c = bounds.center();
        let aabb = Aabb::from_center_half_extents([0.0, 0.0], local(bounds.half_extents()))
            .map_err(box2d("a query box"))?;
        self.query
            .overlap_aabb(Position::new(c.x, c.y), aabb, every_layer())
            .map_err(box2d("an AABB overlap"))
    }

    /// Every shape that overlaps `bounds` (`b2World_OverlapShape` with the box as a proxy:
    /// Box2D's exact test), in Box2D's order.
    pub fn overlap_box(&self, bounds: Bounds) -> Result<Vec<ShapeId>, Box2dError> {
        let c = bounds.center();
        let h = bounds.half_extents();
        let corners = [
            Vec2::new(-h.x, -h.y),
            Vec2::new(h.x, -h.y),
            Vec2::new(h.x, h.y),
            Vec2::new(-h.x, h.y),
        ];
        let proxy = ShapeProxy::new(corners.map(local), 0.0).map_err(box2d("a box proxy"))?;
        self.query
            .overlap_shape(Position::new(c.x, c.y), proxy, every_layer())
            .map_err(box2d("a shape overlap"))
    }
}
