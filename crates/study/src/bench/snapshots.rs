//! `ricochet bench --snapshots`: what a snapshot of a bench scene costs (issue #22). The
//! scene is stepped to `--frames`, its snapshot taken, and 8 frames more stepped (a
//! rollback's distance); then each pass times `snapshot`, `to_bytes`, `from_bytes`,
//! `restore` (back those frames, onto the same bodies: patched in place), `checksum` and a
//! `Simulation` clone. Each figure is the median of the passes. Figures, never assertions.
//! Against rapier's serde snapshot of the same bodies at the same frame
//! ([`ricochet_oracle::bench::rapier_snapshot`]: `bincode` of its `PhysicsWorld`).

use std::fmt::Write as _;
use std::time::Instant;

use anyhow::Context;
use ricochet_oracle::bench::{RapierSnapshot, rapier_snapshot};
use ricochet_scenes::bench::Scene;
use ricochet_sim::{Simulation, Snapshot};

/// Timed passes per scene (each figure is their median).
pub const PASSES: usize = 21;

/// One scene's figures; times in microseconds.
#[derive(Clone, Debug)]
pub struct SnapshotRow {
    /// The scene's name.
    pub scene: String,
    /// The frame the snapshot was taken at.
    pub frame: u64,
    /// Bodies in the world.
    pub bodies: usize,
    /// Moving (dynamic and kinematic) bodies.
    pub moving: usize,
    /// `to_bytes`' length.
    pub bytes: usize,
    /// `Simulation::snapshot`.
    pub snapshot_us: f64,
    /// `Snapshot::to_bytes`.
    pub to_bytes_us: f64,
    /// `Snapshot::from_bytes`.
    pub from_bytes_us: f64,
    /// `Simulation::restore`.
    pub restore_us: f64,
    /// The four above, each pass's sum.
    pub round_trip_us: f64,
    /// `Simulation::checksum`.
    pub checksum_us: f64,
    /// `Simulation::clone`.
    pub clone_us: f64,
    /// rapier's snapshot of the same bodies.
    pub rapier: RapierSnapshot,
}

impl SnapshotRow {
    /// Bytes per moving body.
    #[must_use]
    pub fn bytes_per_moving(&self) -> f64 {
        self.bytes as f64 / self.moving.max(1) as f64
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Microseconds `f` took, and what it returned.
fn timed<T>(f: impl FnOnce() -> T) -> (f64, T) {
    let t = Instant::now();
    let x = std::hint::black_box(f());
    (t.elapsed().as_secs_f64() * 1e6, x)
}

/// Measures `scene` snapshotted at frame `frames` (see the module docs).
///
/// # Errors
/// A snapshot that does not read back or restore (a bug: the figures would mean nothing).
pub fn run_snapshots(name: &str, scene: Scene, frames: u64) -> anyhow::Result<SnapshotRow> {
    let mut sim = Simulation::from_scenario(scene.build(frames + 8));
    for _ in 0..frames {
        drop(sim.step());
    }
    let rapier =
        rapier_snapshot(&sim, PASSES).with_context(|| format!("{name}: rapier's snapshot"))?;
    let at = sim.snapshot();
    let bytes = at.to_bytes().len();
    let sum = sim.checksum();
    for _ in 0..8 {
        drop(sim.step());
    }
    let mut t: [Vec<f64>; 7] = Default::default();
    for _ in 0..PASSES {
        let (a, s) = timed(|| sim.snapshot());
        let (b, bytes) = timed(|| s.to_bytes());
        let (c, back) = timed(|| Snapshot::from_bytes(&bytes));
        let back = back.with_context(|| format!("{name}: reading the snapshot back"))?;
        let (d, restored) = timed(|| sim.restore(&at));
        restored.with_context(|| format!("{name}: restoring the snapshot"))?;
        drop(back);
        let (e, got) = timed(|| sim.checksum());
        anyhow::ensure!(got == sum, "{name}: the restored checksum differs");
        let (f, copy) = timed(|| sim.clone());
        drop(copy);
        for (k, x) in [a, b, c, d, a + b + c + d, e, f].into_iter().enumerate() {
            t[k].push(x);
        }
    }
    let [a, b, c, d, rt, e, f] = t.map(median);
    Ok(SnapshotRow {
        scene: name.to_owned(),
        frame: frames,
        bodies: sim.world().len(),
        moving: sim.world().movers().len(),
        bytes,
        snapshot_us: a,
        to_bytes_us: b,
        from_bytes_us: c,
        restore_us: d,
        round_trip_us: rt,
        checksum_us: e,
        clone_us: f,
        rapier,
    })
}

/// The table `ricochet bench --snapshots` prints.
#[must_use]
pub fn table(rows: &[SnapshotRow]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{:<20} {:>6} {:>7} {:>7} {:>9} {:>8} {:>9} {:>9} {:>10} {:>9} {:>11} {:>9} {:>9} \
         {:>10} {:>10} {:>10} {:>10}",
        "scene",
        "frame",
        "bodies",
        "moving",
        "bytes",
        "B/moving",
        "snap µs",
        "bytes µs",
        "parse µs",
        "restore µs",
        "round µs",
        "check µs",
        "clone µs",
        "rapier B",
        "B/moving",
        "ser µs",
        "de µs"
    );
    for r in rows {
        let _ = writeln!(
            s,
            "{:<20} {:>6} {:>7} {:>7} {:>9} {:>8.1} {:>9.1} {:>9.1} {:>10.1} {:>9.1} {:>11.1} \
             {:>9.1} {:>9.1} {:>10} {:>10.1} {:>10.1} {:>10.1}",
            r.scene,
            r.frame,
            r.bodies,
            r.moving,
            r.bytes,
            r.bytes_per_moving(),
            r.snapshot_us,
            r.to_bytes_us,
            r.from_bytes_us,
            r.restore_us,
            r.round_trip_us,
            r.checksum_us,
            r.clone_us,
            r.rapier.bytes,
            r.rapier.bytes as f64 / r.moving.max(1) as f64,
            r.rapier.serialize_us,
            r.rapier.deserialize_us
        );
    }
    s
}

/// What the columns mean, printed under the table.
pub const NOTES: &str = "\
bytes: Snapshot::to_bytes at the frame; B/moving: per dynamic or kinematic body. Times: median \
of 21 passes, in microseconds: snapshot, to_bytes (bytes), from_bytes (parse), restore (8 frames \
back, onto the same bodies), their sum (round), checksum, Simulation::clone. rapier: bincode of \
its PhysicsWorld (every set a step reads; dynamic bodies with the same velocities, stepped once): \
bytes, per moving body, serialise and deserialise times. A debug build's times say nothing: \
build with --release.
";
