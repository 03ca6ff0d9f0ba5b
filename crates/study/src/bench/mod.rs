//! The benchmark behind `ricochet bench`: Ricochet's full step against rapier2d's
//! collision-only pipeline and Box2D v3's step, on the scenes of [`ricochet_scenes::bench`],
//! in the same process on the same frames. [`measure`](mod@measure) runs one scene;
//! [`report`] makes the table, the CSV and each scene's contact summaries.

pub mod measure;
pub mod report;

pub use measure::{MAX_FRAMES, Row, run_scene};
