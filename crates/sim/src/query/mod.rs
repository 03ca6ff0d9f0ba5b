//! Scene queries: what a game asks the world between steps (rapier's `QueryPipeline`,
//! Box2D's `b2World_CastRay`/`b2World_OverlapAABB`). Every query takes `&self`, sees the
//! bodies through a [`QueryFilter`], and is exact, as the narrow phase is: candidates come
//! from bounds, and each is tested with `ricochet-geom`'s exact ray, point, box, shape and
//! time-of-impact functions, in a frame centred on the body (so an answer at `1e6` is as
//! good as at the origin).
//!
//! | query | answers | as |
//! |---|---|---|
//! | [`Simulation::cast_ray`] | the first hit, [`RayHit`] | rapier `cast_ray`, Box2D `b2World_CastRayClosest` |
//! | [`Simulation::cast_ray_all`] | every body hit, by distance then entity | rapier `intersections_with_ray` |
//! | [`Simulation::cast_shape`] | the first touch of a moving shape, [`ShapeHit`] | rapier `cast_shape`, Box2D `b2World_CastShape` |
//! | [`Simulation::overlap_point`] | the bodies at a point, id order | rapier `intersections_with_point` |
//! | [`Simulation::overlap_aabb`] | the bodies overlapping a box (exact shapes), id order | Box2D `b2World_OverlapAABB` (bounds only there) |
//! | [`Simulation::overlap_shape`] | the bodies a shape overlaps, id order | rapier `intersections_with_shape` |
//!
//! # Conventions
//! - **Solid bodies** (rapier's `solid = true`): a ray starting strictly inside a body hits
//!   it at distance 0, at the origin, with a **zero normal** (rapier gives a zero normal
//!   too); a shape cast overlapping a body at its start pose hits it at fraction 0.
//! - **Normals:** a ray hit's normal is the body's outward unit normal (against the ray); a
//!   shape hit's points from the cast shape towards the body.
//! - **Touching** counts as [`ricochet_geom::overlaps`] counts it: not at all. A point on a
//!   body's boundary is not in it; a shape or box that only touches a body does not
//!   overlap it. A ray that reaches a body's boundary hits it (grazing included), and a ray
//!   starting on the boundary heading in hits at 0 with the face's normal; heading out, it
//!   misses.
//! - **Bad input never panics:** a zero or non-finite direction, a non-finite or negative
//!   distance, a non-finite pose, point or box (or one beyond
//!   [`ricochet_geom::MAX_COORDINATE`]) give `None` or an empty list.
//! - **Order:** overlaps list entities in id order, each once; `cast_ray_all` by distance,
//!   then entity; ties of the first hit go to the lower entity.
//!
//! # Wrap worlds
//! In a world with `bounds` and `wrap = true` a query sees every image of every body (the
//! body translated by whole world sizes): a ray that leaves one edge goes on from the
//! other, up to `max_distance`, its distance accumulated; a shape cast follows its
//! translation across the edges the same way; an overlap sees the images of a body
//! straddling an edge. Hit points are on the body as the world holds it (the image's point
//! moved back by whole world sizes). A region query spanning more than
//! [`MAX_IMAGES_PER_AXIS`] world sizes along an axis sees only that many images.

mod candidates;
mod filter;
mod hits;
mod images;
mod overlaps;
mod rays;
mod shapes;

pub use filter::QueryFilter;
pub use hits::{RayHit, ShapeHit};
pub use images::MAX_IMAGES_PER_AXIS;
