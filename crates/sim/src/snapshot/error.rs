//! What can be wrong with a snapshot's bytes, or with restoring one.

/// Why [`crate::Snapshot::from_bytes`] refused some bytes, or [`crate::Simulation::restore`]
/// a snapshot. Never a panic: every truncation or bit flip of [`crate::Snapshot::to_bytes`]
/// is one of these.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum SnapshotError {
    /// The bytes do not start with the snapshot magic (`RCSN`): not a snapshot.
    #[error("not a Ricochet snapshot (bad magic)")]
    BadMagic,
    /// Written by another version of the format.
    #[error("snapshot format version {found}, this build reads version {expected}")]
    Version {
        /// The version in the bytes.
        found: u32,
        /// [`crate::SNAPSHOT_VERSION`].
        expected: u32,
    },
    /// Fewer bytes than the snapshot says it has (or than its header needs).
    #[error("snapshot truncated: {found} bytes, {needed} needed")]
    Truncated {
        /// Bytes needed.
        needed: u64,
        /// Bytes given.
        found: u64,
    },
    /// The bytes' checksum does not match them: they were damaged.
    #[error("snapshot checksum mismatch: the bytes were damaged")]
    Checksum,
    /// Checksummed bytes that do not describe a state (a field out of range, an entity out of
    /// order, bytes left over): what is wrong, and where in the state.
    #[error("malformed snapshot: {what}")]
    Malformed {
        /// What is wrong, naming the field.
        what: String,
    },
    /// The snapshot was taken of another scene (another world definition, templates or
    /// script, or another initial set of bodies) than the simulation's.
    #[error(
        "snapshot of another scene: scene {snapshot_scene:016x}, the simulation runs {scene:016x}"
    )]
    OtherScene {
        /// The hash of the snapshot's scene definition.
        snapshot_scene: u64,
        /// The hash of the simulation's scene definition.
        scene: u64,
    },
}

impl SnapshotError {
    /// A [`SnapshotError::Malformed`] naming `what`.
    pub(crate) fn malformed(what: impl Into<String>) -> SnapshotError {
        SnapshotError::Malformed { what: what.into() }
    }
}
