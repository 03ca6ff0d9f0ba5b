//! Ricochet's exact 2D collision geometry.
//!
//! **Owns:** the shapes a body can carry ([`Shape`]: circle, AABB, OBB, capsule, convex
//! polygon, a compound of those, and a terrain chain of segments: [`Shape::chain`]), the [`Pose`] that places a shape in the world, the
//! bounding box of any shape at any pose ([`Bounds`]), the scenario/case-file description of a
//! shape ([`ShapeDef`]) with its validation, and the narrow phase: a cheap boolean
//! [`overlaps`] and a full [`contact()`] (signed depth, unit normal from `a` to `b`, a contact
//! point) for every pairing, how far a shape reaches at any angle ([`Shape::reach`],
//! [`beyond_reach`]), and rays against every shape ([`cast_ray`], [`contains_point`]).
//!
//! **Never:** does I/O (a case file is read from a reader its caller opened, through
//! [`CaseReader`]), keeps state between calls, reads the clock, allocates in the narrow phase
//! (but for a pair of compounds with more than 64 part pairs: their parts' boxes, to cull
//! them), or uses platform trigonometry (all `sin`/`cos` go through `libm`, so results are
//! the same bits on every machine). It knows nothing about bodies, layers, time or responses:
//! those
//! belong to the simulation crate.
//!
//! # Number type: `f64`
//! Every coordinate is an `f64`. The shared ground-truth cases put shapes about `1e6` from the
//! origin with tolerances near `1e-4`, and shapes of size `1e-7` near the origin with
//! tolerances near `1e-11`. An `f32` cannot even store a position at `1.7e6` closer than
//! `0.125`. `f64` has a unit roundoff of `1.1e-16`, so a position at `1e6` is stored to
//! `1.2e-10`. On top of that, every pair is computed in a frame centred on body `a`
//! ([`contact()`] subtracts the two positions first, which is exact for nearby bodies), so a pair
//! far from the origin is exactly as accurate as the same pair at the origin.
//!
//! # Conventions
//! - The contact normal points from `a` to `b`; `depth > 0` means overlap, and moving `b` by
//!   `depth * normal` separates the pair. When the shapes are apart, `depth` is minus the
//!   distance between them and the normal is the direction from `a`'s closest point to `b`'s.
//! - An AABB ignores the body's rotation (its centre offset still turns with the body). An OBB
//!   turns by the body's angle plus its own. Angles are radians, counter-clockwise.
//! - Polygons are convex and counter-clockwise in local coordinates, with at most
//!   [`MAX_POLYGON_VERTICES`] vertices.
//!
//! # Example
//! ```
//! use ricochet_geom::{contact, Pose, Shape, Vec2};
//! let ball = Shape::circle(1.0).unwrap();
//! let crate_ = Shape::aabb(Vec2::new(1.0, 1.0)).unwrap();
//! let c = contact(&ball, &Pose::at(0.0, 0.0), &crate_, &Pose::at(1.5, 0.0));
//! assert!(c.overlaps());
//! assert!((c.depth - 0.5).abs() < 1e-15);
//! assert_eq!(c.normal, Vec2::X);
//! ```

mod bounds;
mod case;
mod case_reader;
mod collide;
mod contact;
mod cores;
mod def;
mod math;
mod number;
mod placed;
mod ray;
mod reach;
mod shape;
mod toi;

pub use bounds::Bounds;
pub use case::{Case, CaseBody, CaseError, MAX_ID_BYTES, MAX_QUOTED, parse_case, parse_case_file};
pub use case_reader::{CaseReader, MAX_CASE_BYTES};
pub use collide::{
    contact, contact_deeper_than, contact_placed, overlaps, overlaps_placed, overlaps_placing,
    pair_name,
};
pub use contact::Contact;
pub use def::ShapeDef;
pub use math::{Pose, Rot, Vec2};
pub use number::{Number, Numbers};
pub use placed::{
    PlacedAabb, PlacedCapsule, PlacedCircle, PlacedObb, PlacedPolygon, PlacedPrimitive,
    PlacedSegment, place, place_rotated, placed_bounds,
};
pub use ray::{Ray, RayIntersection, cast_placed, cast_ray, contains_placed, contains_point};
pub use reach::beyond_reach;
pub use shape::{
    Aabb, Capsule, Circle, Compound, MAX_CHAIN_POINTS, MAX_COMPOUND_PARTS, MAX_COORDINATE,
    MAX_POLYGON_VERTICES, MIN_SIZE, Obb, Polygon, Primitive, Segment, Shape, ShapeError, ShapeKind,
};
pub use toi::{Impact, Sweep, time_of_impact};

/// The pair functions, one per pairing of primitives, for callers (and benchmarks) that want
/// to skip the dispatch. Each is a pure function of two shapes placed in one frame.
pub mod pairs {
    pub use crate::collide::{
        aabb_aabb::{collide_aabb_aabb, overlaps_aabb_aabb},
        aabb_capsule::{collide_aabb_capsule, overlaps_aabb_capsule},
        aabb_obb::{collide_aabb_obb, overlaps_aabb_obb},
        aabb_polygon::{collide_aabb_polygon, overlaps_aabb_polygon},
        capsule_capsule::{collide_capsule_capsule, overlaps_capsule_capsule},
        capsule_polygon::{collide_capsule_polygon, overlaps_capsule_polygon},
        circle_aabb::{collide_circle_aabb, overlaps_circle_aabb},
        circle_capsule::{collide_circle_capsule, overlaps_circle_capsule},
        circle_circle::{collide_circle_circle, overlaps_circle_circle},
        circle_obb::{collide_circle_obb, overlaps_circle_obb},
        circle_polygon::{collide_circle_polygon, overlaps_circle_polygon},
        obb_capsule::{collide_obb_capsule, overlaps_obb_capsule},
        obb_obb::{collide_obb_obb, overlaps_obb_obb},
        obb_polygon::{collide_obb_polygon, overlaps_obb_polygon},
        polygon_polygon::{collide_polygon_polygon, overlaps_polygon_polygon},
    };
    pub use crate::cores::{Core, collide_cores, overlaps_cores};
}
