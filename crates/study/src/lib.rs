//! Ricochet's measurements: the accuracy study and the benchmark against rapier2d and Box2D.
//!
//! **Owns:** [`accuracy`]: error against run time on the scenes of
//! [`ricochet_scenes::accuracy`] (timestep and substep sweeps, stability far from the origin
//! and at high speed), its tables, CSV and SVG chart; [`bench`](mod@bench): Ricochet's step
//! timed against rapier's collision-only pipeline and Box2D's step on the scenes of
//! [`ricochet_scenes::bench`], the contact sets compared by the referee's rule
//! ([`ricochet_oracle::bench`]) and by Box2D's ([`ricochet_box2d::compare_box2d`]), its table
//! and CSV. Each is split into measurement (`measure`), what people read (`report`) and, for accuracy, the
//! chart (`chart`).
//!
//! **Never:** builds a scene (they come from `ricochet-scenes`), links rapier or Box2D
//! directly (the rapier side is `ricochet-oracle`'s, the Box2D side `ricochet-box2d`'s),
//! writes files or prints (the binary does, from the
//! strings returned here), or lets the wall clock reach a log or a test assertion: times are
//! benchmark figures only.

pub mod accuracy;
pub mod bench;
