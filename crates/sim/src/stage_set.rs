//! The stages by name, and sets of them: which stages a frame ran or skipped, kept as a
//! bitmask so that recording them costs nothing per frame.

/// A stage of the pipeline, in pipeline order (see [`crate::Simulation`]'s module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Stage {
    /// This frame's script events.
    Script,
    /// Freeze the moving bodies outside the active region.
    Cull,
    /// Clear `grounded`.
    Unground,
    /// Controllers turn inputs into velocities.
    Controls,
    /// `v += a dt`.
    Forces,
    /// Riders carried by their carrier's `vx dt`, then `x += vx dt`.
    MoveX,
    /// Per-axis separation along x.
    ResolveX,
    /// Riders carried by their carrier's `vy dt`, then `y += vy dt`.
    MoveY,
    /// Per-axis separation along y.
    ResolveY,
    /// `angle += ω dt`.
    Turn,
    /// Broad phase, narrow phase and responses.
    Detect,
    /// Count down lifetimes.
    Lifetimes,
    /// Wrap around or leave the world.
    Bounds,
    /// Put resting bodies to sleep.
    Sleep,
    /// Which pairs touch; begin and end touch events.
    Touch,
}

impl Stage {
    /// Every stage, in pipeline order.
    pub const ALL: [Stage; 15] = [
        Stage::Script,
        Stage::Cull,
        Stage::Unground,
        Stage::Controls,
        Stage::Forces,
        Stage::MoveX,
        Stage::ResolveX,
        Stage::MoveY,
        Stage::ResolveY,
        Stage::Turn,
        Stage::Detect,
        Stage::Lifetimes,
        Stage::Bounds,
        Stage::Sleep,
        Stage::Touch,
    ];

    /// The name logs use (`"move_x"`).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Stage::Script => "script",
            Stage::Cull => "cull",
            Stage::Unground => "unground",
            Stage::Controls => "controls",
            Stage::Forces => "forces",
            Stage::MoveX => "move_x",
            Stage::ResolveX => "resolve_x",
            Stage::MoveY => "move_y",
            Stage::ResolveY => "resolve_y",
            Stage::Turn => "turn",
            Stage::Detect => "detect",
            Stage::Lifetimes => "lifetimes",
            Stage::Bounds => "bounds",
            Stage::Sleep => "sleep",
            Stage::Touch => "touch",
        }
    }

    /// The stage's bit in a [`StageSet`].
    fn bit(self) -> u16 {
        1 << self as u16
    }
}

/// A set of stages, iterated in pipeline order.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StageSet(u16);

impl StageSet {
    /// No stage.
    pub const EMPTY: StageSet = StageSet(0);

    /// Adds `stage`.
    pub fn insert(&mut self, stage: Stage) {
        self.0 |= stage.bit();
    }

    /// Whether `stage` is in the set.
    #[must_use]
    pub fn contains(self, stage: Stage) -> bool {
        self.0 & stage.bit() != 0
    }

    /// How many stages are in the set.
    #[must_use]
    pub fn len(self) -> usize {
        self.0.count_ones() as usize
    }

    /// Whether the set is empty.
    #[must_use]
    pub fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// The stages in the set, in pipeline order.
    pub fn iter(self) -> impl Iterator<Item = Stage> {
        Stage::ALL.into_iter().filter(move |s| self.contains(*s))
    }
}

impl FromIterator<Stage> for StageSet {
    fn from_iter<I: IntoIterator<Item = Stage>>(iter: I) -> StageSet {
        let mut set = StageSet::EMPTY;
        for s in iter {
            set.insert(s);
        }
        set
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_set_iterates_in_pipeline_order() {
        let set: StageSet = [Stage::Sleep, Stage::Script, Stage::Detect]
            .into_iter()
            .collect();
        assert_eq!(set.len(), 3);
        assert!(set.contains(Stage::Detect) && !set.contains(Stage::Cull));
        let names: Vec<&str> = set.iter().map(Stage::name).collect();
        assert_eq!(names, ["script", "detect", "sleep"]);
        assert_eq!(
            Stage::ALL.iter().map(|s| s.bit()).fold(0, |a, b| a | b),
            0x7fff
        );
    }
}
