//! Two decoded messages compared field by field: the first path where they differ, with
//! both values, and the body it is in. Lists of bodies are matched by id and generation.

use std::collections::{BTreeMap, BTreeSet};

use crate::LogMessage;
use serde_json::Value;

use super::Divergence;
use crate::escape_controls;

/// Compares two JSON values; returns the first differing path with both values.
fn compare(
    a: &Value,
    b: &Value,
    tol: f64,
    path: &mut String,
    body: &mut Option<Label>,
) -> Option<(String, String, String)> {
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (
                x.as_f64().unwrap_or(f64::NAN),
                y.as_f64().unwrap_or(f64::NAN),
            );
            let same = if tol == 0.0 {
                x == y
            } else {
                (x - y).abs() <= tol
            };
            (!same).then(|| (path.clone(), a.to_string(), b.to_string()))
        }
        (Value::Object(x), Value::Object(y)) => {
            for (k, va) in x {
                let len = path.len();
                if !path.is_empty() {
                    path.push('.');
                }
                path.push_str(k);
                let found = match y.get(k) {
                    None => Some((path.clone(), va.to_string(), "missing".to_owned())),
                    Some(vb) => compare(va, vb, tol, path, body),
                };
                if found.is_some() {
                    return found;
                }
                path.truncate(len);
            }
            y.keys().find(|k| !x.contains_key(*k)).map(|k| {
                (
                    format!("{path}.{k}"),
                    "missing".to_owned(),
                    y[k].to_string(),
                )
            })
        }
        (Value::Array(x), Value::Array(y)) => compare_arrays(x, y, tol, path, body),
        _ => (a != b).then(|| (path.clone(), a.to_string(), b.to_string())),
    }
}

/// A body's id in a log: its `id` and, in logs that have one, its `generation` (a slot
/// reused by a later body has the next generation, so id and generation name one body).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(super) struct BodyId {
    id: u64,
    generation: Option<u64>,
}

impl std::fmt::Display for BodyId {
    /// `id:generation` as the logs write a body, or `id` in a log without generations.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.generation {
            Some(g) => write!(f, "{}:{g}", self.id),
            None => write!(f, "{}", self.id),
        }
    }
}

/// The body named by field `id` (with its generation in field `generation`) of an object.
fn body_id(v: &Value, id: &str, generation: &str) -> Option<BodyId> {
    Some(BodyId {
        id: v.get(id).and_then(Value::as_u64)?,
        generation: v.get(generation).and_then(Value::as_u64),
    })
}

/// The id of a list element that is an object with one (bodies in `/bodies`).
pub(super) fn id_of(v: &Value) -> Option<BodyId> {
    body_id(v, "id", "generation")
}

/// How a report names the body or pair a difference is in, and the body's id when the
/// element lists no name (a `/bodies` delta between keyframes), for [`super::diff_files`] to
/// find the name in an earlier message.
pub(super) struct Label {
    pub(super) text: String,
    pub(super) unnamed: Option<BodyId>,
}

fn labelled(v: &Value) -> Label {
    let unnamed = id_of(v).filter(|_| v.get("name").and_then(Value::as_str).is_none());
    Label {
        text: label(v),
        unnamed,
    }
}

fn label(v: &Value) -> String {
    let pair = (
        body_id(v, "a", "a_generation"),
        body_id(v, "b", "b_generation"),
    );
    match (id_of(v), v.get("name").and_then(Value::as_str), pair) {
        (Some(id), Some(name), _) => format!("{id} ({})", escape_controls(name)),
        (Some(id), None, _) => id.to_string(),
        (None, _, (Some(a), Some(b))) => format!("pair {a}/{b}"),
        _ => String::new(),
    }
}

fn compare_arrays(
    x: &[Value],
    y: &[Value],
    tol: f64,
    path: &mut String,
    body: &mut Option<Label>,
) -> Option<(String, String, String)> {
    // Lists of bodies are matched by id (and generation), so one extra body is reported as
    // that body, not as every later element shifted by one.
    let by_id = x.iter().chain(y).all(|v| id_of(v).is_some()) && !x.is_empty() && !y.is_empty();
    if by_id {
        let ys: BTreeMap<BodyId, &Value> =
            y.iter().filter_map(|v| id_of(v).map(|i| (i, v))).collect();
        for va in x {
            let Some(id) = id_of(va) else { continue };
            let len = path.len();
            path.push_str(&format!("[id={id}]"));
            let found = match ys.get(&id) {
                None => Some((path.clone(), va.to_string(), "missing".to_owned())),
                Some(vb) => compare(va, vb, tol, path, body),
            };
            if found.is_some() {
                *body = Some(labelled(va));
                return found;
            }
            path.truncate(len);
        }
        let xs: BTreeSet<BodyId> = x.iter().filter_map(id_of).collect();
        return y
            .iter()
            .find(|v| id_of(v).is_some_and(|i| !xs.contains(&i)))
            .map(|vb| {
                *body = Some(labelled(vb));
                (
                    format!(
                        "{path}[id={}]",
                        id_of(vb).map(|i| i.to_string()).unwrap_or_default()
                    ),
                    "missing".to_owned(),
                    vb.to_string(),
                )
            });
    }
    for (i, (va, vb)) in x.iter().zip(y).enumerate() {
        let len = path.len();
        path.push_str(&format!("[{i}]"));
        if let Some(found) = compare(va, vb, tol, path, body) {
            if body.is_none() && !label(va).is_empty() {
                *body = Some(labelled(va));
            }
            return Some(found);
        }
        path.truncate(len);
    }
    (x.len() != y.len()).then(|| {
        (
            format!("{path}.length"),
            x.len().to_string(),
            y.len().to_string(),
        )
    })
}

pub(super) fn first_in_message(
    topic: &str,
    a: &LogMessage,
    b: &LogMessage,
    tol: f64,
) -> Option<Divergence> {
    let mut path = String::new();
    let mut body = None;
    let time_differs = a.log_time != b.log_time;
    let found = if time_differs {
        Some((
            "log_time".to_owned(),
            a.log_time.to_string(),
            b.log_time.to_string(),
        ))
    } else {
        compare(&a.data, &b.data, tol, &mut path, &mut body)
    };
    let (body, unnamed) = body.map_or((None, None), |l| (Some(l.text), l.unnamed));
    found.map(|(field, va, vb)| Divergence {
        topic: topic.to_owned(),
        time_ns: a.log_time.min(b.log_time),
        frame: a.data.get("frame").and_then(Value::as_u64),
        body,
        unnamed,
        field,
        a: va,
        b: vb,
    })
}
