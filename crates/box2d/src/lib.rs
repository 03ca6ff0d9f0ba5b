//! Box2D v3 as the second baseline of `ricochet bench`: the same shapes at the same poses as
//! a running Ricochet [`Simulation`], stepped by Box2D, timed by Box2D's own profile, and its
//! contact set compared with Ricochet's.
//!
//! **Owns:** the only link to Box2D in the workspace (`boxdd` 0.6, Box2D v3 built from its C
//! source by the system C compiler, in its `double-precision` large-world mode: positions in
//! `f64`, shapes, rotations and pair-relative geometry in `f32`); the conversion of Ricochet
//! shapes to Box2D shapes placed as `ricochet_geom` places them (`convert.rs`); the layer
//! matrix as Box2D filters (`filter.rs`); the [`Box2dScene`] the bench steps; and the rule by
//! which a frame's contact set agrees with Box2D's ([`compare_box2d`]).
//!
//! **Never:** feeds anything back into the simulation (it only reads a [`Simulation`] and its
//! [`FrameOutput`]), does I/O, reads the clock (Box2D's profile does, and those figures only
//! reach the bench's table), or links rapier (that baseline is `ricochet-oracle`'s). Other
//! crates must not link Box2D; they call this one.
//!
//! # The configuration
//!
//! Box2D creates a contact only when one of the two bodies is dynamic, and its solver moves
//! dynamic bodies. A game that moves its own bodies and asks Box2D only "what touches what"
//! has three choices:
//!
//! - **kinematic bodies with sensor shapes:** no contact at all between two kinematic bodies,
//!   and sensor events are overlap flags computed after the step (`b2OverlapSensors`, not the
//!   broad and narrow phase the bench compares); sensors do not see other sensors, so the
//!   `report` pairs between two moving layers (rain's drops, platformer actors) would be lost;
//! - **dynamic bodies teleported with `b2Body_SetTransform` and stepped with `dt = 0`:** Box2D
//!   skips its solver entirely, so "its full step" would only be its collision step;
//! - **dynamic bodies with every motion locked** (`b2BodyDef::motionLocks`: `linearX`,
//!   `linearY`, `angularZ`), teleported with `b2Body_SetTransform`, stepped with the scene's
//!   `dt` in 4 sub-steps: Box2D pairs, collides and solves them as the dynamic bodies they
//!   are, but the solver can never move them (a lock zeroes the velocity before positions are
//!   integrated), so every pose comes from Ricochet.
//!
//! [`Box2dScene`] takes the third: its `collide` time is exactly Box2D's broad and narrow
//! phase on the same bodies, and its full step is Box2D's real step on the same contacts.
//! Around it, it does what a good Box2D user would:
//!
//! - one Box2D body and one shape per Ricochet body, statics as static bodies (each at its own
//!   `f64` position: one shared static body would put every tile's offset in `f32`);
//!   `invokeContactCreation` off for static shapes (they are paired when the moving shapes
//!   are);
//! - gravity zero, sleep off (`b2Body_SetTransform` does not wake a sleeping body, so a
//!   sleeping body would miss its new pose);
//! - one worker: Box2D single-threaded, as Ricochet and the rapier baseline are; Box2D built
//!   as boxdd-sys builds it (`-O2`, SSE2, asserts on: it does not define `NDEBUG`). Built with
//!   `CFLAGS=-DNDEBUG` instead, three alternating runs each gave `collide` 2.07–2.40 against
//!   2.06–2.35 ms on `asteroids-10000` and 4.96–5.10 against 4.84–4.98 ms on `rain-10000`: no
//!   difference beyond this machine's noise, so the bench keeps the default build;
//! - the layer matrix as category and mask bits (`filter.rs`), so layers Ricochet ignores are
//!   never paired;
//! - contact recycling off (`b2BodyDef::enableContactRecycling`, on by default): a recycled
//!   contact keeps its anchors and extrapolates its separation along its old normal while the
//!   pair moves less than `10 × linear slop` relative to each other, so it reports the pairs
//!   near the given poses rather than at them. Box2D's own documentation warns that it "may
//!   lead to ghost collision that should be avoided on characters", and that is what the
//!   bench met: with it on, `platformer-10000-1000` reported 855 box–tile penetrations in 100
//!   frames where the boxes stand flush or beside the tile (a box walking onto the next tile,
//!   its old side normal extrapolated), and `rain-10000` 3. It does not make Box2D faster
//!   here: stepping both worlds on the same frames (median of 100, three runs), `collide` was
//!   2.6–3.0 ms with recycling and 2.3 ms without on `asteroids-10000`, 1.0–1.3 against
//!   1.1–1.5 ms on `platformer-10000-1000`, 5.6 against 5.2–5.5 ms on `rain-10000`;
//! - Box2D's defaults for the rest: speculative margin (`4 × linear slop`), continuous
//!   collision, linear slop `0.005` (one length unit per metre).
//!
//! [`Box2dScene::sync`] copies only the poses that changed; [`Box2dScene::step`] steps once
//! and keeps `b2World_GetProfile`'s figures ([`StepTimes`]); [`Box2dScene::touching`] reads
//! the pairs whose manifold has points, the state Box2D's contact begin and end events report,
//! with the manifold's smallest separation so that the comparison can tell a penetration from
//! Box2D's speculative contacts.
//!
//! `queries.rs` asks the same world `ricochet bench --queries`'s rays and box overlaps
//! ([`Box2dScene::queries`]: `b2World_CastRayClosest`, `b2World_OverlapAABB`,
//! `b2World_OverlapShape`), each convention stated there.
//!
//! [`Simulation`]: ricochet_sim::Simulation
//! [`FrameOutput`]: ricochet_sim::FrameOutput

mod agreement;
mod convert;
mod filter;
mod queries;
mod scene;

pub use agreement::{Box2dAgreement, compare_box2d};
pub use filter::BOX2D_LAYERS;
pub use queries::{Box2dQueries, Box2dRayHit};
pub use scene::{Box2dScene, SUB_STEPS, StepTimes};

/// The tolerance of the contact-set comparison, world units, on both sides of touching:
/// Ricochet's depth `<= BOX2D_CONTACT_TOLERANCE` or Box2D's separation
/// `>= -BOX2D_CONTACT_TOLERANCE` is a touch either engine may call either way.
///
/// Box2D computes a pair in `f32` relative to the pair (shapes, rotations, and the offset
/// between the two bodies, rounded after an `f64` subtraction): with the bench's shapes (a few
/// units across) each rounding is a few `1e-7`. Over every pair both engines find penetrating
/// in 100 frames, the depths differ by at most `7.6e-8` on `asteroids-10000` and `9.4e-8` on
/// `platformer-10000-1000`; on `rain-10000` all but 4 of 64 594 pairs are within `1e-5`, and
/// those 4 are deep capsule pairs (depths 0.07 to 0.75) where Box2D's manifold points are not
/// the deepest ones (up to `4.9e-4` shallower or deeper): a difference of depth, not of
/// whether the pair penetrates. So `1e-5` leaves a margin of a hundred over rounding; a box
/// standing flush on a tile comes out within `1e-6` of 0 (the tests check it).
pub const BOX2D_CONTACT_TOLERANCE: f64 = 1e-5;

/// How many disagreements a [`Box2dAgreement`] keeps word for word (all are counted).
pub const MAX_AGREEMENT_DETAILS: usize = 20;

/// What Box2D has allocated in this process (`b2GetByteCount`: every world's bodies, shapes,
/// contacts, trees and stacks), megabytes.
pub fn allocated_mb() -> Result<f64, Box2dError> {
    boxdd::allocated_byte_count()
        .map(|bytes| bytes as f64 / (1024.0 * 1024.0))
        .map_err(|e| Box2dError::Box2d(format!("reading the allocated byte count: {e}")))
}

/// Why a Box2D scene could not be built or read.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum Box2dError {
    /// A Ricochet scene has no Box2D equivalent (a compound shape, more than 64 layers, a
    /// polygon Box2D's hull would change, bodies spawned or removed).
    #[error("Box2D conversion: {0}")]
    Conversion(String),
    /// Box2D (through boxdd) refused a call.
    #[error("Box2D: {0}")]
    Box2d(String),
}

#[cfg(test)]
mod tests;
