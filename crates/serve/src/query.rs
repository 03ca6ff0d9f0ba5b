//! The `/query` service: a scene query of the simulation as it stands between two frames
//! (the state the clients were last sent), in JSON, answered with the hits.
//!
//! A request is one of four kinds (`kind`), each with an optional `layers` (layer names:
//! only their bodies are seen; default every layer):
//!
//! | kind | fields | asks |
//! |---|---|---|
//! | `ray` | `origin: [x, y]`, `direction: [x, y]` (any length but 0), `max_distance` (0 to 1e15), `all` (default false) | [`Simulation::cast_ray`], or [`Simulation::cast_ray_all`] with `all` |
//! | `point` | `point: [x, y]` | [`Simulation::overlap_point`] |
//! | `aabb` | `min: [x, y]`, `max: [x, y]` | [`Simulation::overlap_aabb`] |
//! | `shape` | `shape` (a scenario file's shape table in JSON: `{"kind": "circle", "radius": 0.5}`, `{"kind": "obb", "half_extents": [1, 0.5]}`, `capsule`, `polygon`, `compound`), `position: [x, y]`, `angle` (radians, default 0) | [`Simulation::overlap_shape`] |
//!
//! The answer is `{"frame": F, "count": N, "hits": [...], "truncated": T}`: `F` the next
//! frame (the state asked is the one after frame `F - 1`), `N` the number of hits, and at
//! most [`MAX_HITS`] of them listed (`truncated` says whether some were left out). A hit is
//! `{"body": "5:1", "name": "rock", "layer": "rocks"}`, and for a ray also `point`,
//! `normal` and `distance` as [`ricochet_sim::RayHit`] gives them (the order and the
//! conventions are the API's: `crates/sim/src/query/mod.rs`).
//!
//! A bad request (malformed JSON, an unknown field or layer, a coordinate that is not
//! finite or beyond ±1e15, a zero direction, `min` above `max`, an invalid shape) is a
//! service-call failure naming the field; nothing is asked of the simulation then.

use ricochet_geom::{Bounds, MAX_COORDINATE, Number, Pose, Shape, ShapeDef, Vec2};
use ricochet_sim::{Entity, QueryFilter, Simulation};
use serde::Deserialize;
use serde_json::{Value, json};

/// Hits listed at most in one answer (about 150 bytes each): the answer stays small
/// whatever the scene and the query.
pub const MAX_HITS: usize = 256;

/// A `/query` request, as parsed (not yet checked against the scenario).
#[derive(Deserialize, Debug, Clone, PartialEq)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Request {
    /// A ray.
    Ray {
        /// Where it starts.
        origin: [f64; 2],
        /// Where it goes (normalised; not zero).
        direction: [f64; 2],
        /// How far it looks.
        max_distance: f64,
        /// Every body it hits (else the first).
        #[serde(default)]
        all: bool,
        /// Only these layers' bodies.
        #[serde(default)]
        layers: Option<Vec<String>>,
    },
    /// The bodies a point is inside.
    Point {
        /// The point.
        point: [f64; 2],
        /// Only these layers' bodies.
        #[serde(default)]
        layers: Option<Vec<String>>,
    },
    /// The bodies overlapping a box.
    Aabb {
        /// Its lower corner.
        min: [f64; 2],
        /// Its upper corner.
        max: [f64; 2],
        /// Only these layers' bodies.
        #[serde(default)]
        layers: Option<Vec<String>>,
    },
    /// The bodies overlapping a shape.
    Shape {
        /// The shape, as a scenario file gives one.
        shape: ShapeDef,
        /// Where it is.
        position: [f64; 2],
        /// Its angle, radians.
        #[serde(default)]
        angle: f64,
        /// Only these layers' bodies.
        #[serde(default)]
        layers: Option<Vec<String>>,
    },
}

/// Parses a `/query` request's JSON (the scenario's checks come when it is answered).
pub fn parse(body: &[u8]) -> Result<Request, String> {
    serde_json::from_slice(body).map_err(|e| format!("bad request: {e}"))
}

/// `[x, y]` as a point, if finite and within ±1e15 (a scenario file's coordinates).
fn point(field: &str, v: [f64; 2]) -> Result<Vec2, String> {
    let p = Vec2::new(v[0], v[1]);
    if p.is_finite() && p.abs().max_element() <= MAX_COORDINATE {
        Ok(p)
    } else {
        Err(format!(
            "{field}: [{}, {}] must be finite numbers within ±{MAX_COORDINATE:e}",
            Number(v[0]),
            Number(v[1])
        ))
    }
}

/// The filter for `layers` (every layer when none are named).
fn filter(sim: &Simulation, layers: Option<&[String]>) -> Result<QueryFilter, String> {
    let Some(names) = layers else {
        return Ok(QueryFilter::all());
    };
    let known = &sim.scenario().world.layers;
    let mut ids = Vec::with_capacity(names.len());
    for name in names {
        let id = known.id(name).ok_or_else(|| {
            format!(
                "layers: no layer {name:?} (the scenario has {:?})",
                known.names()
            )
        })?;
        ids.push(id);
    }
    Ok(QueryFilter::layers(&ids))
}

/// A body as a hit names it: its id, name and layer's name.
fn body(sim: &Simulation, e: Entity) -> Value {
    let layer = sim
        .layer(e)
        .map_or("?", |l| sim.scenario().world.layers.name(l));
    json!({
        "body": e.to_string(),
        "name": sim.name(e).unwrap_or("?"),
        "layer": layer,
    })
}

/// Answers `request` on `sim`, whose next frame is `frame`: the JSON answer, or why the
/// request is refused.
pub fn answer(sim: &Simulation, frame: u64, request: &Request) -> Result<String, String> {
    let (count, hits): (usize, Vec<Value>) = match request {
        Request::Ray {
            origin,
            direction,
            max_distance,
            all,
            layers,
        } => {
            let origin = point("origin", *origin)?;
            let direction = point("direction", *direction)?;
            if direction == Vec2::ZERO {
                return Err("direction: must not be [0, 0]".to_owned());
            }
            if !(max_distance.is_finite() && (0.0..=MAX_COORDINATE).contains(max_distance)) {
                return Err(format!(
                    "max_distance: {} must be 0 to {MAX_COORDINATE:e}",
                    Number(*max_distance)
                ));
            }
            let filter = filter(sim, layers.as_deref())?;
            let found = if *all {
                sim.cast_ray_all(origin, direction, *max_distance, &filter)
            } else {
                sim.cast_ray(origin, direction, *max_distance, &filter)
                    .into_iter()
                    .collect()
            };
            let listed = found
                .iter()
                .take(MAX_HITS)
                .map(|h| {
                    let mut v = body(sim, h.entity);
                    v["point"] = json!([h.point.x, h.point.y]);
                    v["normal"] = json!([h.normal.x, h.normal.y]);
                    v["distance"] = json!(h.distance);
                    v
                })
                .collect();
            (found.len(), listed)
        }
        Request::Point {
            point: p,
            layers: l,
        } => {
            let p = point("point", *p)?;
            let found = sim.overlap_point(p, &filter(sim, l.as_deref())?);
            listed(sim, &found)
        }
        Request::Aabb { min, max, layers } => {
            let (min, max) = (point("min", *min)?, point("max", *max)?);
            if min.x > max.x || min.y > max.y {
                return Err("min: must be at or below max on both axes".to_owned());
            }
            let found = sim.overlap_aabb(Bounds { min, max }, &filter(sim, layers.as_deref())?);
            listed(sim, &found)
        }
        Request::Shape {
            shape,
            position,
            angle,
            layers,
        } => {
            let shape: Shape = shape.to_shape().map_err(|e| format!("shape: {e}"))?;
            let position = point("position", *position)?;
            if !angle.is_finite() {
                return Err(format!("angle: {} must be finite", Number(*angle)));
            }
            let pose = Pose::new(position, *angle);
            let reach = shape.bounds(&pose);
            point("shape's bounds", [reach.min.x, reach.min.y])?;
            point("shape's bounds", [reach.max.x, reach.max.y])?;
            let found = sim.overlap_shape(&shape, pose, &filter(sim, layers.as_deref())?);
            listed(sim, &found)
        }
    };
    let answer = json!({
        "frame": frame,
        "count": count,
        "hits": hits,
        "truncated": count > MAX_HITS,
    });
    Ok(answer.to_string())
}

/// The first [`MAX_HITS`] of `found` as hits, and how many there are.
fn listed(sim: &Simulation, found: &[Entity]) -> (usize, Vec<Value>) {
    let hits = found.iter().take(MAX_HITS).map(|&e| body(sim, e)).collect();
    (found.len(), hits)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_kind_parses_and_unknown_fields_or_kinds_are_refused() {
        let ray = parse(br#"{"kind": "ray", "origin": [0, 0], "direction": [1, 0], "max_distance": 5, "layers": ["rock"]}"#);
        assert_eq!(
            ray,
            Ok(Request::Ray {
                origin: [0.0, 0.0],
                direction: [1.0, 0.0],
                max_distance: 5.0,
                all: false,
                layers: Some(vec!["rock".to_owned()]),
            })
        );
        let shape = parse(
            br#"{"kind": "shape", "shape": {"kind": "circle", "radius": 0.5}, "position": [1, 2]}"#,
        );
        assert!(matches!(shape, Ok(Request::Shape { angle, .. }) if angle == 0.0));
        for bad in [
            &br#"{"kind": "ray", "origin": [0, 0], "direction": [1, 0], "max_distance": 5, "color": 1}"#[..],
            br#"{"kind": "cone", "point": [0, 0]}"#,
            br#"{"kind": "point", "point": [0]}"#,
            br#"{"kind": "point", "point": [NaN, 0]}"#,
            br#"{"kind": "point", "point": [1e999, 0]}"#,
            br#"{"point": [0, 0]}"#,
            b"not json",
        ] {
            let e = parse(bad).unwrap_err();
            assert!(e.starts_with("bad request: "), "{e}");
        }
    }
}
