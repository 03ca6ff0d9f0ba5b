//! The platformer: a tile map, a kinematic platform that the game moves back and forth,
//! and a player (a runner) who starts standing on it. Everything the game does between
//! steps is a function of the frame, so a restored simulation, stepped by the same loop,
//! gets the same inputs.

use ricochet_sim::prelude::*;

/// Layers: the player is pushed out of the ground and of the platform.
pub const PLAYER: LayerId = 0;
/// The tiles.
pub const GROUND: LayerId = 1;
/// The moving platform (a layer of its own, so a probe can see through it).
pub const PLATFORM: LayerId = 2;

/// Gravity, units/s² (down).
pub const GRAVITY: f64 = -30.0;
/// Tiles are 1 × 1 boxes: half extents.
pub const TILE_HALF: f64 = 0.5;
/// The ground row: its first tile's centre (then one every unit to the right) and count.
pub const GROUND_START: Vec2 = Vec2::new(-10.0, 0.0);
/// How many tiles the ground row has (x = -10 to 9, tops at y = 0.5).
pub const GROUND_TILES: u32 = 20;
/// A ledge of 3 tiles above the left end (a second row of the same map).
pub const LEDGE_START: Vec2 = Vec2::new(-10.0, 6.0);
/// Tiles in the ledge.
pub const LEDGE_TILES: u32 = 3;
/// The platform's half extents (4 wide, 0.5 thick) and where it starts.
pub const PLATFORM_HALF: Vec2 = Vec2::new(2.0, 0.25);
/// The platform's start (its top at y = 3.25).
pub const PLATFORM_START: Vec2 = Vec2::new(4.0, 3.0);
/// The player's half extents.
pub const PLAYER_HALF: Vec2 = Vec2::new(0.4, 0.5);
/// How far the platform moves each frame.
pub const PLATFORM_STEP: f64 = 0.05;
/// The frame at which the player jumps (inside the snapshot's 100 frames).
pub const JUMP_FRAME: u64 = 350;

/// A platformer in progress.
pub struct Level {
    /// The simulation.
    pub sim: Simulation,
    /// Every tile, in spawn order: the ground row, then the ledge.
    pub tiles: Vec<Entity>,
    /// The moving platform.
    pub platform: Entity,
    /// The player.
    pub player: Entity,
}

impl Level {
    /// The level at frame 0, nothing stepped yet.
    pub fn new() -> Result<Level, Box<dyn std::error::Error>> {
        let mut layers = Layers::new(vec!["player".into(), "ground".into(), "platform".into()]);
        layers.set(PLAYER, GROUND, Response::Separate);
        layers.set(PLAYER, PLATFORM, Response::Separate);
        let mut sim = Simulation::from_def(WorldDef {
            gravity: Vec2::new(0.0, GRAVITY),
            layers,
            ..WorldDef::default()
        })?;
        let tiles = sim.spawn_tiles(&TileRows {
            name: "tile".into(),
            layer: GROUND,
            shape: Shape::aabb(Vec2::splat(TILE_HALF))?,
            step: Vec2::new(1.0, 0.0),
            rows: vec![(GROUND_START, GROUND_TILES), (LEDGE_START, LEDGE_TILES)],
        });
        let platform = sim.spawn(&BodyDef {
            name: "platform".into(),
            layer: PLATFORM,
            kind: BodyKind::Kinematic,
            shape: Shape::aabb(PLATFORM_HALF)?,
            position: PLATFORM_START,
            ..BodyDef::default()
        });
        // Standing on the platform: its bottom on the platform's top.
        let feet = PLATFORM_START.y + PLATFORM_HALF.y;
        let player = sim.spawn(&BodyDef {
            name: "player".into(),
            layer: PLAYER,
            shape: Shape::aabb(PLAYER_HALF)?,
            position: Vec2::new(PLATFORM_START.x, feet + PLAYER_HALF.y),
            controller: Some(Controller::Runner {
                run_speed: 6.0,
                jump_speed: 12.0,
            }),
            ..BodyDef::default()
        });
        Ok(Level {
            sim,
            tiles,
            platform,
            player,
        })
    }

    /// Sends what the game does in the frame the next step runs, then steps it.
    pub fn step(&mut self) -> Result<FrameOutput, ControlError> {
        let frame = self.sim.frame();
        if frame >= 1 {
            // Frame 0 moves nothing (README): the platform's motion starts at frame 1.
            let target = Vec2::new(platform_x(frame), PLATFORM_START.y);
            self.sim
                .set_target_pose(self.platform, Pose::new(target, 0.0))?;
        }
        if frame == JUMP_FRAME && self.sim.contains(self.player) {
            self.sim.apply(self.player, Action::Jump)?;
        }
        Ok(self.sim.step())
    }
}

/// Where the game puts the platform at the end of `frame`: from its start, 3 units right
/// over 60 frames, 6 left over 120, 3 right over 60, and again (period 240 frames).
#[must_use]
pub fn platform_x(frame: u64) -> f64 {
    let phase = i32::try_from(frame % 240).unwrap_or(0); // always fits
    let steps = if phase < 60 {
        phase
    } else if phase < 180 {
        120 - phase
    } else {
        phase - 240
    };
    PLATFORM_START.x + f64::from(steps) * PLATFORM_STEP
}
