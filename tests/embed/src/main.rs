//! A program written as a newcomer would, from README's "Embed the simulation in a game"
//! and the `ricochet-sim` docs alone, with `ricochet-sim` as its one dependency: a
//! platformer with tiles and a moving platform (`level.rs`), and checks that the player
//! rides it, that a ray cast down from the player hits what exact geometry says at the
//! distance it says, and that a snapshot taken at frame 300, restored after 100 more
//! frames, steps to the same checksum and the same outputs.
//!
//! Every expected value is geometry worked out by hand from the level's constants (a ray
//! straight down meets a box's top face at `y_centre + half_height`), never a value this
//! program read earlier from the simulation and pasted in. `cargo run -p ricochet-embed`
//! prints a line per check and exits 1 if any failed; `cargo test -p ricochet-embed` runs
//! the same checks as a test.

mod level;

use level::{
    GROUND, GROUND_START, GROUND_TILES, JUMP_FRAME, LEDGE_TILES, Level, PLATFORM_HALF,
    PLATFORM_STEP, PLAYER_HALF, TILE_HALF, platform_x,
};
use ricochet_sim::prelude::*;

/// What a check found wrong.
type Outcome = Result<(), String>;

/// Exact sums of a few terms of size ~10 differ from their rounded float value by a few
/// ulps (about 1e-15 each): far below this, far above 0.
const ROUNDING: f64 = 1e-12;

/// Fails with `what` unless `got` is within [`ROUNDING`] of `want`.
fn near(what: &str, got: f64, want: f64) -> Outcome {
    if (got - want).abs() <= ROUNDING {
        Ok(())
    } else {
        Err(format!("{what}: {got}, expected {want}"))
    }
}

/// Fails with `what` unless `ok`.
fn ensure(ok: bool, what: impl FnOnce() -> String) -> Outcome {
    if ok { Ok(()) } else { Err(what()) }
}

/// The level stepped through frame `frame - 1`: the next step runs `frame`.
fn level_at(frame: u64) -> Result<Level, String> {
    let mut level = Level::new().map_err(|e| e.to_string())?;
    while level.sim.frame() < frame {
        level.step().map_err(|e| e.to_string())?;
    }
    Ok(level)
}

/// The tiles of the map, in spawn order: 20 ground tiles, then 3 on the ledge.
fn tiles_are_spawned_in_order() -> Outcome {
    let level = Level::new().map_err(|e| e.to_string())?;
    let count = usize::try_from(GROUND_TILES + LEDGE_TILES).map_err(|e| e.to_string())?;
    ensure(level.tiles.len() == count, || {
        format!("{} tiles, expected {count}", level.tiles.len())
    })?;
    for (k, &tile) in level.tiles.iter().enumerate() {
        // Ids in spawn order (the lowest free id each), each tile static.
        ensure(tile.index as usize == k, || format!("tile {k} is {tile}"))?;
        ensure(level.sim.kind(tile) == Some(BodyKind::Static), || {
            format!("tile {k} is not static")
        })?;
    }
    // The 6th ground tile is 5 units right of the first.
    let at = level.sim.position(level.tiles[5]);
    ensure(at == Some(GROUND_START + Vec2::new(5.0, 0.0)), || {
        format!("tile 5 at {at:?}")
    })
}

/// The player stands on the platform and is carried by it, frame after frame: it moves
/// by what the platform moves, its bottom stays on the platform's top.
fn the_player_rides_the_platform() -> Outcome {
    let mut level = level_at(2)?; // frame 1 found what it stands on: carried from frame 2
    let (platform, player) = (level.platform, level.player);
    // It started centred on the platform; the platform's move of frame 1 went without it
    // (`carrier` is what held it up in the last step, and frame 0 moves nothing).
    let offset = -PLATFORM_STEP;
    // 200 frames: right, then left past the start (the platform turns at frames 60, 180).
    for _ in 0..200 {
        let frame = level.sim.frame();
        level.step().map_err(|e| e.to_string())?;
        let when = format!("frame {frame}");
        let p = level.sim.position(platform).ok_or("the platform is gone")?;
        let q = level.sim.position(player).ok_or("the player is gone")?;
        near(&format!("{when}: platform x"), p.x, platform_x(frame))?;
        near(&format!("{when}: player x - platform x"), q.x - p.x, offset)?;
        let feet = q.y - PLAYER_HALF.y;
        near(
            &format!("{when}: feet on the platform's top"),
            feet,
            p.y + PLATFORM_HALF.y,
        )?;
        let carrier = level.sim.carrier(player);
        ensure(carrier == Some(Some(platform)), || {
            format!("{when}: carried by {carrier:?}")
        })?;
        ensure(level.sim.grounded(player) == Some(true), || {
            format!("{when}: not grounded")
        })?;
    }
    Ok(())
}

/// A ray straight down from the player's centre, the player left out, hits the platform's
/// top at `player.y - (platform.y + 0.25)`; one that sees only the ground layer goes
/// through the platform to the tile below, at `player.y - 0.5`; a ray shorter than that
/// hits nothing.
fn a_ray_down_from_the_player_hits_at_the_exact_distance() -> Outcome {
    let level = level_at(100)?;
    let sim = &level.sim;
    let q = sim.position(level.player).ok_or("the player is gone")?;
    let p = sim.position(level.platform).ok_or("the platform is gone")?;
    let down = Vec2::new(0.0, -1.0);
    let probe = QueryFilter::all().exclude(level.player);

    let hit = sim
        .cast_ray(q, down, 100.0, &probe)
        .ok_or("the ray hit nothing")?;
    ensure(hit.entity == level.platform, || {
        format!("hit {}, expected the platform", hit.entity)
    })?;
    let top = p.y + PLATFORM_HALF.y;
    near("distance to the platform", hit.distance, q.y - top)?;
    near("hit point x", hit.point.x, q.x)?;
    near("hit point y", hit.point.y, top)?;
    ensure(hit.normal == Vec2::new(0.0, 1.0), || {
        format!("normal {}", hit.normal)
    })?;

    // Through the platform: the ground tile under the player, the one whose centre is
    // nearest its x (tiles are 1 wide, centred on whole numbers from -10).
    let ground = QueryFilter::layers(&[GROUND]);
    let hit = sim
        .cast_ray(q, down, 100.0, &ground)
        .ok_or("the ground ray hit nothing")?;
    let k = (q.x - GROUND_START.x).round();
    ensure(hit.entity.index as f64 == k, || {
        format!("hit {} under x = {}, expected tile {k}", hit.entity, q.x)
    })?;
    near("distance to the ground", hit.distance, q.y - TILE_HALF)?;

    // Shorter than the way down to the platform: a miss.
    let short = (q.y - top) * 0.99;
    ensure(sim.cast_ray(q, down, short, &probe).is_none(), || {
        format!("a ray of {short} hit something")
    })?;
    // And the point under the platform's centre is in the platform and nothing else.
    let inside = sim.overlap_point(p, &QueryFilter::all());
    ensure(inside == [level.platform], || format!("at {p}: {inside:?}"))
}

/// What a run leaves behind: the outputs of each frame, the checksum, the player's pose.
#[derive(Debug, PartialEq)]
struct Run {
    outputs: Vec<FrameOutput>,
    checksum: u64,
    player: Option<Pose>,
}

/// Steps 100 frames from where `level` is.
fn hundred_frames(level: &mut Level) -> Result<Run, String> {
    let mut outputs = Vec::with_capacity(100);
    for _ in 0..100 {
        outputs.push(level.step().map_err(|e| e.to_string())?);
    }
    Ok(Run {
        outputs,
        checksum: level.sim.checksum(),
        player: level.sim.pose(level.player),
    })
}

/// A snapshot at frame 300, as bytes; 100 frames on; restored from the bytes, the same
/// checksum as at frame 300; 100 frames again: the same outputs and the same checksum.
/// The same from the bytes restored onto a level built anew (a peer joining).
fn a_snapshot_at_300_restores_to_the_same_run() -> Outcome {
    let mut level = level_at(300)?;
    let bytes = level.sim.snapshot().to_bytes();
    let at_300 = level.sim.checksum();
    let first = hundred_frames(&mut level)?;
    // The jump is in these 100 frames: the run did something besides riding.
    let jumped = first.outputs.iter().any(|o| {
        o.events.iter().any(|e| {
            matches!(
                e,
                GameEvent::Input {
                    input: ScriptInput::Jump(JumpOutcome::Jumped),
                    ..
                }
            )
        })
    });
    ensure(jumped, || format!("no jump at frame {JUMP_FRAME}"))?;
    ensure(first.checksum != at_300, || {
        "the checksum did not change".into()
    })?;

    let snapshot = Snapshot::from_bytes(&bytes).map_err(|e| e.to_string())?;
    level.sim.restore(&snapshot).map_err(|e| e.to_string())?;
    ensure(level.sim.frame() == 300, || {
        format!("restored at frame {}", level.sim.frame())
    })?;
    ensure(level.sim.checksum() == at_300, || {
        "restored, the checksum differs from frame 300's".into()
    })?;
    let again = hundred_frames(&mut level)?;
    ensure(again == first, || {
        "the restored run stepped differently".into()
    })?;

    let mut peer = Level::new().map_err(|e| e.to_string())?;
    peer.sim.restore(&snapshot).map_err(|e| e.to_string())?;
    let joined = hundred_frames(&mut peer)?;
    ensure(joined == first, || {
        "a new level restored stepped differently".into()
    })
}

/// Damaged bytes are an error, never a panic.
fn damaged_snapshot_bytes_are_an_error() -> Outcome {
    let level = level_at(10)?;
    let mut bytes = level.sim.snapshot().to_bytes();
    ensure(
        Snapshot::from_bytes(&bytes[..bytes.len() / 2]).is_err(),
        || "half the bytes were accepted".into(),
    )?;
    let middle = bytes.len() / 2;
    bytes[middle] ^= 1;
    ensure(Snapshot::from_bytes(&bytes).is_err(), || {
        "a flipped bit was accepted".into()
    })
}

/// A check: its name, and the function.
type Check = (&'static str, fn() -> Outcome);

/// Every check.
const CHECKS: [Check; 5] = [
    ("tiles are spawned in order", tiles_are_spawned_in_order),
    (
        "the player rides the platform",
        the_player_rides_the_platform,
    ),
    (
        "a ray down from the player hits at the exact distance",
        a_ray_down_from_the_player_hits_at_the_exact_distance,
    ),
    (
        "a snapshot at 300 restores to the same run",
        a_snapshot_at_300_restores_to_the_same_run,
    ),
    (
        "damaged snapshot bytes are an error",
        damaged_snapshot_bytes_are_an_error,
    ),
];

/// Runs every check, printing each; how many failed.
fn run_checks() -> usize {
    let mut failed = 0;
    for (name, check) in CHECKS {
        match check() {
            Ok(()) => println!("ok     {name}"),
            Err(why) => {
                failed += 1;
                println!("FAILED {name}: {why}");
            }
        }
    }
    println!("embed: {} passed, {failed} failed", CHECKS.len() - failed);
    failed
}

fn main() -> std::process::ExitCode {
    if run_checks() == 0 {
        std::process::ExitCode::SUCCESS
    } else {
        std::process::ExitCode::FAILURE
    }
}

#[cfg(test)]
mod tests {
    /// `cargo test` counts the program: every check passes.
    #[test]
    fn every_check_passes() {
        assert_eq!(super::run_checks(), 0);
    }
}
