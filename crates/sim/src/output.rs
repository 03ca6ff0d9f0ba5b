//! What one frame produces: contacts, events, destroyed bodies and counters. The recorder
//! turns these into log messages; the simulation never formats or writes anything.

use ricochet_geom::{Pose, Shape, Vec2};

use crate::broad_phase::BroadPhaseKind;
use crate::def::{BodyKind, LayerId, Response};
use crate::entity::Entity;
use crate::event::GameEvent;
use crate::stage_set::StageSet;

/// Which detection pass found a contact.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// The per-axis pass after moving along x.
    X,
    /// The per-axis pass after moving along y.
    Y,
    /// The full pass at the frame's final poses.
    All,
    /// A swept test: the first touch along the frame's motion (time of impact), logged at
    /// the poses of that moment.
    Swept,
}

impl Phase {
    /// `"x"`, `"y"` or `"all"`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Phase::X => "x",
            Phase::Y => "y",
            Phase::All => "all",
            Phase::Swept => "swept",
        }
    }
}

/// One detected contact, with the poses it was detected at, so that anyone can recompute it.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactRecord {
    /// The body with the lower id.
    pub a: Entity,
    /// The body with the higher id.
    pub b: Entity,
    /// The pass that found it.
    pub phase: Phase,
    /// Exact minimum translation direction from `a` to `b` at the poses below.
    pub normal: Vec2,
    /// Exact penetration depth at the poses below.
    pub depth: f64,
    /// Contact point.
    pub point: Vec2,
    /// `a`'s pose at detection.
    pub pose_a: Pose,
    /// `b`'s pose at detection.
    pub pose_b: Pose,
    /// The layer pair's response.
    pub response: Response,
    /// The push the response applied to the moving body (zero when nothing moved).
    pub resolved: Vec2,
}

/// A body removed this frame, as it was just before removal.
#[derive(Clone, Debug, PartialEq)]
pub struct RemovedBody {
    /// Its id.
    pub entity: Entity,
    /// Name.
    pub name: String,
    /// Layer.
    pub layer: LayerId,
    /// Shape.
    pub shape: Shape,
    /// Pose.
    pub pose: Pose,
    /// Velocity.
    pub velocity: Vec2,
    /// Angular velocity, radians per second.
    pub angular_velocity: f64,
    /// Kind.
    pub kind: BodyKind,
}

/// Deterministic per-frame counters (no timings: those differ run to run).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Stats {
    /// Bodies alive at the end of the frame.
    pub bodies: usize,
    /// The broad phase `detect` ran (what `auto` chose), or `None` when it did not run.
    pub broad_phase: Option<BroadPhaseKind>,
    /// Candidate pairs the broad phase found that `detect` kept for the narrow phase (bounds
    /// overlap, layers interact, not both at rest, not two boxes settled per axis).
    pub broad_pairs: u64,
    /// Exact narrow-phase tests run.
    pub narrow_tests: u64,
    /// Contacts recorded.
    pub contacts: u64,
    /// Layer combinations present in the scene (moving with moving, a layer with itself,
    /// moving with static) that the broad phase never looked at because they `ignore` each
    /// other: no body pair of theirs is ever formed.
    pub layer_pairs_skipped: u64,
    /// Moving bodies frozen outside the active region this frame.
    pub frozen: usize,
    /// Bodies asleep at the end of the frame.
    pub asleep: usize,
    /// Stages run.
    pub stages_run: StageSet,
    /// Stages skipped because the scene had nothing for them.
    pub stages_skipped: StageSet,
    /// Narrow-phase tests per layer pair `(a, b)` with `a <= b`, sorted by the pair, only
    /// pairs with tests.
    pub tests_by_layer_pair: Vec<((LayerId, LayerId), u64)>,
    /// Kinetic energy of the dynamic bodies at the end of the frame.
    pub kinetic_energy: f64,
}

/// Everything one frame produced.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameOutput {
    /// Frame number (0 is the initial state).
    pub frame: u64,
    /// Contacts in detection order: the x pass, the y pass, then the full pass, each sorted
    /// by `(a, b)`.
    pub contacts: Vec<ContactRecord>,
    /// Events in the order they happened.
    pub events: Vec<GameEvent>,
    /// Bodies removed this frame.
    pub removed: Vec<RemovedBody>,
    /// Counters.
    pub stats: Stats,
    /// Every body's pose at the start of the `detect` pass, in id order, when
    /// [`crate::Simulation::capture_detect_poses`] is on (for the rapier referee).
    pub detect_poses: Option<Vec<(Entity, Pose)>>,
}
