//! Validated definitions: what a scenario file loads into (Box2D's `b2WorldDef` and
//! `b2BodyDef`), each with a `Default`.

use ricochet_geom::{Shape, Vec2};

pub use crate::limits::{
    MAX_CONTROLLER_VALUE, MAX_FRAMES, MAX_MASS, MIN_MASS, RunLengthError, controller_out_of_range,
    shape_reach,
};

/// Index of a layer in [`Layers::names`].
pub type LayerId = u8;

/// How a body moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BodyKind {
    /// Moved by forces, velocity and collision responses.
    Dynamic,
    /// Never moves.
    Static,
    /// Moves at its velocity; never pushed by collisions.
    Kinematic,
}

impl BodyKind {
    /// The name used in scenario files and logs.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            BodyKind::Dynamic => "dynamic",
            BodyKind::Static => "static",
            BodyKind::Kinematic => "kinematic",
        }
    }
}

/// What drives a body besides physics.
#[derive(Clone, Debug, PartialEq)]
pub enum Controller {
    /// Asteroids ship.
    Ship {
        /// Thrust force along the heading.
        thrust: f64,
        /// Turn rate at full input, radians/s.
        turn_rate: f64,
        /// Template name of the bullet.
        bullet: String,
        /// Bullet speed relative to the ship.
        bullet_speed: f64,
        /// Distance ahead of the centre where bullets appear.
        muzzle: f64,
    },
    /// Platformer character.
    Runner {
        /// Horizontal speed at full input.
        run_speed: f64,
        /// Jump speed.
        jump_speed: f64,
    },
    /// Patrols, turning around when bumped along x.
    Walker {
        /// Speed; the sign is the current direction.
        speed: f64,
    },
}

/// A child spawned where a body is destroyed.
#[derive(Clone, Debug, PartialEq)]
pub struct Split {
    /// Template of the child.
    pub template: String,
    /// Offset from the parent's position.
    pub offset: Vec2,
    /// Velocity added to the parent's.
    pub velocity: Vec2,
}

/// Everything needed to create a body.
#[derive(Clone, Debug, PartialEq)]
pub struct BodyDef {
    /// Name, used by script events and shown in logs.
    pub name: String,
    /// Layer.
    pub layer: LayerId,
    /// Collision shape.
    pub shape: Shape,
    /// Dynamic, static or kinematic.
    pub kind: BodyKind,
    /// Mass of a dynamic body (default 1; a scenario file's from [`MIN_MASS`] to
    /// [`MAX_MASS`]; a simulation brings a mass past them to the nearest, and
    /// [`crate::Scenario::check`] and [`crate::Simulation::try_spawn`] refuse it).
    pub mass: f64,
    /// Position.
    pub position: Vec2,
    /// Angle, radians.
    pub angle: f64,
    /// Velocity.
    pub velocity: Vec2,
    /// Angular velocity, radians/s.
    pub angular_velocity: f64,
    /// Constant force.
    pub force: Vec2,
    /// Multiplier of the world gravity (default 1).
    pub gravity_scale: f64,
    /// Frames until removal.
    pub lifetime: Option<u32>,
    /// Input handling.
    pub controller: Option<Controller>,
    /// Children spawned on destruction.
    pub split: Vec<Split>,
    /// The game's own data for this body (rapier's `user_data`, Box2D's `userData`): an id
    /// into the game's tables, say. Kept for the body's whole life, read with
    /// [`crate::Simulation::user_data`], changed with [`crate::Simulation::set_user_data`];
    /// no stage reads it, and no log holds it. Default 0. A template's is given to each
    /// body spawned from it (a ship's bullets, a split's children).
    pub user_data: u128,
}

impl Default for BodyDef {
    fn default() -> Self {
        BodyDef {
            name: "body".to_owned(),
            layer: 0,
            shape: Shape::circle(0.5).expect("a positive radius is valid"),
            kind: BodyKind::Dynamic,
            mass: 1.0,
            position: Vec2::ZERO,
            angle: 0.0,
            velocity: Vec2::ZERO,
            angular_velocity: 0.0,
            force: Vec2::ZERO,
            gravity_scale: 1.0,
            lifetime: None,
            controller: None,
            split: Vec::new(),
            user_data: 0,
        }
    }
}

/// Which body a `destroy` response removes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Doomed {
    /// The body in the first layer of the pair.
    First,
    /// The body in the second layer.
    Second,
    /// Both.
    Both,
}

/// What happens when two layers' bodies overlap.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Response {
    /// Never tested.
    Ignore,
    /// Logged, and the game gets an event.
    Report,
    /// One or both removed (children of a split spawned).
    Destroy(Doomed),
    /// Pushed apart: per axis for boxes, along the normal otherwise.
    Separate,
    /// A one-way platform (`one_way` in a `[[collide]]` entry, the second layer the
    /// platform's): solid only to a dynamic body that was above the platform's top at the
    /// start of the step and is not moving up relative to it; passed through otherwise
    /// (`stages/one_way.rs`).
    OneWay(Platform),
}

/// Which body of a [`Response::OneWay`] pair is the platform.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Platform {
    /// The body in the first layer of the pair.
    First,
    /// The body in the second layer.
    Second,
}

impl Response {
    /// The name used in scenario files and logs.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Response::Ignore => "ignore",
            Response::Report => "report",
            Response::Destroy(_) => "destroy",
            Response::Separate => "separate",
            Response::OneWay(_) => "one_way",
        }
    }
}

/// Layer names and the symmetric layer-pair response matrix.
#[derive(Clone, Debug, PartialEq)]
pub struct Layers {
    names: Vec<String>,
    /// `matrix[a * n + b]`: the response when a body of layer `a` meets one of layer `b`,
    /// with `Doomed` relative to `(a, b)`.
    matrix: Vec<Response>,
    /// `sweep[a * n + b]`: whether the pair is tested along the frame's whole motion (time
    /// of impact) instead of only at the end of it.
    sweep: Vec<bool>,
    /// Layers whose bodies move further than their size in a frame (bullets).
    fast: Vec<bool>,
    /// `touch[a * n + b]`: whether the `touch` stage tracks the pair's touches and reports
    /// their begin and end (default true; an `ignore` pair never touches whatever it says).
    touch: Vec<bool>,
}

impl Layers {
    /// Layers with every pair ignored.
    #[must_use]
    pub fn new(names: Vec<String>) -> Layers {
        let n = names.len();
        Layers {
            names,
            matrix: vec![Response::Ignore; n * n],
            sweep: vec![false; n * n],
            fast: vec![false; n],
            touch: vec![true; n * n],
        }
    }

    /// Marks a layer as fast: every pair it is in is swept unless its `[[collide]]` entry says
    /// otherwise (call before [`Layers::set_sweep`]).
    pub fn set_fast(&mut self, layer: LayerId) {
        let n = self.names.len();
        let l = usize::from(layer);
        self.fast[l] = true;
        for other in 0..n {
            self.sweep[l * n + other] = true;
            self.sweep[other * n + l] = true;
        }
    }

    /// Whether a layer is fast.
    #[must_use]
    pub fn is_fast(&self, layer: LayerId) -> bool {
        self.fast[usize::from(layer)]
    }

    /// Chooses swept (time-of-impact) testing for a pair, both ways round.
    pub fn set_sweep(&mut self, a: LayerId, b: LayerId, sweep: bool) {
        let n = self.names.len();
        let (a, b) = (usize::from(a), usize::from(b));
        self.sweep[a * n + b] = sweep;
        self.sweep[b * n + a] = sweep;
    }

    /// Whether a pair is swept.
    #[must_use]
    #[inline]
    pub fn sweeps(&self, a: LayerId, b: LayerId) -> bool {
        self.sweep[usize::from(a) * self.names.len() + usize::from(b)]
    }

    /// Chooses whether the touches of a pair are tracked and reported
    /// ([`crate::GameEvent::TouchBegin`], [`crate::GameEvent::TouchEnd`]), both ways round.
    /// On by default; off, the pair's contacts are still detected, answered and recorded.
    pub fn set_touches(&mut self, a: LayerId, b: LayerId, touches: bool) {
        let n = self.names.len();
        let (a, b) = (usize::from(a), usize::from(b));
        self.touch[a * n + b] = touches;
        self.touch[b * n + a] = touches;
    }

    /// Whether the touches of a pair are tracked and reported: its response is not
    /// `ignore` (an ignored pair is never tested, so never touches) and
    /// [`Layers::set_touches`] did not switch it off.
    #[must_use]
    #[inline]
    pub fn touches(&self, a: LayerId, b: LayerId) -> bool {
        let k = usize::from(a) * self.names.len() + usize::from(b);
        self.touch[k] && self.matrix[k] != Response::Ignore
    }

    /// Whether some layer pair [`touches`](Layers::touches).
    #[must_use]
    pub fn any_touches(&self) -> bool {
        self.matrix
            .iter()
            .zip(&self.touch)
            .any(|(r, t)| *t && *r != Response::Ignore)
    }

    /// Whether every pair that is tested (not `ignore`) [`touches`](Layers::touches).
    #[must_use]
    pub fn all_touch(&self) -> bool {
        self.matrix
            .iter()
            .zip(&self.touch)
            .all(|(r, t)| *t || *r == Response::Ignore)
    }

    /// Sets the response of `(a, b)`, and the mirrored one of `(b, a)`.
    pub fn set(&mut self, a: LayerId, b: LayerId, response: Response) {
        let n = self.names.len();
        let (a, b) = (usize::from(a), usize::from(b));
        self.matrix[a * n + b] = response;
        let mirrored = match response {
            Response::Destroy(Doomed::First) => Response::Destroy(Doomed::Second),
            Response::Destroy(Doomed::Second) => Response::Destroy(Doomed::First),
            Response::OneWay(Platform::First) => Response::OneWay(Platform::Second),
            Response::OneWay(Platform::Second) => Response::OneWay(Platform::First),
            other => other,
        };
        if a != b {
            self.matrix[b * n + a] = mirrored;
        }
    }

    /// The response when a body of layer `a` meets one of layer `b`.
    #[must_use]
    #[inline]
    pub fn response(&self, a: LayerId, b: LayerId) -> Response {
        self.matrix[usize::from(a) * self.names.len() + usize::from(b)]
    }

    /// The layer names, in id order.
    #[must_use]
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The id of a layer name.
    #[must_use]
    pub fn id(&self, name: &str) -> Option<LayerId> {
        self.names
            .iter()
            .position(|n| n == name)
            .and_then(|i| LayerId::try_from(i).ok())
    }

    /// The name of a layer id.
    #[must_use]
    pub fn name(&self, id: LayerId) -> &str {
        &self.names[usize::from(id)]
    }

    /// Whether any pair of layers has this kind of response.
    #[must_use]
    pub fn any(&self, pred: impl Fn(Response) -> bool) -> bool {
        self.matrix.iter().any(|r| pred(*r))
    }
}

/// Which broad phase finds candidate pairs (the `broad_phase` module). All of them find the
/// same pairs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BroadPhaseKind {
    /// Every pair is tested: `O(n²)`.
    BruteForce,
    /// Sort and sweep along x, re-sorting the previous call's order.
    SortAndSweep,
    /// A uniform grid, hashed deterministically.
    Grid,
    /// Sort and sweep along x within horizontal strips as tall as the tallest body.
    Strips,
    /// A loose quadtree per layer, rebuilt every call for moving bodies.
    Quadtree,
    /// A dynamic tree of enlarged (fat) boxes per layer, kept across calls: a body's leaf
    /// moves only when its bounds leave its fat box.
    Tree,
    /// Chosen per call from the number of moving and static bodies (see the module docs).
    #[default]
    Auto,
}

impl BroadPhaseKind {
    /// The name scenario files and `/stats` use: `brute-force`, `sort-and-sweep`, `grid`,
    /// `strips`, `quadtree`, `tree`, `auto`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            BroadPhaseKind::BruteForce => "brute-force",
            BroadPhaseKind::SortAndSweep => "sort-and-sweep",
            BroadPhaseKind::Grid => "grid",
            BroadPhaseKind::Strips => "strips",
            BroadPhaseKind::Quadtree => "quadtree",
            BroadPhaseKind::Tree => "tree",
            BroadPhaseKind::Auto => "auto",
        }
    }
}

/// World bounds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldBounds {
    /// Lower-left corner.
    pub min: Vec2,
    /// Upper-right corner.
    pub max: Vec2,
    /// Whether bodies leaving one side come back on the other.
    pub wrap: bool,
}

impl WorldBounds {
    /// The world's size, `max - min`.
    #[must_use]
    pub fn size(&self) -> Vec2 {
        self.max - self.min
    }

    /// Where a body's images may be in a wrapping world: the translations by whole world
    /// sizes `(sx * width, sy * height)`, `sx` and `sy` in `-1, 0, 1`, in the fixed order
    /// of the wrap-seam rule. The direct one (`sx = sy = 0`) comes first, then `sx`, then
    /// `sy` ascending. Of the translations of `b` that overlap `a`, `detect` takes the
    /// deepest (the earliest touch for a swept pair), the first in this order on a tie.
    #[must_use]
    pub fn image_offsets(&self) -> [Vec2; 9] {
        let size = self.size();
        let mut out = [Vec2::ZERO; 9];
        let mut k = 1;
        for sx in [-1.0, 0.0, 1.0] {
            for sy in [-1.0, 0.0, 1.0] {
                if sx != 0.0 || sy != 0.0 {
                    out[k] = Vec2::new(sx * size.x, sy * size.y);
                    k += 1;
                }
            }
        }
        out
    }
}

/// World-wide settings.
#[derive(Clone, Debug, PartialEq)]
pub struct WorldDef {
    /// Seconds per step (default 1/60).
    pub dt: f64,
    /// Gravity, units/s² (default zero).
    pub gravity: Vec2,
    /// Optional bounds.
    pub bounds: Option<WorldBounds>,
    /// Layers and their response matrix.
    pub layers: Layers,
    /// Which broad phase finds candidate pairs (default: chosen automatically).
    pub broad_phase: BroadPhaseKind,
    /// Bodies outside this region are frozen (default: none, everything is simulated).
    pub active_region: Option<ActiveRegion>,
    /// Dynamic bodies resting on static geometry for this many frames fall asleep
    /// (default: `None`, nothing sleeps).
    pub sleep_after: Option<u32>,
    /// The steepest surface a `runner` or `walker` walks up and down, in degrees from the
    /// horizontal (`[world] max_climb_angle`, default [`DEFAULT_MAX_CLIMB_ANGLE`], from 0 to
    /// less than [`MAX_CLIMB_ANGLE_LIMIT`]); a steeper one is a wall to it
    /// (`stages/slope.rs`).
    pub max_climb_angle: f64,
}

/// The default [`WorldDef::max_climb_angle`], degrees: rapier's character controller's
/// default too.
pub const DEFAULT_MAX_CLIMB_ANGLE: f64 = 45.0;

/// [`WorldDef::max_climb_angle`] is below this, degrees: at 90° every wall would be ground,
/// and the reach of the snap to the ground (`tan` of the angle) would be unbounded.
pub const MAX_CLIMB_ANGLE_LIMIT: f64 = 90.0;

/// A region around a focus body (the player): moving bodies entirely outside it are frozen,
/// neither moved nor tested, until the region reaches them again.
#[derive(Clone, Debug, PartialEq)]
pub struct ActiveRegion {
    /// The name of the body the region follows (the lowest id with that name).
    pub focus: String,
    /// Half the region's width and height, centred on the focus body.
    pub half_extents: Vec2,
}

impl Default for WorldDef {
    fn default() -> Self {
        WorldDef {
            dt: 1.0 / 60.0,
            gravity: Vec2::ZERO,
            bounds: None,
            layers: Layers::new(vec!["default".to_owned()]),
            broad_phase: BroadPhaseKind::Auto,
            active_region: None,
            sleep_after: None,
            max_climb_angle: DEFAULT_MAX_CLIMB_ANGLE,
        }
    }
}
