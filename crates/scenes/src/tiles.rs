//! Test scenes of static tiles and moving bodies that `separate` from them under gravity: the
//! platformer physics the simulation tests share (a floor, walls, boxes and balls), built in
//! code.
//!
//! ```
//! use ricochet_scenes::tiles::Tiles;
//! let scene = Tiles::new("box", -20.0)
//!     .tile("floor", [10.0, 1.0], [0.0, -1.0])
//!     .aabb("box", [0.5, 0.5], [0.3, 3.0])
//!     .scenario();
//! assert_eq!(scene.world.layers.names(), ["tile", "box"]);
//! ```

use ricochet_geom::{Shape, Vec2};
use ricochet_sim::{BodyDef, BodyKind, Event, LayerId, Response, Scenario, WorldDef};

use crate::{layers, scenario};

/// The tiles' layer.
pub const TILE: LayerId = 0;
/// The moving bodies' layer.
pub const MOVER: LayerId = 1;

/// A scene under construction: layers `tile` and one layer of moving bodies, movers
/// `separate` from tiles, 60 Hz, 600 frames, gravity `(0, g)`.
#[derive(Clone, Debug)]
pub struct Tiles {
    scenario: Scenario,
}

impl Tiles {
    /// An empty scene whose moving bodies are on layer `mover` (`box`, `ball`, ...).
    #[must_use]
    pub fn new(mover: &str, g: f64) -> Tiles {
        let world = WorldDef {
            gravity: Vec2::new(0.0, g),
            layers: layers(&["tile", mover], &[(MOVER, TILE, Response::Separate)]),
            ..WorldDef::default()
        };
        Tiles {
            scenario: scenario("tiles", world, Vec::new(), 600),
        }
    }

    /// Moving bodies `separate` from each other too.
    #[must_use]
    pub fn solid(mut self) -> Tiles {
        self.scenario
            .world
            .layers
            .set(MOVER, MOVER, Response::Separate);
        self
    }

    /// Bodies resting on static geometry this long fall asleep (`[world] sleep_after`).
    #[must_use]
    pub fn sleep_after(mut self, frames: Option<u32>) -> Tiles {
        self.scenario.world.sleep_after = frames;
        self
    }

    /// A static AABB tile of half extents `half` centred at `at`.
    #[must_use]
    pub fn tile(self, name: &str, half: [f64; 2], at: [f64; 2]) -> Tiles {
        let shape = Shape::aabb(Vec2::from(half)).expect("positive half extents");
        self.body(name, shape, at).with(|b| {
            b.layer = TILE;
            b.kind = BodyKind::Static;
        })
    }

    /// A dynamic AABB box of half extents `half` centred at `at`.
    #[must_use]
    pub fn aabb(self, name: &str, half: [f64; 2], at: [f64; 2]) -> Tiles {
        let shape = Shape::aabb(Vec2::from(half)).expect("positive half extents");
        self.body(name, shape, at)
    }

    /// A dynamic ball of `radius` centred at `at`.
    #[must_use]
    pub fn ball(self, name: &str, radius: f64, at: [f64; 2]) -> Tiles {
        let shape = Shape::circle(radius).expect("a positive radius");
        self.body(name, shape, at)
    }

    /// A dynamic body of any shape on the movers' layer.
    #[must_use]
    pub fn body(mut self, name: &str, shape: Shape, at: [f64; 2]) -> Tiles {
        self.scenario.bodies.push(BodyDef {
            name: name.to_owned(),
            layer: MOVER,
            shape,
            position: Vec2::from(at),
            ..BodyDef::default()
        });
        self
    }

    /// Changes the body added last (its velocity, gravity scale, ...).
    #[must_use]
    pub fn with(mut self, change: impl FnOnce(&mut BodyDef)) -> Tiles {
        if let Some(b) = self.scenario.bodies.last_mut() {
            change(b);
        }
        self
    }

    /// Adds a script event.
    #[must_use]
    pub fn event(mut self, event: Event) -> Tiles {
        self.scenario.script.push(event);
        self
    }

    /// The finished scenario.
    #[must_use]
    pub fn scenario(self) -> Scenario {
        self.scenario
    }
}
