//! The checks of one drawn entity: per-body metadata, f32 numbers, the contact normals, and
//! every primitive where `ricochet_geom::place` puts its body's shape. See `seek.rs`.

use std::collections::BTreeMap;

use ricochet_geom::{PlacedPrimitive, Pose, Vec2, place};
use serde_json::Value;

use super::log::*;
use crate::util::shape_def;

/// Per-body: each of `ours` an entity of its own, named and described as its body.
pub(super) fn check_per_body(
    shown: &BTreeMap<String, Value>,
    ours: &[&Value],
    statics: bool,
    report: &mut impl FnMut(String),
) {
    let want: BTreeMap<String, &Value> = ours
        .iter()
        .map(|b| (format!("body/{}", body_id(b)), *b))
        .collect();
    let missing: Vec<&String> = want.keys().filter(|id| !shown.contains_key(*id)).collect();
    let extra: Vec<&String> = shown.keys().filter(|id| !want.contains_key(*id)).collect();
    if !missing.is_empty() || !extra.is_empty() {
        report(format!(
            "alive, not shown {missing:?}; shown, not a live body of this topic {extra:?}"
        ));
    }
    for (id, body) in want {
        let Some(e) = shown.get(&id) else { continue };
        let name = body["name"].as_str().unwrap();
        let mut report = |p: String| report(format!("{id} \"{name}\": {p}"));
        let meta = metadata(e);
        let mut want = vec![
            ("name", name.to_owned()),
            ("id", body_id(body)),
            ("layer", body["layer"].as_str().unwrap().to_owned()),
        ];
        let kind = meta.get(3).map(|(_, v)| v.as_str());
        let kind_ok = if statics {
            kind == Some("static")
        } else {
            matches!(kind, Some("dynamic" | "kinematic"))
        };
        want.push(("kind", kind.filter(|_| kind_ok).unwrap_or("?").to_owned()));
        let same_keys = meta.len() == if statics { 4 } else { 6 };
        let head_ok = same_keys
            && meta[..4]
                .iter()
                .zip(&want)
                .all(|((k, v), (wk, wv))| k == wk && v == wv);
        // Velocities to the bit (the scene is sent again when one changes).
        let v = pair(&body["velocity"]);
        let w = num(body, "angular_velocity");
        let speed_ok = statics
            || (same_keys
                && meta[4].0 == "velocity"
                && parse_pair(&meta[4].1).is_some_and(|p| same(p.x, v.x) && same(p.y, v.y))
                && meta[5].0 == "angular_velocity"
                && meta[5].1.parse::<f64>().is_ok_and(|x| same(x, w)));
        if !head_ok || !speed_ok {
            let speed = if statics {
                String::new()
            } else {
                format!(", velocity [{}, {}], angular_velocity {w}", v.x, v.y)
            };
            report(format!("metadata {meta:?}, /bodies: {want:?}{speed}"));
        }
        compare_drawing(e, &[body], &mut report);
    }
}

/// What every entity is: in `world`, not following a frame, no lifetime, every number an
/// f32, only cubes, cylinders and triangles.
pub(super) fn check_entity(id: &str, e: &Value, report: &mut impl FnMut(String)) {
    if e["frame_id"] != "world" || e["frame_locked"] != false {
        report(format!(
            "{id}: in frame {} (locked {}), not in world",
            e["frame_id"], e["frame_locked"]
        ));
    }
    let forever = match &e["lifetime"] {
        Value::Null => true,
        Value::String(s) => s == "0s",
        _ => false,
    };
    if !forever {
        report(format!("{id}: lifetime {}", e["lifetime"]));
    }
    for key in ["arrows", "spheres", "lines", "texts", "models"] {
        if e[key].as_array().is_some_and(|a| !a.is_empty()) {
            report(format!("{id}: {key} drawn"));
        }
    }
    check_f32(e, id, report);
}

/// Every number of `v` (but triangle indices) at f32 precision.
pub(super) fn check_f32(v: &Value, what: &str, report: &mut impl FnMut(String)) {
    fn walk(v: &Value, bad: &mut Vec<f64>) {
        match v {
            Value::Number(n) => {
                let x = n.as_f64().unwrap();
                if f64::from(x as f32) != x {
                    bad.push(x);
                }
            }
            Value::Array(a) => a.iter().for_each(|v| walk(v, bad)),
            Value::Object(o) => o
                .iter()
                .filter(|(k, _)| *k != "indices")
                .for_each(|(_, v)| walk(v, bad)),
            _ => {}
        }
    }
    let mut bad = Vec::new();
    walk(v, &mut bad);
    if !bad.is_empty() {
        report(format!("{what}: numbers not at f32 precision: {bad:?}"));
    }
}

/// The contact normals shown: frame `f`'s contacts (`contacts`, its `/contacts`).
pub(super) fn check_arrows(
    shown: &BTreeMap<String, Value>,
    contacts: &Value,
    report: &mut impl FnMut(String),
) {
    let want: Vec<Vec2> = contacts["contacts"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|c| {
            let (point, normal) = (pair(&c["point"]), pair(&c["normal"]));
            [point, point + normal * num(c, "depth").max(0.8)]
        })
        .collect();
    let ids: Vec<&String> = shown.keys().collect();
    let Some(e) = shown.get("contacts") else {
        if !want.is_empty() || !ids.is_empty() {
            report(format!(
                "/scene/contacts: {ids:?} shown, {} contacts",
                want.len() / 2
            ));
        }
        return;
    };
    let lines = e["lines"].as_array().unwrap();
    let ok = ids.len() == 1
        && e["frame_id"] == "world"
        && lines.len() == 1
        && lines[0]["type"] == "LINE_LIST"
        && Planar::of(&lines[0]).is_ok_and(|p| p.at == Vec2::ZERO && p.yaw == 0.0)
        && lines[0]["indices"].as_array().is_some_and(|i| i.is_empty());
    if !ok {
        report(format!("/scene/contacts: not one line list in world: {e}"));
        return;
    }
    let points = lines[0]["points"].as_array().unwrap();
    let drawn: Vec<Vec2> = points
        .iter()
        .map(|p| Vec2::new(num(p, "x"), num(p, "y")))
        .collect();
    let flat = points.iter().all(|p| num(p, "z") == DEPTH);
    if !flat || drawn.len() != want.len() || !drawn.iter().zip(&want).all(|(&a, &b)| close2(a, b)) {
        report(format!(
            "/scene/contacts: points {drawn:?}, the contacts {want:?}"
        ));
    }
    check_f32(e, "/scene/contacts", report);
}

/// The bit-exact same number.
pub(super) fn same(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits()
}

/// `[x, y]` as `ricochet_geom::Numbers` writes it.
pub(super) fn parse_pair(s: &str) -> Option<Vec2> {
    let (x, y) = s.strip_prefix('[')?.strip_suffix(']')?.split_once(", ")?;
    Some(Vec2::new(x.parse().ok()?, y.parse().ok()?))
}

/// An entity's metadata, as (key, value) pairs in order.
pub(super) fn metadata(e: &Value) -> Vec<(String, String)> {
    let meta = e["metadata"].as_array().unwrap().iter();
    let s = |v: &Value| v.as_str().unwrap().to_owned();
    meta.map(|kv| (s(&kv["key"]), s(&kv["value"]))).collect()
}

/// A body's `ID:GENERATION`.
pub(super) fn body_id(b: &Value) -> String {
    format!("{}:{}", b["id"], b["generation"].as_u64().unwrap_or(0))
}

/// How many parts (primitives) a body's shape has.
pub(super) fn parts(b: &Value) -> usize {
    let shape = shape_def(&b["shape"]).to_shape().unwrap();
    shape.primitives().len()
}

/// Nanoseconds since the epoch of a decoded `google.protobuf.Timestamp` (RFC 3339, UTC, as in
/// "1970-01-01T00:00:00.016666667Z"; Ricochet's logs start at the epoch).
pub(super) fn ns(ts: &Value) -> u64 {
    let s = ts.as_str().unwrap_or_else(|| panic!("a timestamp: {ts}"));
    let (date, time) = s.strip_suffix('Z').and_then(|s| s.split_once('T')).unwrap();
    let day: u64 = date.strip_prefix("1970-01-").unwrap().parse().unwrap();
    let (hms, frac) = time.split_once('.').unwrap_or((time, ""));
    let secs = (hms.split(':')).fold(0, |acc, part| acc * 60 + part.parse::<u64>().unwrap());
    let nanos: u64 = format!("{frac:0<9}").parse().unwrap();
    ((day - 1) * 86_400 + secs) * 1_000_000_000 + nanos
}

/// Foxglove applying a `SceneUpdate`: its deletions, then its entities (added or replaced).
pub(super) fn apply(entities: &mut BTreeMap<String, Value>, update: &Value) {
    for d in update["deletions"].as_array().unwrap() {
        match d["type"].as_str().unwrap() {
            "ALL" => entities.clear(),
            _ => drop(entities.remove(d["id"].as_str().unwrap())),
        }
    }
    for e in update["entities"].as_array().unwrap() {
        entities.insert(e["id"].as_str().unwrap().to_owned(), e.clone());
    }
}

/// The bodies of a full `/bodies` message, by `(id, generation)`: in id order.
pub(super) fn alive(full: &Value) -> BTreeMap<(u64, u64), Value> {
    let bodies = full["bodies"].as_array().unwrap().iter();
    let generation = |b: &Value| b["generation"].as_u64().unwrap_or(0);
    bodies
        .map(|b| ((b["id"].as_u64().unwrap(), generation(b)), b.clone()))
        .collect()
}

/// One drawn cube or cylinder: where, how turned (`None`: any way), how large, and whose.
pub(super) struct Solid {
    pub(super) at: Vec2,
    pub(super) yaw: Option<f64>,
    pub(super) size: Vec2,
    pub(super) what: String,
}

/// Compares entity `e`'s primitives with the shapes of `bodies` (in order) placed at their
/// poses: the cubes, the cylinders and the one triangle list, each in the bodies' order.
pub(super) fn compare_drawing(e: &Value, bodies: &[&Value], report: &mut impl FnMut(String)) {
    let (mut cubes, mut cylinders) = (Vec::new(), Vec::new());
    let (mut points, mut indices, mut fans) = (Vec::new(), Vec::new(), Vec::new());
    for body in bodies {
        let shape = shape_def(&body["shape"]).to_shape().unwrap();
        let pose = Pose::new(pair(&body["position"]), num(body, "angle"));
        for (k, prim) in shape.primitives().iter().enumerate() {
            let what = format!("body {} part {k}", body_id(body));
            let disc = |at: Vec2, radius: f64, what: String| Solid {
                at,
                yaw: Some(0.0),
                size: Vec2::splat(2.0 * radius),
                what,
            };
            match place(prim, &pose, Vec2::ZERO) {
                PlacedPrimitive::Circle(c) => cylinders.push(disc(c.center, c.radius, what)),
                PlacedPrimitive::Aabb(b) => cubes.push(Solid {
                    at: b.center,
                    yaw: Some(0.0),
                    size: 2.0 * b.half,
                    what,
                }),
                PlacedPrimitive::Obb(b) => cubes.push(Solid {
                    at: b.center,
                    yaw: Some(libm::atan2(b.rot.s, b.rot.c)),
                    size: 2.0 * b.half,
                    what,
                }),
                PlacedPrimitive::Capsule(c) => {
                    let d = c.b - c.a;
                    // A capsule of one point: a square, any way round.
                    let turn = (d.length() > 0.0).then(|| libm::atan2(d.y, d.x));
                    cubes.push(Solid {
                        at: (c.a + c.b) * 0.5,
                        yaw: turn,
                        size: Vec2::new(d.length(), 2.0 * c.radius),
                        what: format!("{what} (capsule's segment)"),
                    });
                    for (end, p) in [("a", c.a), ("b", c.b)] {
                        cylinders.push(disc(p, c.radius, format!("{what} (capsule end {end})")));
                    }
                }
                PlacedPrimitive::Polygon(p) => {
                    let first = points.len() as u64;
                    points.extend_from_slice(&p.vertices[..p.count]);
                    let n = p.count as u64;
                    indices.extend((1..n - 1).flat_map(|k| [first, first + k, first + k + 1]));
                    fans.push((first, what));
                }
                // Chain segments are lines, not cubes, cylinders or triangles.
                PlacedPrimitive::Segment(_) => {}
            }
        }
    }
    for (key, want) in [("cubes", cubes), ("cylinders", cylinders)] {
        let drawn = e[key].as_array().unwrap();
        if drawn.len() != want.len() {
            report(format!(
                "{} {key}, the shapes make {}",
                drawn.len(),
                want.len()
            ));
        }
        for (got, want) in drawn.iter().zip(&want) {
            let size = &got["size"];
            let extent = Vec2::new(num(size, "x"), num(size, "y"));
            let ok = match Planar::of(got) {
                Ok(p) => {
                    close2(p.at, want.at)
                        && want.yaw.is_none_or(|yaw| close_angle(p.yaw, yaw))
                        && close2(extent, want.size)
                        && num(size, "z") == DEPTH
                }
                Err(_) => false,
            };
            if !ok {
                report(format!(
                    "{}: drawn {} {}, the shape at {} turned {:?} of size {}",
                    want.what, got["pose"], size, want.at, want.yaw, want.size
                ));
            }
        }
    }
    let lists = e["triangles"].as_array().unwrap();
    if lists.len() != usize::from(!points.is_empty()) {
        report(format!(
            "{} triangle lists, the shapes {} polygons",
            lists.len(),
            fans.len()
        ));
        return;
    }
    let Some(list) = lists.first() else { return };
    if !Planar::of(list).is_ok_and(|p| p.at == Vec2::ZERO && p.yaw == 0.0) {
        report(format!(
            "the triangle list is not in world coordinates: {}",
            list["pose"]
        ));
    }
    let drawn = list["points"].as_array().unwrap();
    let got_indices: Vec<u64> = (list["indices"].as_array().unwrap().iter())
        .map(|i| i.as_u64().unwrap())
        .collect();
    if drawn.len() != points.len() || got_indices != indices {
        report(format!(
            "{} points and indices {got_indices:?}, the polygons {} points and fans {indices:?}",
            drawn.len(),
            points.len()
        ));
        return;
    }
    for (i, (got, &want)) in drawn.iter().zip(&points).enumerate() {
        let p = Vec2::new(num(got, "x"), num(got, "y"));
        if !close2(p, want) || num(got, "z") != 0.0 {
            let whose = fans.iter().rev().find(|f| f.0 <= i as u64).unwrap();
            let vertex = i as u64 - whose.0;
            report(format!(
                "{} vertex {vertex} drawn at {got}, the shape at {want}",
                whose.1
            ));
        }
    }
}
