//! The accuracy study behind `ricochet accuracy`: run time against error, on the scenes of
//! [`ricochet_scenes::accuracy`], whose exact answers are known. Every scene is stepped by
//! [`ricochet_sim::Simulation`], the same path `ricochet run` takes: frame 0 is the initial
//! state, every later `step()` advances one `dt`. The scenes and what their errors mean are
//! described in `docs/accuracy.md`.
//!
//! [`measure()`] runs everything ([`measure`](mod@measure)); [`report`] turns the result into
//! the printed tables, the acceptance checks and the CSV; [`chart`] into the SVG.

pub mod chart;
pub mod measure;
pub mod report;

pub use measure::measure;

/// The frame rates of the timestep sweep: dt = 1/30 s to 1/960 s.
pub const FRAME_HZ: [u32; 6] = [30, 60, 120, 240, 480, 960];
/// The frame rate the substep rows keep.
pub const SUBSTEP_HZ: u32 = 60;
/// Sim steps per displayed frame in the substep rows.
pub const SUBSTEPS: [u32; 3] = [1, 2, 4];
/// The coordinate offsets of the stability study, up to just inside
/// `ricochet_geom::MAX_COORDINATE` (1e15), beyond which scenarios are rejected.
pub const OFFSETS: [f64; 14] = [
    0.0, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 9e14,
];
/// The bullet speeds of the stability study, units/s.
pub const SPEEDS: [f64; 9] = [1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10];
/// The bullet speed of the timestep sweep, units/s.
pub const BULLET_SPEED: f64 = 300.0;
/// Position tolerance of the stability study: what rounding may add to a run, in units.
pub const POSITION_TOLERANCE: f64 = 1e-6;

/// One measured figure: one error of one run.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// The scene: `projectile`, `spring`, `orbit`, `drop`, `bullets`.
    pub scene: &'static str,
    /// `euler`, `prescribed`, `state`, `swept`, `discrete`, `rapier`, with `+substeps` for
    /// the rows that keep 60 Hz frames and take `substeps` sim steps per frame.
    pub method: String,
    /// Displayed frames per second: the frame dt is `1 / frame_hz`.
    pub frame_hz: u32,
    /// Sim steps per displayed frame: the sim's dt is `1 / (frame_hz * substeps)`.
    pub substeps: u32,
    /// The error kind (`position`, `energy`, `landing_frame`, ...; see [`report::KINDS`]).
    pub kind: &'static str,
    /// The error against the exact answer.
    pub error: f64,
    /// Wall seconds per simulated second.
    pub wall: f64,
}

impl Row {
    /// The displayed frame's dt, seconds (the CSV's `dt`).
    #[must_use]
    pub fn dt(&self) -> f64 {
        1.0 / f64::from(self.frame_hz)
    }
}

/// What the scenes measure `offset` units from the origin (both axes), at 60 Hz.
#[derive(Clone, Debug, PartialEq)]
pub struct OffsetResult {
    /// The offset.
    pub offset: f64,
    /// How far the projectile's end position moved from the run at the origin (rounding).
    pub projectile: f64,
    /// The drop's landing step minus the exact one.
    pub landing: f64,
    /// The drop's largest distance from the rest height after landing.
    pub rest: f64,
    /// Bullets (swept, 300 units/s) whose hits are not the exact first hit.
    pub swept_wrong: f64,
}

/// Bullets at `speed`, 60 Hz: wrong first hits and wall time, swept and discrete.
#[derive(Clone, Debug, PartialEq)]
pub struct SpeedResult {
    /// Units/s.
    pub speed: f64,
    /// Swept bullets whose hits are not the exact first hit.
    pub swept_wrong: f64,
    /// Discrete bullets whose hits are not the exact first hit.
    pub discrete_wrong: f64,
    /// Wall seconds per simulated second, swept.
    pub swept_wall: f64,
    /// Wall seconds per simulated second, discrete.
    pub discrete_wall: f64,
}

/// Everything one run of the study measured.
#[derive(Clone, Debug, PartialEq)]
pub struct Study {
    /// The timestep and substep sweeps of every scene, in a fixed order.
    pub rows: Vec<Row>,
    /// The stability study far from the origin.
    pub offsets: Vec<OffsetResult>,
    /// The stability study of fast bullets.
    pub speeds: Vec<SpeedResult>,
    /// Whether a script of `set_force` events gives the same bits as writing the force
    /// before each step.
    pub script_matches: bool,
}

/// The rows of one scene, method and kind, in sweep order.
#[must_use]
pub fn series<'a>(rows: &'a [Row], scene: &str, method: &str, kind: &str) -> Vec<&'a Row> {
    rows.iter()
        .filter(|r| r.scene == scene && r.method == method && r.kind == kind)
        .collect()
}
