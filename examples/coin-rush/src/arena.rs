//! The arena, built in code: its layers, tiles, the moving platform and where coins and
//! runners go. Every number a test checks is one of these constants (units are tiles: a
//! tile is a 1 × 1 box; speeds in units/s, at 60 frames a second).
//!
//! ```text
//!  wall                                                              wall
//!   |   [c0]                                                  [c1]   |
//!   |  ledge (-15..-11, top 5.5)        [c2]          ledge (10..14)  |
//!   |                           ==platform== (top 3.25, x -5..5)      |
//!   |          [c3]      s3          s1     s2      [c4]              |
//!   +-------------------------- floor (top 0.5) ----------------------+
//! ```
//!
//! Reaching things: a runner jumps at 15 units/s against gravity 30, so its feet rise
//! 15² / (2 · 30) = 3.75: from the floor (0.5) to 4.25, short of the ledges (5.5) and of
//! the coin above the platform (its bottom at 6.65); from the platform (3.25) to 7.0.

use ricochet_sim::prelude::*;

use crate::ZAP_WINDOW;

/// The runners' layer.
pub const RUNNER: LayerId = 0;
/// The tiles (floor, walls, ledges).
pub const GROUND: LayerId = 1;
/// The moving platform.
pub const PLATFORM: LayerId = 2;
/// The coins: sensors that report a runner's touch and push nothing.
pub const COIN: LayerId = 3;

/// Gravity, units/s² (down).
pub const GRAVITY: f64 = 30.0;
/// A tile's half extent.
pub const TILE_HALF: f64 = 0.5;
/// The floor: its first tile's centre, and count (x = -16 to 15, top at y = 0.5).
pub const FLOOR: (Vec2, u32) = (Vec2::new(-16.0, 0.0), 32);
/// The walls: their bottom tiles' centres (columns of [`WALL_TILES`] from y = 1 up).
pub const WALLS: [Vec2; 2] = [Vec2::new(-17.0, 1.0), Vec2::new(16.0, 1.0)];
/// Tiles in each wall.
pub const WALL_TILES: u32 = 10;
/// The ledges: each one's first tile and count (tops at y = 5.5).
pub const LEDGES: [(Vec2, u32); 2] = [(Vec2::new(-15.0, 5.0), 5), (Vec2::new(10.0, 5.0), 5)];
/// Every tile in the arena.
pub const TILES: u32 = FLOOR.1 + 2 * WALL_TILES + LEDGES[0].1 + LEDGES[1].1;

/// The platform's half extents (4 wide, half a tile thick).
pub const PLATFORM_HALF: Vec2 = Vec2::new(2.0, 0.25);
/// The platform's centre at frame 0 (top at y = 3.25).
pub const PLATFORM_START: Vec2 = Vec2::new(0.0, 3.0);
/// How far the platform moves in a frame (3 units/s).
pub const PLATFORM_STEP: f64 = 0.05;
/// Frames in one of the platform's round trips (right 5, left 10, right 5).
pub const PLATFORM_PERIOD: u64 = 400;

/// A runner's half extents (0.8 × 1).
pub const RUNNER_HALF: Vec2 = Vec2::new(0.4, 0.5);
/// A runner's speed at full input, units/s.
pub const RUN_SPEED: f64 = 6.0;
/// A runner's jump speed, units/s.
pub const JUMP_SPEED: f64 = 15.0;
/// Where runners appear, by join order (the player numbered `n` at `SPAWNS[(n - 1) % 4]`):
/// standing on the floor (centre 0.5 above its top).
pub const SPAWNS: [Vec2; 4] = [
    Vec2::new(-4.0, 1.0),
    Vec2::new(4.0, 1.0),
    Vec2::new(-12.0, 1.0),
    Vec2::new(12.0, 1.0),
];

/// A coin's radius.
pub const COIN_RADIUS: f64 = 0.35;
/// The coins: on the left ledge, on the right ledge, above the platform's middle (reached
/// only by a jump from the platform), and two on the floor.
pub const COINS: [Vec2; 5] = [
    Vec2::new(-13.0, 6.3),
    Vec2::new(12.0, 6.3),
    Vec2::new(0.0, 7.0),
    Vec2::new(-8.0, 1.3),
    Vec2::new(8.0, 1.3),
];

/// What went wrong building the arena (never, with these constants; a game built on the
/// API still says so rather than panic).
#[derive(Debug, thiserror::Error)]
pub enum ArenaError {
    /// A shape was refused.
    #[error(transparent)]
    Shape(#[from] ShapeError),
    /// The world or a body was refused.
    #[error(transparent)]
    Control(#[from] ControlError),
    /// The history a zap needs was refused.
    #[error(transparent)]
    History(#[from] HistoryError),
}

/// The arena's bodies that the game keeps track of.
pub struct Arena {
    /// The simulation, nothing stepped yet.
    pub sim: Simulation,
    /// The moving platform.
    pub platform: Entity,
    /// The coins, in [`COINS`] order.
    pub coins: [Entity; 5],
}

/// Builds the arena at frame 0: tiles, the platform and every coin.
pub fn build() -> Result<Arena, ArenaError> {
    let mut layers = Layers::new(
        ["runner", "ground", "platform", "coin"]
            .map(str::to_owned)
            .to_vec(),
    );
    layers.set(RUNNER, GROUND, Response::Separate);
    layers.set(RUNNER, PLATFORM, Response::Separate);
    layers.set(RUNNER, COIN, Response::Report);
    // Standing on the ground is not news: only a coin's touches are events.
    layers.set_touches(RUNNER, GROUND, false);
    layers.set_touches(RUNNER, PLATFORM, false);
    let mut sim = Simulation::from_def(WorldDef {
        gravity: Vec2::new(0.0, -GRAVITY),
        layers,
        ..WorldDef::default()
    })?;
    // A zap is checked against the frame its player saw: one of the last ZAP_WINDOW.
    sim.keep_history(ZAP_WINDOW as usize)?;
    let tile = Shape::aabb(Vec2::splat(TILE_HALF))?;
    sim.spawn_tiles(&TileRows {
        name: "floor".into(),
        layer: GROUND,
        shape: tile.clone(),
        step: Vec2::new(1.0, 0.0),
        rows: vec![FLOOR, LEDGES[0], LEDGES[1]],
    });
    sim.spawn_tiles(&TileRows {
        name: "wall".into(),
        layer: GROUND,
        shape: tile,
        step: Vec2::new(0.0, 1.0),
        rows: WALLS.iter().map(|&w| (w, WALL_TILES)).collect(),
    });
    let platform = sim.spawn(&BodyDef {
        name: "platform".into(),
        layer: PLATFORM,
        kind: BodyKind::Kinematic,
        shape: Shape::aabb(PLATFORM_HALF)?,
        position: PLATFORM_START,
        ..BodyDef::default()
    });
    let mut coins = [platform; 5];
    for (slot, &at) in coins.iter_mut().zip(COINS.iter()) {
        *slot = sim.spawn(&coin(at)?);
    }
    Ok(Arena {
        sim,
        platform,
        coins,
    })
}

/// A coin at `at`: a static sensor.
pub fn coin(at: Vec2) -> Result<BodyDef, ShapeError> {
    Ok(BodyDef {
        name: "coin".into(),
        layer: COIN,
        kind: BodyKind::Static,
        shape: Shape::circle(COIN_RADIUS)?,
        position: at,
        ..BodyDef::default()
    })
}

/// A runner for the player named `name`, at `at`.
pub fn runner(name: &str, at: Vec2) -> Result<BodyDef, ShapeError> {
    Ok(BodyDef {
        name: name.to_owned(),
        layer: RUNNER,
        shape: Shape::aabb(RUNNER_HALF)?,
        position: at,
        controller: Some(Controller::Runner {
            run_speed: RUN_SPEED,
            jump_speed: JUMP_SPEED,
        }),
        ..BodyDef::default()
    })
}

/// Where the platform is at the end of `frame`: from its start, right 5 units over 100
/// frames, left 10 over 200, right 5 over 100 (a triangle wave of period
/// [`PLATFORM_PERIOD`]).
#[must_use]
pub fn platform_x(frame: u64) -> f64 {
    // Below PLATFORM_PERIOD (400): fits an i32.
    let phase = i32::try_from(frame % PLATFORM_PERIOD).unwrap_or(0);
    let steps = if phase < 100 {
        phase
    } else if phase < 300 {
        200 - phase
    } else {
        phase - 400
    };
    PLATFORM_START.x + f64::from(steps) * PLATFORM_STEP
}
