//! Shared by the `past` and `query_refit` tests: random scenes (every shape, every body kind,
//! wrap worlds and not), random edits between steps (spawns, despawns, reshapes, teleports),
//! random query filters, and query answers as bits.
#![allow(dead_code, reason = "each test file uses its own part of the helpers")]

use proptest::prelude::*;
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

/// The area a test probes `scene` in with queries, from the origin: its world's bounds, or
/// 40 x 40 when it has none (its bodies were spawned within 20 to 60 a side).
pub fn probed_size(scene: &Scenario) -> Vec2 {
    scene
        .world
        .bounds
        .map_or(Vec2::new(40.0, 40.0), |b| b.size())
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

/// The scene queries, as a `Simulation` answers them now and a `Past` answers them then: the
/// two tests ask both the same way.
pub trait Queries {
    fn cast_ray(&self, o: Vec2, d: Vec2, max: f64, f: &QueryFilter) -> Option<RayHit>;
    fn cast_ray_all(&self, o: Vec2, d: Vec2, max: f64, f: &QueryFilter) -> Vec<RayHit>;
    fn cast_shape(&self, s: &Shape, pose: Pose, t: Vec2, f: &QueryFilter) -> Option<ShapeHit>;
    fn overlap_point(&self, p: Vec2, f: &QueryFilter) -> Vec<Entity>;
    fn overlap_aabb(&self, b: Bounds, f: &QueryFilter) -> Vec<Entity>;
    fn overlap_shape(&self, s: &Shape, pose: Pose, f: &QueryFilter) -> Vec<Entity>;
}

/// Implements [`Queries`] by the type's own methods of the same names.
macro_rules! queries_by_own_methods {
    ($t:ty) => {
        impl Queries for $t {
            fn cast_ray(&self, o: Vec2, d: Vec2, max: f64, f: &QueryFilter) -> Option<RayHit> {
                <$t>::cast_ray(self, o, d, max, f)
            }
            fn cast_ray_all(&self, o: Vec2, d: Vec2, max: f64, f: &QueryFilter) -> Vec<RayHit> {
                <$t>::cast_ray_all(self, o, d, max, f)
            }
            fn cast_shape(
                &self,
                s: &Shape,
                pose: Pose,
                t: Vec2,
                f: &QueryFilter,
            ) -> Option<ShapeHit> {
                <$t>::cast_shape(self, s, pose, t, f)
            }
            fn overlap_point(&self, p: Vec2, f: &QueryFilter) -> Vec<Entity> {
                <$t>::overlap_point(self, p, f)
            }
            fn overlap_aabb(&self, b: Bounds, f: &QueryFilter) -> Vec<Entity> {
                <$t>::overlap_aabb(self, b, f)
            }
            fn overlap_shape(&self, s: &Shape, pose: Pose, f: &QueryFilter) -> Vec<Entity> {
                <$t>::overlap_shape(self, s, pose, f)
            }
        }
    };
}

queries_by_own_methods!(Simulation);
queries_by_own_methods!(Past<'_>);

/// Asks `ours` and `theirs` (the independent source: a scene restored at the same frame)
/// `rounds` rounds of random queries (rays, all hits of a ray, a cast shape, a point, a
/// box, a shape; filters drawn from `theirs`' bodies), and one box around everything;
/// every answer must be the same bits. How many of `theirs`' answers found something.
pub fn same_answers(
    ours: &impl Queries,
    theirs: &Simulation,
    rng: &mut Rng,
    size: Vec2,
    rounds: usize,
) -> Result<usize, TestCaseError> {
    let live = theirs.world().entity.clone();
    let everywhere = Bounds {
        min: Vec2::splat(-1e6),
        max: Vec2::splat(1e6),
    };
    prop_assert_eq!(
        ours.overlap_aabb(everywhere, &QueryFilter::all()),
        theirs.overlap_aabb(everywhere, &QueryFilter::all())
    );
    let mut hits = 0;
    for _ in 0..rounds {
        let f = filter(rng, &live);
        // Inside the world and out of it (wrapped in first in a wrap world).
        let origin = rng.vec(-0.2, 1.2) * size;
        let dir = rng.vec(-1.0, 1.0);
        let max = if rng.chance(0.1) {
            f64::INFINITY
        } else {
            rng.range(0.0, 3.0) * size.max_element()
        };
        let (a, b) = (
            ours.cast_ray(origin, dir, max, &f),
            theirs.cast_ray(origin, dir, max, &f),
        );
        prop_assert_eq!(a.as_ref().map(ray_bits), b.as_ref().map(ray_bits));
        hits += usize::from(b.is_some());
        let (a, b) = (
            ours.cast_ray_all(origin, dir, max, &f),
            theirs.cast_ray_all(origin, dir, max, &f),
        );
        prop_assert_eq!(
            a.iter().map(ray_bits).collect::<Vec<_>>(),
            b.iter().map(ray_bits).collect::<Vec<_>>()
        );
        let s = shape(rng);
        let pose = Pose::new(rng.vec(-0.2, 1.2) * size, rng.range(-3.0, 3.0));
        let t = rng.vec(-1.0, 1.0) * size * 0.5;
        let (a, b) = (
            ours.cast_shape(&s, pose, t, &f),
            theirs.cast_shape(&s, pose, t, &f),
        );
        prop_assert_eq!(a.as_ref().map(shape_bits), b.as_ref().map(shape_bits));
        hits += usize::from(b.is_some());
        let point = rng.vec(0.0, 1.0) * size;
        let b = theirs.overlap_point(point, &f);
        hits += usize::from(!b.is_empty());
        prop_assert_eq!(ours.overlap_point(point, &f), b);
        let c = rng.vec(-0.1, 1.1) * size;
        let h = rng.vec(0.1, 8.0);
        let q = Bounds {
            min: c - h,
            max: c + h,
        };
        let b = theirs.overlap_aabb(q, &f);
        hits += usize::from(!b.is_empty());
        prop_assert_eq!(ours.overlap_aabb(q, &f), b);
        let b = theirs.overlap_shape(&s, pose, &f);
        hits += usize::from(!b.is_empty());
        prop_assert_eq!(ours.overlap_shape(&s, pose, &f), b);
    }
    Ok(hits)
}
