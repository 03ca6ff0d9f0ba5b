//! Map outlines (in world units, y up) → Ricochet primitives: boxes stay boxes (an AABB when
//! axis-aligned, an OBB when turned), convex outlines become polygons of at most
//! [`MAX_POLYGON_VERTICES`] vertices (a fan of parts when longer), and concave ones are
//! split by ear clipping, then neighbouring triangles are merged while the union stays
//! strictly convex and small enough (Hertel–Mehlhorn).

use std::collections::BTreeMap;

use ricochet_geom::MAX_POLYGON_VERTICES;
use ricochet_geom::{MAX_CHAIN_POINTS, Primitive, Shape, Vec2};

/// How many points an ellipse's polygon has: the 32-gon inscribed in the ellipse (the
/// affine image of a regular 32-gon in the unit circle) is within `1 - cos(pi/32)`, 0.48%, of
/// the longer semi-axis.
pub(crate) const ELLIPSE_POINTS: usize = 32;

/// A shape of the map in world coordinates.
#[derive(Clone, Debug)]
pub(crate) enum Outline {
    /// A disc.
    Circle { center: Vec2, radius: f64 },
    /// A capsule around `a`–`b`.
    Capsule { a: Vec2, b: Vec2, radius: f64 },
    /// A closed outline, either orientation, convex or not (not crossing itself).
    Ring(Vec<Vec2>),
    /// An open line: a polyline, which becomes terrain chains (`build::chains`).
    Line(Vec<Vec2>),
}

fn cross(a: Vec2, b: Vec2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// Twice the signed area (counter-clockwise positive).
fn twice_area(p: &[Vec2]) -> f64 {
    (0..p.len())
        .map(|i| cross(p[i], p[(i + 1) % p.len()]))
        .sum()
}

/// The outline as primitives relative to `origin`, or what is wrong with it.
pub(crate) fn primitives(outline: &Outline, origin: Vec2) -> Result<Vec<Primitive>, String> {
    let shape_err = |e: ricochet_geom::ShapeError| e.to_string();
    match outline {
        Outline::Circle { center, radius } => Ok(vec![
            Primitive::circle(*center - origin, *radius).map_err(shape_err)?,
        ]),
        Outline::Capsule { a, b, radius } => Ok(vec![
            Primitive::capsule(*a - origin, *b - origin, *radius).map_err(shape_err)?,
        ]),
        Outline::Ring(points) => {
            let ring: Vec<Vec2> = points.iter().map(|p| *p - origin).collect();
            ring_primitives(&ring)
        }
        Outline::Line(_) => Err(
            "a polyline among a tile's collision shapes: a chain is a body of its own; draw \
             it on an object layer"
                .to_owned(),
        ),
    }
}

/// Consecutive repeats and straight-through points removed, counter-clockwise.
fn clean(points: &[Vec2]) -> Vec<Vec2> {
    let mut p: Vec<Vec2> = Vec::with_capacity(points.len());
    for &v in points {
        if p.last() != Some(&v) {
            p.push(v);
        }
    }
    while p.len() > 1 && p.first() == p.last() {
        p.pop();
    }
    // Drop points where the outline goes straight on (repeat until none: removing one can
    // make its neighbour straight).
    loop {
        let n = p.len();
        if n < 3 {
            break;
        }
        let straight = (0..n).find(|&i| {
            let a = p[(i + n - 1) % n];
            let b = p[i];
            let c = p[(i + 1) % n];
            let scale = (b - a).length() * (c - b).length();
            cross(b - a, c - b).abs() <= 1e-12 * scale && (b - a).dot(c - b) > 0.0
        });
        match straight {
            Some(i) => {
                p.remove(i);
            }
            None => break,
        }
    }
    if twice_area(&p) < 0.0 {
        p.reverse();
    }
    p
}

fn is_convex(p: &[Vec2]) -> bool {
    let n = p.len();
    n >= 3 && (0..n).all(|i| cross(p[(i + 1) % n] - p[i], p[(i + 2) % n] - p[(i + 1) % n]) > 0.0)
}

/// A rectangle as a box: its centre, half extents along its first edge and the next, and
/// the first edge's angle; `None` when not a rectangle.
fn as_box(p: &[Vec2]) -> Option<(Vec2, Vec2, f64)> {
    if p.len() != 4 {
        return None;
    }
    let e: Vec<Vec2> = (0..4).map(|i| p[(i + 1) % 4] - p[i]).collect();
    for i in 0..4 {
        let (a, b) = (e[i], e[(i + 1) % 4]);
        if a.dot(b).abs() > 1e-9 * a.length() * b.length()
            || (a + e[(i + 2) % 4]).length() > 1e-9 * a.length()
        {
            return None;
        }
    }
    let center = (p[0] + p[2]) * 0.5;
    let half = Vec2::new(e[0].length() * 0.5, e[1].length() * 0.5);
    Some((center, half, libm::atan2(e[0].y, e[0].x)))
}

fn ring_primitives(points: &[Vec2]) -> Result<Vec<Primitive>, String> {
    let p = clean(points);
    if p.len() < 3 || twice_area(&p) <= 0.0 {
        return Err(
            "the outline has no area (fewer than 3 distinct corners, or all in a line)".to_owned(),
        );
    }
    let shape_err = |e: ricochet_geom::ShapeError| e.to_string();
    if let Some((center, half, angle)) = as_box(&p) {
        // Axis-aligned within rounding (a quarter turn's cosine is 6e-17, not 0).
        let s = libm::sin(angle).abs();
        let c = libm::cos(angle).abs();
        if s < 1e-12 || c < 1e-12 {
            let half = if s < 1e-12 {
                half
            } else {
                Vec2::new(half.y, half.x)
            };
            return Ok(vec![Primitive::aabb(center, half).map_err(shape_err)?]);
        }
        return Ok(vec![
            Primitive::obb(center, half, angle).map_err(shape_err)?,
        ]);
    }
    let parts = if is_convex(&p) {
        fan(&p)
    } else {
        split_concave(&p)?
    };
    parts
        .iter()
        .map(|part| Primitive::polygon(part).map_err(shape_err))
        .collect()
}

/// A convex outline as polygons of at most [`MAX_POLYGON_VERTICES`] vertices sharing its
/// first vertex.
pub(crate) fn fan(p: &[Vec2]) -> Vec<Vec<Vec2>> {
    if p.len() <= MAX_POLYGON_VERTICES {
        return vec![p.to_vec()];
    }
    let mut parts = Vec::new();
    let mut k = 1;
    while k + 1 < p.len() {
        let end = (k + MAX_POLYGON_VERTICES - 1).min(p.len());
        let mut part = vec![p[0]];
        part.extend_from_slice(&p[k..end]);
        parts.push(part);
        k = end - 1;
    }
    parts
}

/// Whether `q` is inside or on triangle `a b c` (counter-clockwise).
fn in_triangle(q: Vec2, a: Vec2, b: Vec2, c: Vec2) -> bool {
    cross(b - a, q - a) >= 0.0 && cross(c - b, q - b) >= 0.0 && cross(a - c, q - c) >= 0.0
}

/// Ear clipping (indices into `p`), then merging triangles across their shared edges while
/// the union stays strictly convex with at most [`MAX_POLYGON_VERTICES`] vertices.
fn split_concave(p: &[Vec2]) -> Result<Vec<Vec<Vec2>>, String> {
    let crossing = || {
        "the polygon crosses itself (no convex split exists); redraw it as a simple outline, or \
         as several polygons"
            .to_owned()
    };
    let mut idx: Vec<usize> = (0..p.len()).collect();
    let mut tris: Vec<Vec<usize>> = Vec::with_capacity(p.len());
    while idx.len() > 3 {
        let n = idx.len();
        let ear = (0..n).find(|&i| {
            let (a, b, c) = (idx[(i + n - 1) % n], idx[i], idx[(i + 1) % n]);
            if cross(p[b] - p[a], p[c] - p[b]) <= 0.0 {
                return false;
            }
            idx.iter()
                .all(|&j| j == a || j == b || j == c || !in_triangle(p[j], p[a], p[b], p[c]))
        });
        let Some(i) = ear else {
            return Err(crossing());
        };
        tris.push(vec![idx[(i + n - 1) % n], idx[i], idx[(i + 1) % n]]);
        idx.remove(i);
    }
    if cross(p[idx[1]] - p[idx[0]], p[idx[2]] - p[idx[1]]) <= 0.0 {
        return Err(crossing());
    }
    tris.push(idx);
    // The triangles must tile the outline exactly: a crossing outline's ears overlap.
    let total: f64 = tris
        .iter()
        .map(|t| twice_area(&t.iter().map(|&i| p[i]).collect::<Vec<_>>()))
        .sum();
    if (total - twice_area(p)).abs() > 1e-9 * twice_area(p).abs() {
        return Err(crossing());
    }
    let mut polys: Vec<Option<Vec<usize>>> = tris.into_iter().map(Some).collect();
    loop {
        // Each directed edge → its polygon; an inner edge appears once each way.
        let mut edges: BTreeMap<(usize, usize), usize> = BTreeMap::new();
        for (k, poly) in polys.iter().enumerate() {
            if let Some(poly) = poly {
                for i in 0..poly.len() {
                    edges.insert((poly[i], poly[(i + 1) % poly.len()]), k);
                }
            }
        }
        let mut merged = false;
        for (&(a, b), &k) in &edges {
            let Some(&m) = edges.get(&(b, a)) else {
                continue;
            };
            if m <= k {
                continue;
            }
            let (Some(pk), Some(pm)) = (&polys[k], &polys[m]) else {
                continue;
            };
            if let Some(u) = union(pk, pm, a, b)
                && u.len() <= MAX_POLYGON_VERTICES
                && is_convex(&u.iter().map(|&i| p[i]).collect::<Vec<_>>())
            {
                polys[k] = Some(u);
                polys[m] = None;
                merged = true;
                break;
            }
        }
        if !merged {
            break;
        }
    }
    Ok(polys
        .into_iter()
        .flatten()
        .map(|poly| poly.iter().map(|&i| p[i]).collect())
        .collect())
}

/// The union of two counter-clockwise polygons sharing the edge `a → b` (in `x`) and
/// `b → a` (in `y`).
fn union(x: &[usize], y: &[usize], a: usize, b: usize) -> Option<Vec<usize>> {
    let ib = x.iter().position(|&v| v == b)?;
    let ia = y.iter().position(|&v| v == a)?;
    // `x` from b round to a, then `y` from a round to b, without repeating a and b.
    let mut out: Vec<usize> = (0..x.len()).map(|k| x[(ib + k) % x.len()]).collect();
    out.extend((1..y.len() - 1).map(|k| y[(ia + k) % y.len()]));
    Some(out)
}

/// A polyline's chains, each a body (position: the centre of its points' bounds): one
/// chain of up to [`MAX_CHAIN_POINTS`] points, or several that share their end points and
/// name each other's as ghosts, so the joints between them are as smooth as the rest.
pub(crate) fn chains(points: &[Vec2]) -> Result<Vec<(Vec2, Shape)>, String> {
    if points.len() < 2 {
        return Err(format!(
            "a polyline of {} point(s): a chain needs at least 2",
            points.len()
        ));
    }
    if let Some(k) = (1..points.len()).find(|&k| points[k] == points[k - 1]) {
        return Err(format!(
            "polyline point {k} is on point {}: a chain's segments must have a length; \
             remove the repeated point",
            k - 1
        ));
    }
    let step = MAX_CHAIN_POINTS - 1;
    let mut out = Vec::new();
    let mut start = 0;
    while start + 1 < points.len() {
        let end = (start + step).min(points.len() - 1);
        let part = &points[start..=end];
        let (lo, hi) = part.iter().fold(
            (Vec2::splat(f64::INFINITY), Vec2::splat(f64::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        );
        let origin = (lo + hi) * 0.5;
        let local: Vec<Vec2> = part.iter().map(|p| *p - origin).collect();
        let prev = start.checked_sub(1).map(|k| points[k] - origin);
        let next = points.get(end + 1).map(|p| *p - origin);
        let shape = Shape::chain(&local, prev, next).map_err(|e| e.to_string())?;
        out.push((origin, shape));
        start = end;
    }
    Ok(out)
}
