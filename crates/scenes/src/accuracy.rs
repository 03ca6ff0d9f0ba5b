//! The scenes of `ricochet accuracy`, each with its exact answer (`docs/accuracy.md`):
//!
//! - [`projectile`]: gravity only; the exact position is `x0 + v0 t + g t²/2`.
//! - [`SPRING`] and [`ORBIT`]: `x'' = -ω² x` ([`Harmonic`]: a body on a spring; a circular
//!   orbit round the origin). The simulation has no spring or central force: the force is
//!   written into the body before every step, or scripted with `set_force` events
//!   ([`Harmonic::force_script`]).
//! - [`drop`]: a box falls onto a static floor (per-axis `separate`);
//!   [`exact_landing_step`] is the semi-implicit-Euler landing step.
//! - [`Field`]: bullets cross a field of rocks; each bullet's exact first hit (analytic
//!   ray–circle entry).
//!
//! Every scene takes its step rate `hz` (dt = `1 / hz`) and, where the stability study moves
//! it, an `offset` added to every coordinate on both axes.

use std::f64::consts::PI;

use ricochet_geom::{Shape, Vec2};
use ricochet_sim::{
    Action, BodyDef, BodyKind, Doomed, Event, Layers, Response, Scenario, ScriptAction, WorldDef,
};

use crate::{Rng, layers, scenario};

/// Gravity, units/s² (downwards).
pub const G: f64 = 9.81;
/// Frames a scenario runs when nothing else says (what a scenario file without `frames`
/// gets).
const FRAMES: u64 = 600;

/// The world of every accuracy scene: `dt = 1 / hz`, the given gravity and layers.
fn world(hz: u32, gravity: Vec2, layers: Layers) -> WorldDef {
    WorldDef {
        dt: 1.0 / f64::from(hz),
        gravity,
        layers,
        ..WorldDef::default()
    }
}

fn circle(radius: f64) -> Shape {
    Shape::circle(radius).expect("a positive radius")
}

// ---------------------------------------------------------------------------------------------
// Projectile.

/// The projectile's start position.
pub const PROJECTILE_X0: Vec2 = Vec2::new(0.0, 1.5);
/// The projectile's start velocity.
pub const PROJECTILE_V0: Vec2 = Vec2::new(3.0, 12.0);
/// The projectile is compared at this time, seconds.
pub const PROJECTILE_T: f64 = 2.0;

/// A ball of radius 0.1 thrown from [`PROJECTILE_X0`] (plus `offset`) at [`PROJECTILE_V0`]
/// under gravity [`G`].
#[must_use]
pub fn projectile(hz: u32, offset: f64) -> Scenario {
    let ball = BodyDef {
        name: "ball".to_owned(),
        shape: circle(0.1),
        position: PROJECTILE_X0 + Vec2::splat(offset),
        velocity: PROJECTILE_V0,
        ..BodyDef::default()
    };
    let w = world(hz, Vec2::new(0.0, -G), layers(&["ball"], &[]));
    scenario("projectile", w, vec![ball], FRAMES)
}

// ---------------------------------------------------------------------------------------------
// Spring and orbit: x'' = -ω² x.

/// A harmonic scene: `x'' = -ω² x` from `x0`, `v0`, for `seconds`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Harmonic {
    /// The scene's name.
    pub scene: &'static str,
    /// Angular frequency, radians/s.
    pub omega: f64,
    /// The body's mass.
    pub mass: f64,
    /// Start position.
    pub x0: Vec2,
    /// Start velocity.
    pub v0: Vec2,
    /// How long the scene runs, seconds.
    pub seconds: f64,
}

/// A body on a spring: amplitude 1, period 2 s, 5 periods.
pub const SPRING: Harmonic = Harmonic {
    scene: "spring",
    omega: PI,
    mass: 1.0,
    x0: Vec2::new(1.0, 0.0),
    v0: Vec2::ZERO,
    seconds: 10.0,
};

/// A circular orbit: radius 10, period 10 s, for 10,000 frames at 60 Hz (166.7 s, 16.7
/// orbits) whatever the timestep.
pub const ORBIT: Harmonic = Harmonic {
    scene: "orbit",
    omega: 2.0 * PI / 10.0,
    mass: 2.0,
    x0: Vec2::new(10.0, 0.0),
    v0: Vec2::new(0.0, 2.0 * PI),
    seconds: 10_000.0 / 60.0,
};

impl Harmonic {
    /// The exact position and velocity at `t`.
    #[must_use]
    pub fn exact(&self, t: f64) -> (Vec2, Vec2) {
        let (s, c) = libm::sincos(self.omega * t);
        (
            self.x0 * c + self.v0 * (s / self.omega),
            self.x0 * (-self.omega * s) + self.v0 * c,
        )
    }

    /// `m v²/2 + m ω² x²/2`, constant along the exact solution.
    #[must_use]
    pub fn energy(&self, x: Vec2, v: Vec2) -> f64 {
        0.5 * self.mass * (v.length_squared() + self.omega * self.omega * x.length_squared())
    }

    /// The force of step `s` (from frame s-1 to frame s): prescribed from the exact position
    /// at the start of the step, or computed from the body's current position (`state`).
    #[must_use]
    pub fn force(&self, s: u64, dt: f64, state: Option<Vec2>) -> Vec2 {
        let x = state.unwrap_or_else(|| self.exact((s - 1) as f64 * dt).0);
        x * (-self.mass * self.omega * self.omega)
    }

    /// The body (named `mass`, radius 0.1) at `x0`, `v0`, no gravity, with `script`.
    #[must_use]
    pub fn scenario(&self, hz: u32, script: Vec<Event>) -> Scenario {
        let body = BodyDef {
            name: "mass".to_owned(),
            mass: self.mass,
            shape: circle(0.1),
            position: self.x0,
            velocity: self.v0,
            ..BodyDef::default()
        };
        let w = world(hz, Vec2::ZERO, layers(&["mass"], &[]));
        let mut s = scenario(self.scene, w, vec![body], FRAMES);
        s.script = script;
        s
    }

    /// A `set_force` event at the start of every frame `1..=steps` at `hz`, the prescribed
    /// force ([`Harmonic::force`] without state): what writing it before each step does.
    #[must_use]
    pub fn force_script(&self, hz: u32, steps: u64) -> Vec<Event> {
        let dt = 1.0 / f64::from(hz);
        (1..=steps)
            .map(|s| Event {
                frame: s,
                action: ScriptAction::Body {
                    name: "mass".to_owned(),
                    action: Action::SetForce(self.force(s, dt, None)),
                },
            })
            .collect()
    }
}

// ---------------------------------------------------------------------------------------------
// A box dropping onto a floor.

/// The box's half size. Neither it nor the floor's half height is a power of two, so the
/// sums that place the box flush round as they would in a game.
pub const BOX_HALF: f64 = 0.3;
/// The floor's half height; its top is at y = 0 (plus the offset).
pub const FLOOR_HALF: f64 = 0.45;
/// The height of the box's bottom above the floor's top at the start.
pub const DROP_HEIGHT: f64 = 4.75;
/// How long the drop runs, seconds (it lands after about 1 s).
pub const DROP_SECONDS: f64 = 2.0;

/// A static floor (body 0, 40 wide, top at `offset`) and a box (body 1) from rest
/// [`DROP_HEIGHT`] above it, in a `separate` layer pair, under gravity [`G`].
#[must_use]
pub fn drop(hz: u32, offset: f64) -> Scenario {
    const BOX: u8 = 0;
    const GROUND: u8 = 1;
    let floor = BodyDef {
        name: "floor".to_owned(),
        layer: GROUND,
        kind: BodyKind::Static,
        shape: Shape::aabb(Vec2::new(20.0, FLOOR_HALF)).expect("positive half extents"),
        position: Vec2::new(offset, offset - FLOOR_HALF),
        ..BodyDef::default()
    };
    let body = BodyDef {
        name: "box".to_owned(),
        layer: BOX,
        shape: Shape::aabb(Vec2::splat(BOX_HALF)).expect("positive half extents"),
        position: Vec2::new(offset, offset + DROP_HEIGHT + BOX_HALF),
        ..BodyDef::default()
    };
    let l = layers(&["box", "ground"], &[(BOX, GROUND, Response::Separate)]);
    let w = world(hz, Vec2::new(0.0, -G), l);
    scenario("drop", w, vec![floor, body], FRAMES)
}

/// The first step whose semi-implicit-Euler position puts the box's bottom below the floor's
/// top: `bottom_n = bottom_0 - g dt² n(n+1)/2` (exact arithmetic, from rest). `None` when
/// the landing at `hz` is a near tie (within 1e-6 units of either side).
#[must_use]
pub fn exact_landing_step(hz: u32) -> Option<u64> {
    let h = f64::from(hz);
    // Below the top when n(n+1) > 2 height hz² / g.
    let q = 2.0 * DROP_HEIGHT * h * h / G;
    let mut n: u64 = 1;
    while ((n * (n + 1)) as f64) <= q {
        n += 1;
    }
    // The gap on either side of the boundary, in units: far above rounding and SLOP.
    let gap = |m: u64| ((m * (m + 1)) as f64 - q).abs() * G / (2.0 * h * h);
    (gap(n) > 1e-6 && gap(n - 1) > 1e-6).then_some(n)
}

// ---------------------------------------------------------------------------------------------
// Bullets through a field of rocks.

/// The bullets' radius.
pub const BULLET_RADIUS: f64 = 0.05;
/// How far past the start every bullet has gone when a run ends, units.
pub const BULLET_RANGE: f64 = 125.0;

/// Rocks (centre, radius) and bullets (start, unit direction); the exact first hit of each
/// bullet (the index of a rock), or none.
#[derive(Clone, Debug, PartialEq)]
pub struct Field {
    /// Rocks: centre and radius.
    pub rocks: Vec<(Vec2, f64)>,
    /// Bullets: start and unit direction.
    pub bullets: Vec<(Vec2, Vec2)>,
    /// Each bullet's exact first hit: the index of a rock, or none.
    pub first_hits: Vec<Option<usize>>,
}

/// Where a ray from `p` along unit `d` enters the circle (`c`, `r`): the distance along the
/// ray, and how far the ray's closest approach is from grazing (positive inside).
fn ray_entry(p: Vec2, d: Vec2, c: Vec2, r: f64) -> (Option<f64>, f64) {
    let to = c - p;
    let along = to.dot(d);
    let miss = (to.x * d.y - to.y * d.x).abs();
    let margin = r - miss;
    if margin <= 0.0 || along <= 0.0 {
        return (None, margin);
    }
    (Some(along - (r * r - miss * miss).sqrt()), margin)
}

impl Field {
    /// 40 rocks of radius 0.5 to 1.5 in x 5..95, y -15..15; 24 bullets from x = -10, spread
    /// over y -18..18, within ±0.1 rad of +x. A bullet whose ray grazes a rock, or enters
    /// two rocks at nearly the same distance, is re-aimed: the exact answer must be clear.
    /// Fails (naming the bullet) when a bullet finds no clear aim in 100 tries.
    pub fn new() -> Result<Field, String> {
        let mut rng = Rng::new(0x005e_ed0f_a57e_501d);
        let rocks: Vec<(Vec2, f64)> = (0..40)
            .map(|_| {
                let c = Vec2::new(rng.range(5.0, 95.0), rng.range(-15.0, 15.0));
                (c, rng.range(0.5, 1.5))
            })
            .collect();
        let mut bullets = Vec::new();
        let mut first_hits = Vec::new();
        for i in 0..24 {
            let p = Vec2::new(-10.0, -18.0 + 36.0 * f64::from(i) / 23.0);
            let mut tries = 0;
            loop {
                tries += 1;
                if tries >= 100 {
                    return Err(format!("no clear aim for bullet {i}"));
                }
                let a = rng.range(-0.1, 0.1);
                let (s, c) = libm::sincos(a);
                let d = Vec2::new(c, s);
                let mut entries: Vec<(f64, usize)> = Vec::new();
                let mut clear = true;
                for (k, &(centre, r)) in rocks.iter().enumerate() {
                    let (entry, margin) = ray_entry(p, d, centre, r + BULLET_RADIUS);
                    clear &= margin.abs() > 1e-3;
                    if let Some(e) = entry {
                        entries.push((e, k));
                    }
                }
                entries.sort_by(|a, b| a.0.total_cmp(&b.0));
                if entries.len() >= 2 && entries[1].0 - entries[0].0 < 1e-3 {
                    clear = false;
                }
                if clear {
                    bullets.push((p, d));
                    first_hits.push(entries.first().map(|e| e.1));
                    break;
                }
            }
        }
        Ok(Field {
            rocks,
            bullets,
            first_hits,
        })
    }

    /// The field as a scenario, moved by `offset` on both axes, bullets at `speed`: the rocks
    /// (static, layer `rock`, bodies `0..rocks`), then the bullets (layer `bullet`, swept when
    /// `swept`), a bullet destroyed by the first rock it meets.
    #[must_use]
    pub fn scenario(&self, hz: u32, speed: f64, swept: bool, offset: f64) -> Scenario {
        const ROCK: u8 = 0;
        const BULLET: u8 = 1;
        let shift = Vec2::splat(offset);
        let mut l = Layers::new(vec!["rock".to_owned(), "bullet".to_owned()]);
        if swept {
            l.set_fast(BULLET);
        }
        l.set(BULLET, ROCK, Response::Destroy(Doomed::First));
        let rocks = self.rocks.iter().enumerate().map(|(k, &(c, r))| BodyDef {
            name: format!("rock{k}"),
            layer: ROCK,
            kind: BodyKind::Static,
            shape: circle(r),
            position: c + shift,
            ..BodyDef::default()
        });
        let bullets = self.bullets.iter().enumerate().map(|(k, &(p, d))| BodyDef {
            name: format!("bullet{k}"),
            layer: BULLET,
            shape: circle(BULLET_RADIUS),
            position: p + shift,
            velocity: d * speed,
            ..BodyDef::default()
        });
        let bodies = rocks.chain(bullets).collect();
        scenario("bullets", world(hz, Vec2::ZERO, l), bodies, FRAMES)
    }

    /// Sim steps (after frame 0) for every bullet to cover [`BULLET_RANGE`] at `speed`.
    #[must_use]
    pub fn steps(speed: f64, hz: u32) -> u64 {
        let seconds = BULLET_RANGE / (speed * libm::cos(0.1));
        (seconds * f64::from(hz)).ceil() as u64 + 1
    }
}
