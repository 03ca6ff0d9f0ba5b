//! The benchmark behind `ricochet bench`: Ricochet's full step against rapier2d's
//! collision-only pipeline and Box2D v3's step, on the scenes of [`ricochet_scenes::bench`],
//! in the same process on the same frames. [`measure`](mod@measure) runs one scene;
//! [`report`] makes the table, the CSV and each scene's contact summaries; [`queries`] is
//! `ricochet bench --queries` (rays and box overlaps against rapier's and Box2D's queries);
//! [`snapshots`] is `ricochet bench --snapshots` (snapshot size and round-trip times);
//! [`broad_phases`] is `ricochet bench --broad-phases` (every broad phase on every scene).

pub mod broad_phases;
pub mod measure;
pub mod queries;
pub mod report;
pub mod snapshots;

pub use measure::{MAX_FRAMES, Row, run_scene};
