//! Ricochet's referee: rapier2d (f64, `enhanced-determinism`) recomputes what Ricochet's
//! simulation did and says where the two disagree.
//!
//! **Owns:** the only link to rapier and parry in the workspace; the conversion of Ricochet
//! shapes to parry shapes placed exactly as `ricochet_geom` places them; the per-frame
//! [`Referee`] (every logged contact recomputed by parry; the `all` pass's set of pairs
//! compared with rapier's broad and narrow phase at the detect poses, with a collider at
//! every image through the wrap seam (`seam.rs`); every swept pair cast
//! by parry along the frame's motion; each difference explained by a named rule of
//! [`rules`]); the free-flight comparison [`compare_motion`];
//! the [`ValidationSummary`] with its printable [`summary_table`]; the rapier side of
//! `ricochet bench` ([`bench`](mod@bench): rapier's collision-only pipeline on the same
//! shapes and poses, and the rule by which two contact sets agree, judged with the referee's
//! own recheck); the query referee's rapier side ([`QueryReferee`]: every body as a
//! collider, asked through rapier's `QueryPipeline` as Ricochet's scene queries are asked,
//! with the exact checks of the rules in `docs/validation.md`, "Scene queries"); and the one
//! layer filter both use (`pairs.rs`: rapier's collision groups
//! up to 32 layers, the layer matrix as a pair hook beyond). See `docs/validation.md` for
//! the rules, the tolerances and the figures.
//!
//! **Never:** feeds anything back into the simulation (it only reads a [`Simulation`] and
//! its [`FrameOutput`]), does I/O, reads the clock, or hides a difference under a blanket
//! tolerance: every difference is either within a [`Tolerances`] bound stated relative to the
//! shapes' size, or counted under a named rule, or reported in
//! [`FrameReport::details`]. Other crates must not link rapier; they call this one.
//!
//! ```no_run
//! # let text = std::fs::read_to_string("scenarios/shapes.toml").unwrap();
//! let scenario = ricochet_sim::load_scenario(&text, "shapes.toml").unwrap();
//! let summary = ricochet_oracle::validate(&scenario, scenario.frames, Default::default());
//! println!("{}", ricochet_oracle::summary_table(&summary));
//! assert!(summary.passed());
//! ```
//!
//! [`Simulation`]: ricochet_sim::Simulation
//! [`FrameOutput`]: ricochet_sim::FrameOutput

pub mod bench;
mod convert;
mod frame_report;
mod motion;
mod pairs;
mod referee;
mod scene_queries;
mod seam;
mod summary;
mod swept;

pub use convert::{ReferenceContact, reference_contact};
pub use motion::{
    BodyMotion, MOTION_ANGLE_PER_FRAME, MOTION_POSITION_RELATIVE, MotionReport, compare_motion,
    rapier_free_flight,
};
pub use referee::{FrameReport, Referee};
pub use scene_queries::{QueryReferee, QueryTolerance, ReferenceRayHit};
pub use summary::{MAX_DETAILS, ValidationSummary, summary_table, validate};

/// How closely Ricochet and rapier must agree on one contact.
///
/// Lengths are relative to the pair's size: `size` is half the diagonal of a shape's local
/// bounding box (the measure of the shared collision cases), and a pair uses the smaller of
/// its two sizes. Measured over 370 000 random overlapping pairs of every pairing (positions
/// up to 40 units from the origin, sizes about 1), the two engines differ by at most
/// `1.1e-15` in depth and `1.5e-11` rad in normal, so the defaults leave a margin of 10⁶ and
/// 60.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerances {
    /// Depths agree when `|depth_ricochet - depth_rapier| <= depth * min(size_a, size_b)`.
    /// The same band decides [`rules::TOUCHING`]: a pair within it of its response's
    /// threshold may fall on either side in either engine. Default `1e-9`.
    pub depth: f64,
    /// Normals agree when the angle between them is at most this, radians. Default `1e-9`.
    pub normal: f64,
    /// How far apart a `swept` contact may be logged, relative to the pair's size: Ricochet
    /// stops its time-of-impact search once the gap is under `1e-9` times the half-diagonal
    /// of the shape's bounds at its end angle, which is up to `√2` times the local size.
    /// Default `2e-9`.
    pub toi_gap: f64,
    /// Time-of-impact agreement, relative to the pair's size: a `swept` contact may be
    /// logged at most `toi * min(size_a, size_b)` further along the pair's relative motion
    /// than parry's first touch. Default `1e-8`.
    pub toi: f64,
}

impl Default for Tolerances {
    fn default() -> Self {
        Tolerances {
            depth: 1e-9,
            normal: 1e-9,
            toi_gap: 2e-9,
            toi: 1e-8,
        }
    }
}

/// The named rules that explain a difference between the engines. Each is counted in
/// [`FrameReport::explained`] under its name; `docs/validation.md` says how each is detected.
/// A difference is counted under the first rule of [`ALL`](rules::ALL) that explains it.
pub mod rules {
    /// Neither body is dynamic: Ricochet's `detect` never tests such a pair (static and
    /// kinematic bodies do not collide with each other), rapier is asked for every pair.
    pub const STATIC_STATIC: &str = "static-static";
    /// Two single-AABB bodies in a `separate` layer pair: the per-axis passes
    /// (`resolve_x`, `resolve_y`) own them and `detect` skips them.
    pub const PER_AXIS_BOXES: &str = "per-axis-boxes";
    /// A `separate` push earlier in the same `all` pass moved one of the bodies: Ricochet
    /// tested the pair at the pushed poses (replayed from the log), where it is not (or
    /// still) in contact, while rapier saw the detect poses.
    pub const MOVED_IN_PASS: &str = "moved-in-pass";
    /// Parry's depth is within the depth tolerance of the response's threshold (0 for
    /// `report`/`destroy`, `SLOP` for `separate`): which side of it a pair falls is rounding.
    pub const TOUCHING: &str = "touching";
    /// The normals differ, but Ricochet's is a minimum translation too: the deepest part
    /// pair overlaps along it by parry's depth (two or more directions tie).
    pub const TIED_NORMAL: &str = "tied-normal";

    /// A swept body stops at its first destroying hit (one where it is the mover, the body
    /// that travelled further): a later touch along its path (found by parry's shape cast)
    /// is not tested by Ricochet.
    pub const FIRST_HIT: &str = "first-hit";
    /// A `swept` contact logged at the end of the frame, later than parry's first touch:
    /// Ricochet's conservative advancement gave up after 100 steps (a grazing approach) and
    /// fell back to the end-of-frame overlap.
    pub const TOI_FALLBACK: &str = "toi-fallback";

    /// A `separate` pair Ricochet stopped by time of impact in `detect` (a fast body
    /// against static or kinematic geometry): rapier's test at the detect poses sees the
    /// tunnelled end pose; the `swept` record is checked as a first touch instead, and its
    /// move replayed like a push.
    pub const SWEPT_SEPARATE: &str = "swept-separate";

    /// Every rule, in the order they are tried, with a one-line meaning.
    pub const ALL: [(&str, &str); 8] = [
        (
            STATIC_STATIC,
            "neither body dynamic: Ricochet never tests the pair",
        ),
        (
            PER_AXIS_BOXES,
            "two single AABBs in a separate pair: owned by resolve_x/resolve_y",
        ),
        (
            MOVED_IN_PASS,
            "a separate push earlier in the pass moved a body of the pair",
        ),
        (TOUCHING, "depth within tolerance of the response threshold"),
        (
            TIED_NORMAL,
            "normals differ but both are minimum translations (a tie)",
        ),
        (
            SWEPT_SEPARATE,
            "a separate pair stopped by time of impact: checked as a first touch",
        ),
        (
            FIRST_HIT,
            "a swept body already stopped at an earlier destroying hit",
        ),
        (
            TOI_FALLBACK,
            "a grazing swept test fell back to the end-of-frame overlap",
        ),
    ];
}

/// Why rapier could not be asked a question (reported as an unexplained mismatch).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum OracleError {
    /// A Ricochet shape has no parry equivalent.
    #[error("shape conversion: {0}")]
    Conversion(&'static str),
    /// Parry has no contact query for this pairing.
    #[error("parry has no contact query for {0}")]
    Unsupported(String),
}
