//! Snapshots: the state a step reads, as bytes, and a checksum of it.
//!
//! (Stub: the format and the field table follow in the next commits.)

mod error;

pub use error::SnapshotError;

use crate::pipeline::Simulation;

/// The version of the snapshot format [`Snapshot::to_bytes`] writes and
/// [`Snapshot::from_bytes`] reads.
pub const SNAPSHOT_VERSION: u32 = 1;

/// A simulation's state between two steps ([`Simulation::snapshot`]), restored with
/// [`Simulation::restore`] onto a simulation of the same scene.
#[derive(Clone, Debug)]
pub struct Snapshot {
    /// [`Simulation::frame`] when it was taken.
    frame: u64,
    /// The hash of the scene definition (world, templates, script).
    scene: u64,
    /// The hash of the bodies at the start of the run the state is told against (0: none).
    start: u64,
    /// The encoded state.
    payload: Vec<u8>,
}

impl Snapshot {
    /// The frame the next step of a simulation restored from it runs: [`Simulation::frame`]
    /// when it was taken.
    #[must_use]
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// The snapshot as bytes: versioned, with a checksum of the bytes.
    #[must_use]
    pub fn to_bytes(&self) -> Vec<u8> {
        let _ = (self.scene, self.start, &self.payload);
        todo!("snapshot bytes")
    }

    /// A snapshot from [`Snapshot::to_bytes`]'s bytes.
    ///
    /// # Errors
    /// Any damage: another magic, version, a truncation, a checksum mismatch, a state that
    /// does not hold together. Never a panic.
    pub fn from_bytes(bytes: &[u8]) -> Result<Snapshot, SnapshotError> {
        let _ = bytes;
        todo!("snapshot parse")
    }
}

impl Simulation {
    /// The state the next step reads, and the game's user data.
    #[must_use]
    pub fn snapshot(&self) -> Snapshot {
        todo!("snapshot")
    }

    /// Puts the simulation back in the state of `s`.
    ///
    /// # Errors
    /// [`SnapshotError::OtherScene`] for a snapshot of another scene.
    pub fn restore(&mut self, s: &Snapshot) -> Result<(), SnapshotError> {
        let _ = s;
        todo!("restore")
    }

    /// A checksum of exactly the state a step reads.
    #[must_use]
    pub fn checksum(&self) -> u64 {
        todo!("checksum")
    }
}
