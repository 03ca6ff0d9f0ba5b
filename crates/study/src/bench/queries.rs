//! `ricochet bench --queries`: Ricochet's scene queries against rapier's `QueryPipeline` and
//! Box2D's world queries on the same bench scene, in one process, with the same seeded rays
//! and boxes, and whether their answers agree.
//!
//! The scene is stepped `frames` frames by Ricochet; then rapier's and Box2D's worlds are
//! built at those poses and stepped once (their trees built from scratch: the best case for
//! them). From one seeded [`Rng`]:
//!
//! - **rays**: an origin drawn in the world, a unit direction, [`RAY_LENGTH`] units long (the
//!   same `max_distance` for all three). The origin is outside every body (rapier's
//!   `intersect_point` says so, untimed), because Box2D's closest-hit cast skips a shape the
//!   ray starts in while Ricochet's and rapier's are solid: the same answer is then owed by
//!   all three;
//! - **boxes**: a centre in the world and half extents of 0.5 to 1.5 times the median body's
//!   half size (its broad-phase box).
//!
//! Every ray and box stays [`margin`] inside the world's bounds: the bench scenes wrap, and
//! Ricochet's queries see every image through the seam where rapier and Box2D see one body.
//!
//! Each engine runs the whole batch [`PASSES`] times; the figure is the median pass, as
//! queries per second. Box2D's answers are shape ids, read back to entities after the timed
//! pass. Agreement: a ray agrees when both miss, or both hit at distances within
//! [`RAPIER_RAY_TOLERANCE`] (rapier) or [`BOX2D_RAY_TOLERANCE`] (Box2D's `f32`) — two
//! bodies hit at the same distance may be named either way; a box agrees when the two sets
//! of entities are equal. `b2World_OverlapAABB` tests tree boxes only (fattened by 0.1):
//! its hits are counted and timed, not compared; Box2D's exact box overlap is
//! `b2World_OverlapShape` with the box as a proxy.

use std::fmt::Write as _;
use std::time::{Duration, Instant};

use anyhow::Context;
use ricochet_box2d::Box2dScene;
use ricochet_oracle::bench::RapierScene;
use ricochet_scenes::Rng;
use ricochet_scenes::bench::Scene;
use ricochet_sim::{Bounds, Entity, Pose, QueryFilter, Shape, Simulation, Vec2, shape_reach};

use super::measure::percentiles;

/// How long every ray is, world units.
pub const RAY_LENGTH: f64 = 20.0;
/// Rays and boxes per scene.
pub const QUERIES: usize = 2000;
/// Timed passes over the batch per engine (the median is reported).
pub const PASSES: usize = 5;
/// Ray distances agree with rapier's within this, world units (both exact in `f64`).
pub const RAPIER_RAY_TOLERANCE: f64 = 1e-7;
/// Ray distances agree with Box2D's within this: its fraction and shapes are `f32`.
pub const BOX2D_RAY_TOLERANCE: f64 = 1e-3;
/// The seed of the rays and boxes.
pub const SEED: u64 = 22;
/// Box2D's overlap skin, length units: `b2World_OverlapShape` counts a shape whose GJK
/// distance to the query is at most `0.1 * B2_LINEAR_SLOP` (`B2_LINEAR_SLOP` = 0.005 length
/// units) as overlapping (`TreeOverlapCallback` in Box2D's `physics_world.c`, v3.2 as
/// vendored by `boxdd-sys` 0.6; upstream `world.c` has the same test). Ricochet counts
/// `depth > 0` only.
pub const BOX2D_OVERLAP_SKIN: f64 = 5e-4;
/// The `f32` slack on that skin: Box2D measures the distance in `f32` relative to the
/// query's origin, within about 100 units here (`100 * 2^-23`, rounded up).
pub const BOX2D_SKIN_SLACK: f64 = 2e-5;

/// One scene's query figures.
#[derive(Clone, Debug, Default)]
pub struct QueryRow {
    /// The scene's name as asked.
    pub scene: String,
    /// Bodies in the scene.
    pub bodies: usize,
    /// Rays cast per pass.
    pub rays: usize,
    /// Boxes asked per pass.
    pub boxes: usize,
    /// Rays per second: Ricochet, rapier, Box2D.
    pub rays_per_s: [f64; 3],
    /// Box overlaps per second: Ricochet, rapier, Box2D exact (`OverlapShape`), Box2D
    /// `OverlapAABB` (tree boxes only).
    pub overlaps_per_s: [f64; 4],
    /// Rays that hit something: Ricochet, rapier, Box2D.
    pub ray_hits: [usize; 3],
    /// Entities found by all the boxes: Ricochet, rapier, Box2D exact, Box2D tree boxes.
    pub overlap_hits: [usize; 4],
    /// Rays whose answer differs from Ricochet's: rapier's, Box2D's.
    pub ray_differences: [usize; 2],
    /// Boxes whose set of entities differs from Ricochet's, unexplained: rapier's, Box2D's
    /// exact.
    pub overlap_differences: [usize; 2],
    /// Bodies only Box2D's exact overlap finds, explained by its skin (rule `box2d-skin`:
    /// Ricochet's exact gap between the box and the body is in `(0, BOX2D_OVERLAP_SKIN +
    /// BOX2D_SKIN_SLACK]`): counted here, not in `overlap_differences`.
    pub box2d_skin: usize,
    /// The first few differences, word for word.
    pub details: Vec<String>,
}

/// How far inside the world's bounds the queries stay: the largest body reach, plus one.
#[must_use]
pub fn margin(sim: &Simulation) -> f64 {
    let w = sim.world();
    (0..w.len())
        .map(|i| {
            let r = shape_reach(w.shape(i));
            r.x.max(r.y)
        })
        .fold(0.0, f64::max)
        + 1.0
}

/// The region the queries are drawn in: the world's bounds less [`margin`], or the bodies'
/// extent for a world without bounds.
fn region(sim: &Simulation) -> Bounds {
    let m = Vec2::splat(margin(sim));
    match sim.scenario().world.bounds {
        Some(b) => Bounds {
            min: b.min + m,
            max: b.max - m,
        },
        None => {
            let w = sim.world();
            let points: Vec<Vec2> = w.position.clone();
            Bounds::of_points(&points)
        }
    }
}

/// A point drawn uniformly in `r`.
fn point_in(rng: &mut Rng, r: &Bounds) -> Vec2 {
    Vec2::new(rng.range(r.min.x, r.max.x), rng.range(r.min.y, r.max.y))
}

/// The seeded rays: origin outside every body (rapier's point test), the whole ray in
/// `region`.
fn rays(rng: &mut Rng, r: &Bounds, rapier: &RapierScene, n: usize) -> Vec<(Vec2, Vec2)> {
    let mut out = Vec::with_capacity(n);
    let mut attempts = 0usize;
    while out.len() < n && attempts < n * 1000 {
        attempts += 1;
        let origin = point_in(rng, r);
        let angle = rng.range(0.0, std::f64::consts::TAU);
        let dir = Vec2::new(libm::cos(angle), libm::sin(angle));
        if !r.contains(origin + dir * RAY_LENGTH) || !rapier.overlap_point(origin).is_empty() {
            continue;
        }
        out.push((origin, dir));
    }
    out
}

/// The median body's half size (its shape reach's larger component).
fn typical_half(sim: &Simulation) -> f64 {
    let w = sim.world();
    let mut h: Vec<f64> = (0..w.len())
        .map(|i| {
            let r = shape_reach(w.shape(i));
            r.x.max(r.y)
        })
        .collect();
    h.sort_by(f64::total_cmp);
    h.get(h.len() / 2).copied().unwrap_or(1.0)
}

/// The seeded boxes, each inside `region`.
fn boxes(rng: &mut Rng, r: &Bounds, half: f64, n: usize) -> Vec<Bounds> {
    (0..n)
        .map(|_| {
            let h = Vec2::new(half * rng.range(0.5, 1.5), half * rng.range(0.5, 1.5));
            let inner = Bounds {
                min: r.min + h,
                max: r.max - h,
            };
            Bounds::around(point_in(rng, &inner), h)
        })
        .collect()
}

/// Runs `pass` [`PASSES`] times; the median pass as queries per second, and the last pass's
/// answers.
fn timed<T>(n: usize, mut pass: impl FnMut() -> anyhow::Result<T>) -> anyhow::Result<(f64, T)> {
    let mut times: Vec<Duration> = Vec::with_capacity(PASSES);
    let mut last = None;
    for _ in 0..PASSES {
        let t = Instant::now();
        let answer = pass()?;
        times.push(t.elapsed());
        last = Some(answer);
    }
    let (median_ms, _) = percentiles(&times);
    let answer = last.context("no pass ran")?;
    Ok((n as f64 / (median_ms * 1e-3), answer))
}

/// Whether two first hits agree (see the module docs).
fn rays_agree(a: Option<(Entity, f64)>, b: Option<(Entity, f64)>, tolerance: f64) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some((_, da)), Some((_, db))) => (da - db).abs() <= tolerance,
        _ => false,
    }
}

/// How many differences a row keeps word for word.
const MAX_DETAILS: usize = 10;

/// Keeps a difference word for word, up to [`MAX_DETAILS`].
fn detail(row: &mut QueryRow, text: String) {
    if row.details.len() < MAX_DETAILS {
        row.details.push(text);
    }
}

/// Whether body `e` is apart from the box `b` (Ricochet's exact contact: not overlapping)
/// by at most Box2D's overlap skin: rule `box2d-skin`.
fn within_skin(sim: &Simulation, b: Bounds, e: Entity) -> bool {
    let w = sim.world();
    let Some(i) = w.index_of(e) else {
        return false;
    };
    let Ok(query) = Shape::aabb(b.half_extents()) else {
        return false;
    };
    let c =
        ricochet_sim::geom::contact(&query, &Pose::new(b.center(), 0.0), w.shape(i), &w.pose(i));
    c.depth <= 0.0 && -c.depth <= BOX2D_OVERLAP_SKIN + BOX2D_SKIN_SLACK
}

/// Runs one scene's queries on all three engines.
pub fn run_queries(name: &str, scene: Scene, frames: u64) -> anyhow::Result<QueryRow> {
    let mut sim = Simulation::from_scenario(scene.build(frames));
    for _ in 0..=frames {
        drop(sim.step());
    }
    let mut rapier = RapierScene::new(&sim).with_context(|| format!("{name}: rapier scene"))?;
    rapier.step();
    let mut box2d = Box2dScene::new(&sim).with_context(|| format!("{name}: Box2D scene"))?;
    box2d
        .step()
        .with_context(|| format!("{name}: Box2D step"))?;
    let area = region(&sim);
    let mut rng = Rng::new(SEED);
    let rays = rays(&mut rng, &area, &rapier, QUERIES);
    let boxes = boxes(&mut rng, &area, typical_half(&sim), QUERIES);
    let all = QueryFilter::all();

    let (ricochet_rps, ricochet_rays) = timed(rays.len(), || {
        Ok(rays
            .iter()
            .map(|&(o, d)| {
                sim.cast_ray(o, d, RAY_LENGTH, &all)
                    .map(|h| (h.entity, h.distance))
            })
            .collect::<Vec<_>>())
    })?;
    let (rapier_rps, rapier_rays) = timed(rays.len(), || {
        Ok(rays
            .iter()
            .map(|&(o, d)| {
                rapier
                    .cast_ray(o, d, RAY_LENGTH)
                    .map(|h| (h.entity, h.distance))
            })
            .collect::<Vec<_>>())
    })?;
    let (box2d_rps, box2d_raw) = timed(rays.len(), || {
        let q = box2d.queries()?;
        rays.iter()
            .map(|&(o, d)| q.cast_ray(o, d, RAY_LENGTH))
            .collect::<Result<Vec<_>, _>>()
            .map_err(anyhow::Error::from)
    })?;
    let (ricochet_ops, ricochet_sets) = timed(boxes.len(), || {
        Ok(boxes
            .iter()
            .map(|b| sim.overlap_aabb(*b, &all))
            .collect::<Vec<_>>())
    })?;
    let (rapier_ops, rapier_sets) = timed(boxes.len(), || {
        Ok(boxes
            .iter()
            .map(|b| rapier.overlap_aabb(*b))
            .collect::<Vec<_>>())
    })?;
    let (box2d_ops, box2d_sets_raw) = timed(boxes.len(), || {
        let q = box2d.queries()?;
        boxes
            .iter()
            .map(|b| q.overlap_box(*b))
            .collect::<Result<Vec<_>, _>>()
            .map_err(anyhow::Error::from)
    })?;
    let (box2d_aabb_ops, box2d_aabb_sets) = timed(boxes.len(), || {
        let q = box2d.queries()?;
        boxes
            .iter()
            .map(|b| q.overlap_aabb(*b))
            .collect::<Result<Vec<_>, _>>()
            .map_err(anyhow::Error::from)
    })?;

    // Box2D's answers as entities, untimed.
    let mut box2d_rays = Vec::with_capacity(box2d_raw.len());
    for hit in box2d_raw {
        box2d_rays.push(match hit {
            Some(h) => Some((box2d.entity(h.shape)?, h.distance)),
            None => None,
        });
    }
    let mut box2d_sets = Vec::with_capacity(box2d_sets_raw.len());
    for shapes in box2d_sets_raw {
        let mut set = Vec::with_capacity(shapes.len());
        for s in shapes {
            set.push(box2d.entity(s)?);
        }
        set.sort_unstable();
        box2d_sets.push(set);
    }

    let mut row = QueryRow {
        scene: name.to_owned(),
        bodies: sim.world().len(),
        rays: rays.len(),
        boxes: boxes.len(),
        rays_per_s: [ricochet_rps, rapier_rps, box2d_rps],
        overlaps_per_s: [ricochet_ops, rapier_ops, box2d_ops, box2d_aabb_ops],
        ..QueryRow::default()
    };
    let count = |v: &[Option<(Entity, f64)>]| v.iter().filter(|h| h.is_some()).count();
    row.ray_hits = [
        count(&ricochet_rays),
        count(&rapier_rays),
        count(&box2d_rays),
    ];
    let total = |v: &[Vec<Entity>]| v.iter().map(Vec::len).sum();
    row.overlap_hits = [
        total(&ricochet_sets),
        total(&rapier_sets),
        total(&box2d_sets),
        box2d_aabb_sets.iter().map(Vec::len).sum(),
    ];
    for (k, (o, d)) in rays.iter().enumerate() {
        let ours = ricochet_rays[k];
        for (engine, theirs, tolerance) in [
            (0, rapier_rays[k], RAPIER_RAY_TOLERANCE),
            (1, box2d_rays[k], BOX2D_RAY_TOLERANCE),
        ] {
            if !rays_agree(ours, theirs, tolerance) {
                row.ray_differences[engine] += 1;
                if row.details.len() < MAX_DETAILS {
                    row.details.push(format!(
                        "ray {k} from ({}, {}) along ({}, {}): ricochet {ours:?}, {} {theirs:?}",
                        o.x,
                        o.y,
                        d.x,
                        d.y,
                        ["rapier", "box2d"][engine]
                    ));
                }
            }
        }
    }
    for (k, b) in boxes.iter().enumerate() {
        let ours = &ricochet_sets[k];
        if ours != &rapier_sets[k] {
            row.overlap_differences[0] += 1;
            detail(
                &mut row,
                format!(
                    "box {k} {:?}..{:?}: ricochet {ours:?}, rapier {:?}",
                    b.min, b.max, rapier_sets[k]
                ),
            );
        }
        let theirs = &box2d_sets[k];
        if ours == theirs {
            continue;
        }
        // Box2D's extra bodies within its skin are the rule; anything else is a difference.
        let skin: Vec<Entity> = theirs
            .iter()
            .copied()
            .filter(|e| !ours.contains(e) && within_skin(&sim, *b, *e))
            .collect();
        let mut rest = theirs.clone();
        rest.retain(|e| !skin.contains(e));
        if &rest == ours {
            row.box2d_skin += skin.len();
        } else {
            row.overlap_differences[1] += 1;
            detail(
                &mut row,
                format!(
                    "box {k} {:?}..{:?}: ricochet {ours:?}, box2d {theirs:?}",
                    b.min, b.max
                ),
            );
        }
    }
    Ok(row)
}

/// What the table's columns mean, printed below it.
pub const NOTES: &str = "queries per second, median of 5 passes over the same seeded batch \
                         (rays 20 units long from outside every body; boxes of 0.5-1.5 times the \
                         median body's half size), every query inside the world's bounds by the \
                         largest body reach plus 1 (no wrap seam); rapier = QueryPipeline \
                         (cast_ray_and_get_normal solid, intersect_shape with a cuboid); box2d \
                         = b2World_CastRayClosest, b2World_OverlapShape with the box (exact), \
                         b2 aabb = b2World_OverlapAABB (tree boxes only, fattened: not \
                         compared); hits = rays that hit / entities found; diff = queries whose \
                         answer differs from Ricochet's (rays: distance beyond 1e-7 for rapier, \
                         1e-3 for Box2D's f32; boxes: a different set), unexplained; b2 skin = \
                         bodies only Box2D's exact overlap finds, apart from the box by at most \
                         its skin 0.1 x B2_LINEAR_SLOP = 5e-4 (+2e-5 f32 slack) by Ricochet's \
                         exact contact (rule box2d-skin: Box2D counts them, Ricochet counts \
                         depth > 0 only)";

/// The table of every scene, then each scene's first differences.
#[must_use]
pub fn table(rows: &[QueryRow]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{:<24} {:>8} {:>11} {:>11} {:>11} {:>17} {:>9} {:>11} {:>11} {:>11} {:>11} {:>23} {:>9} \
         {:>8}",
        "scene",
        "bodies",
        "rays/s",
        "rapier",
        "box2d",
        "ray hits r/ra/b2",
        "ray diff",
        "overlaps/s",
        "rapier",
        "box2d",
        "b2 aabb",
        "found r/ra/b2/b2aabb",
        "box diff",
        "b2 skin"
    );
    for r in rows {
        let _ = writeln!(
            s,
            "{:<24} {:>8} {:>11.0} {:>11.0} {:>11.0} {:>17} {:>9} {:>11.0} {:>11.0} {:>11.0} \
             {:>11.0} {:>23} {:>9} {:>8}",
            r.scene,
            r.bodies,
            r.rays_per_s[0],
            r.rays_per_s[1],
            r.rays_per_s[2],
            format!("{}/{}/{}", r.ray_hits[0], r.ray_hits[1], r.ray_hits[2]),
            format!("{}/{}", r.ray_differences[0], r.ray_differences[1]),
            r.overlaps_per_s[0],
            r.overlaps_per_s[1],
            r.overlaps_per_s[2],
            r.overlaps_per_s[3],
            format!(
                "{}/{}/{}/{}",
                r.overlap_hits[0], r.overlap_hits[1], r.overlap_hits[2], r.overlap_hits[3]
            ),
            format!("{}/{}", r.overlap_differences[0], r.overlap_differences[1]),
            r.box2d_skin,
        );
    }
    for r in rows {
        for d in &r.details {
            let _ = writeln!(s, "{}: {d}", r.scene);
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use ricochet_sim::{BodyDef, BodyKind, Layers, WorldDef};

    use super::*;

    /// A static unit box (half extents 0.5) at the origin, and a query box whose left face
    /// is `gap` from its right face (x = 0.5).
    fn skin(gap: f64) -> bool {
        let mut sim = Simulation::from_def(WorldDef {
            layers: Layers::new(vec!["a".into()]),
            gravity: Vec2::ZERO,
            ..WorldDef::default()
        })
        .unwrap();
        let e = sim.spawn(&BodyDef {
            kind: BodyKind::Static,
            shape: Shape::aabb(Vec2::splat(0.5)).unwrap(),
            ..BodyDef::default()
        });
        let b = Bounds {
            min: Vec2::new(0.5 + gap, -0.25),
            max: Vec2::new(1.5 + gap, 0.25),
        };
        within_skin(&sim, b, e)
    }

    #[test]
    fn box2d_skin_counts_only_bodies_apart_by_at_most_the_skin() {
        // The platformer-100-10 case: 3.4e-4 apart, inside Box2D's 5e-4.
        assert!(skin(3.4e-4));
        assert!(skin(0.0));
        assert!(skin(BOX2D_OVERLAP_SKIN + BOX2D_SKIN_SLACK * 0.5));
        // Beyond the skin and its f32 slack, or overlapping: a real difference.
        assert!(!skin(BOX2D_OVERLAP_SKIN + BOX2D_SKIN_SLACK * 2.0));
        assert!(!skin(1e-3));
        assert!(!skin(-1e-3));
    }
}
