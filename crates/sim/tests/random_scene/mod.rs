//! Shared by the `past` and `query_refit` tests: random scenes (every shape, every body kind,
//! wrap worlds and not), random edits between steps (spawns, despawns, reshapes, teleports),
//! random query filters, and query answers as bits.
#![allow(dead_code, reason = "each test file uses its own part of the helpers")]

use ricochet_sim::Doomed;
use ricochet_sim::prelude::*;

/// A small deterministic generator (xorshift64*): the scene and its edits follow from the
/// proptest's seed.
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    /// Uniform in `[a, b)`.
    pub fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * ((self.next() >> 11) as f64 / (1u64 << 53) as f64)
    }

    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }

    pub fn chance(&mut self, p: f64) -> bool {
        self.range(0.0, 1.0) < p
    }

    pub fn vec(&mut self, a: f64, b: f64) -> Vec2 {
        Vec2::new(self.range(a, b), self.range(a, b))
    }
}

pub fn shape(rng: &mut Rng) -> Shape {
    let r = rng.range(0.3, 3.0);
    match rng.below(5) {
        0 => Shape::circle(r).unwrap(),
        1 => Shape::aabb(Vec2::new(r, rng.range(0.3, 3.0))).unwrap(),
        2 => {
            let v = [
                (1.0, 0.1),
                (0.3, 0.95),
                (-0.8, 0.6),
                (-0.9, -0.5),
                (0.2, -1.0),
            ];
            Shape::polygon(&v.map(|(x, y)| Vec2::new(x * r, y * r))).unwrap()
        }
        3 => Shape::capsule(Vec2::new(-r, 0.0), Vec2::new(r, 0.5), r * 0.4).unwrap(),
        _ => Shape::compound(vec![
            Primitive::circle(Vec2::new(r, 0.0), r * 0.5).unwrap(),
            Primitive::aabb(Vec2::new(-r, 0.0), Vec2::splat(r * 0.5)).unwrap(),
        ])
        .unwrap(),
    }
}

/// A random body in a world of `size`; a moving one turns with chance `turning`.
pub fn body(rng: &mut Rng, size: Vec2, turning: f64) -> BodyDef {
    let kind = match rng.below(10) {
        0..5 => BodyKind::Dynamic,
        5..7 => BodyKind::Kinematic,
        _ => BodyKind::Static,
    };
    let moving = kind != BodyKind::Static;
    BodyDef {
        layer: rng.below(3) as LayerId,
        kind,
        shape: shape(rng),
        position: Vec2::new(rng.range(0.0, size.x), rng.range(0.0, size.y)),
        angle: rng.range(-3.0, 3.0),
        velocity: if moving {
            rng.vec(-30.0, 30.0)
        } else {
            Vec2::ZERO
        },
        angular_velocity: if moving && rng.chance(turning) {
            rng.range(-4.0, 4.0)
        } else {
            0.0
        },
        lifetime: rng.chance(0.2).then(|| 3 + rng.below(30) as u32),
        ..BodyDef::default()
    }
}

/// A random scene named `name` of 3 to `count + 2` bodies ([`body`], turning with chance
/// `turning`), in a world wrapping, bounded or not.
pub fn scenario(rng: &mut Rng, name: &str, count: usize, turning: f64) -> Scenario {
    let size = rng.vec(20.0, 60.0);
    let mut layers = Layers::new(vec!["a".into(), "b".into(), "c".into()]);
    layers.set(0, 1, Response::Report);
    // Removals inside a step: a body despawned by the step is still in the frames it lived.
    layers.set(1, 2, Response::Destroy(Doomed::Second));
    let bounds = match rng.below(3) {
        0 => None,
        k => Some(WorldBounds {
            min: Vec2::ZERO,
            max: size,
            // Not wrapping: a body leaving the world is removed.
            wrap: k == 1,
        }),
    };
    let bodies = (0..3 + rng.below(count))
        .map(|_| body(rng, size, turning))
        .collect();
    Scenario {
        name: name.into(),
        world: WorldDef {
            layers,
            bounds,
            gravity: Vec2::new(0.0, rng.range(-10.0, 0.0)),
            ..WorldDef::default()
        },
        frames: 100,
        templates: Default::default(),
        tiles: Vec::new(),
        bodies,
        script: Vec::new(),
    }
}

/// Spawns, despawns, reshapes or moves a few bodies between two steps. Half the new shapes
/// are a live body's (the world's shape table then gains nothing: only the bodies change).
pub fn edit(sim: &mut Simulation, rng: &mut Rng, size: Vec2) {
    for _ in 0..rng.below(4) {
        let live = sim.world().entity.clone();
        let pick = |rng: &mut Rng| live.get(rng.below(live.len().max(1))).copied();
        let reuse = |sim: &Simulation, rng: &mut Rng| match pick(rng) {
            Some(e) if rng.chance(0.5) => {
                let i = sim.world().index_of(e).unwrap();
                sim.world().shape(i).clone()
            }
            _ => shape(rng),
        };
        match rng.below(4) {
            0 => {
                let b = BodyDef {
                    shape: reuse(sim, rng),
                    ..body(rng, size, 0.6)
                };
                sim.spawn(&b);
            }
            1 => {
                if let Some(e) = pick(rng) {
                    sim.despawn(e).unwrap();
                }
            }
            2 => {
                if let Some(e) = pick(rng) {
                    let s = reuse(sim, rng);
                    sim.set_shape(e, s).unwrap();
                }
            }
            _ => {
                if let Some(e) = pick(rng) {
                    let p = Vec2::new(rng.range(0.0, size.x), rng.range(0.0, size.y));
                    sim.set_position(e, p).unwrap();
                }
            }
        }
    }
}

pub fn filter(rng: &mut Rng, live: &[Entity]) -> QueryFilter {
    let f = match rng.below(3) {
        0 => QueryFilter::all(),
        1 => QueryFilter::layers(&[rng.below(3) as LayerId]),
        _ => QueryFilter::layers(&[0, 2]),
    };
    match live.get(rng.below(live.len().max(1) * 2)) {
        Some(&e) => f.exclude(e),
        None => f,
    }
}

/// A ray hit as bits: equal exactly when every field is the same bits.
pub fn ray_bits(h: &RayHit) -> (Entity, [u64; 5]) {
    let b = |x: f64| x.to_bits();
    (
        h.entity,
        [
            b(h.point.x),
            b(h.point.y),
            b(h.normal.x),
            b(h.normal.y),
            b(h.distance),
        ],
    )
}

pub fn shape_bits(h: &ShapeHit) -> (Entity, [u64; 5]) {
    let b = |x: f64| x.to_bits();
    (
        h.entity,
        [
            b(h.fraction),
            b(h.point.x),
            b(h.point.y),
            b(h.normal.x),
            b(h.normal.y),
        ],
    )
}
