//! Ricochet's side of a contact-set comparison with another engine (rapier here, Box2D in
//! `ricochet-box2d`): one frame's contact records, grouped by pair.

use std::collections::{BTreeMap, BTreeSet};

use ricochet_sim::{ContactRecord, Entity, FrameOutput, Phase, Response, SLOP, Simulation};

/// A pair of bodies, `a < b`, as contact records name them.
pub type Pair = (Entity, Entity);

/// One frame's contact records by pair.
#[derive(Clone, Debug, Default)]
pub struct FramePairs {
    /// Pairs logged at both bodies' end-of-frame poses (what another engine sees after
    /// stepping to them), with the deepest depth logged.
    pub at_end: BTreeMap<Pair, f64>,
    /// Pairs with a swept record (a hit during the frame's motion): another engine may see
    /// them penetrate at the end of the frame without a record there.
    pub swept: BTreeSet<Pair>,
    /// Pairs with a record at other poses (a per-axis pass, a swept hit, an image through the
    /// wrap seam).
    pub elsewhere: BTreeSet<Pair>,
    /// Records left out because a body wrapped round the world this frame (another engine
    /// moved it across the world, not through the seam).
    pub excluded: u64,
}

impl FramePairs {
    /// Groups `out`'s records; `other_poses` hears each record that is not at the
    /// end-of-frame poses (and not excluded), in log order.
    pub fn of(
        sim: &Simulation,
        out: &FrameOutput,
        mut other_poses: impl FnMut(&ContactRecord),
    ) -> FramePairs {
        let w = sim.world();
        let end_pose = |e: Entity| w.index_of(e).map(|i| w.pose(i));
        let at_end =
            |c: &ContactRecord| end_pose(c.a) == Some(c.pose_a) && end_pose(c.b) == Some(c.pose_b);
        let mut pairs = FramePairs::default();
        for c in &out.contacts {
            let key = (c.a, c.b);
            // One-way platforms: rapier never pairs them (`pairs.rs`), so neither does this.
            if wrapped(sim, c.a) || wrapped(sim, c.b) || matches!(c.response, Response::OneWay(_)) {
                pairs.excluded += 1;
                continue;
            }
            if c.phase == Phase::Swept {
                pairs.swept.insert(key);
            }
            if at_end(c) {
                let depth = pairs.at_end.entry(key).or_insert(f64::NEG_INFINITY);
                *depth = depth.max(c.depth);
            } else {
                pairs.elsewhere.insert(key);
                other_poses(c);
            }
        }
        pairs
    }
}

/// Whether body `e` wrapped round a wrapping world this frame (it moved more than half the
/// world along an axis).
#[must_use]
pub fn wrapped(sim: &Simulation, e: Entity) -> bool {
    let w = sim.world();
    let (Some(b), Some(i)) = (sim.scenario().world.bounds, w.index_of(e)) else {
        return false;
    };
    let size = b.max - b.min;
    let moved = (w.position[i] - w.start_position(i)).abs();
    b.wrap && (moved.x > 0.5 * size.x || moved.y > 0.5 * size.y)
}

/// The depth at which a response starts: `SLOP` for `separate` (the per-axis passes leave
/// boxes flush, a push leaves at most `SLOP`), 0 otherwise.
#[must_use]
pub fn threshold(response: Response) -> f64 {
    if response == Response::Separate {
        SLOP
    } else {
        0.0
    }
}
