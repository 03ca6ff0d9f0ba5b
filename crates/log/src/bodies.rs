//! Every body's full state, frame by frame, rebuilt from a log's `/bodies` messages.
//!
//! `/bodies` lists every body with every field at a keyframe, and between keyframes only
//! what changed (see `proto/ricochet.proto`). [`BodyStates`] applies the messages in order
//! and gives each frame as if it listed every body in full: what `ricochet diff` and any
//! reader that wants whole frames need. Memory is one state per live body.

use std::collections::BTreeMap;

use serde_json::{Map, Value};

/// The bodies alive after the messages applied so far, by `(id, generation)`.
#[derive(Debug, Default, Clone)]
pub struct BodyStates {
    bodies: BTreeMap<(u64, u64), Map<String, Value>>,
}

fn key(body: &Value) -> Option<(u64, u64)> {
    Some((
        body.get("id")?.as_u64()?,
        body.get("generation").and_then(Value::as_u64).unwrap_or(0),
    ))
}

/// Whether a field of a delta holds a value: a non-empty list, or any other value.
fn present(value: &Value) -> bool {
    !matches!(value, Value::Null) && value.as_array().is_none_or(|a| !a.is_empty())
}

impl BodyStates {
    /// Applies one `/bodies` message (decoded to JSON) and returns the frame in full: the
    /// same message with every live body listed with every field, sorted by id and
    /// generation, and `keyframe` true.
    pub fn apply(&mut self, message: &Value) -> Value {
        let keyframe = message
            .get("keyframe")
            .and_then(Value::as_bool)
            .unwrap_or(false);
        if keyframe {
            self.bodies.clear();
        }
        let list = |name: &str| message.get(name).and_then(Value::as_array);
        for body in list("removed").into_iter().flatten() {
            if let Some(k) = key(body) {
                self.bodies.remove(&k);
            }
        }
        for body in list("bodies").into_iter().flatten() {
            let (Some(k), Some(fields)) = (key(body), body.as_object()) else {
                continue;
            };
            let state = self.bodies.entry(k).or_default();
            for (name, value) in fields {
                if present(value) || !state.contains_key(name) {
                    state.insert(name.clone(), value.clone());
                }
            }
        }
        let mut full = message.as_object().cloned().unwrap_or_default();
        full.insert("keyframe".to_owned(), Value::Bool(true));
        full.insert(
            "bodies".to_owned(),
            Value::Array(self.bodies.values().cloned().map(Value::Object).collect()),
        );
        Value::Object(full)
    }

    /// The state of body `id` of generation `generation`, if it is alive.
    pub fn get(&self, id: u64, generation: u64) -> Option<&Map<String, Value>> {
        self.bodies.get(&(id, generation))
    }

    /// How many bodies are alive.
    pub fn len(&self) -> usize {
        self.bodies.len()
    }

    /// Whether no body is alive.
    pub fn is_empty(&self) -> bool {
        self.bodies.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn deltas_keep_what_they_do_not_list_and_keyframes_replace_everything() {
        let mut s = BodyStates::default();
        let k = s.apply(&json!({"frame": 0, "keyframe": true, "removed": [], "bodies": [
            {"id": 2, "generation": 0, "name": "b", "position": [1.0, 2.0], "angle": 0.5, "velocity": [3.0, 4.0]},
            {"id": 1, "generation": 0, "name": "a", "position": [0.0, 0.0], "angle": 0.0, "velocity": [0.0, 0.0]},
        ]}));
        assert_eq!(k["bodies"][0]["name"], "a", "sorted by id");
        let d = s.apply(
            &json!({"frame": 1, "keyframe": false, "removed": [], "bodies": [
                {"id": 2, "generation": 0, "position": [1.5, 2.0], "velocity": []},
            ]}),
        );
        assert_eq!(
            d["bodies"][1],
            json!({"id": 2, "generation": 0, "name": "b", "position": [1.5, 2.0], "angle": 0.5, "velocity": [3.0, 4.0]})
        );
        let r = s.apply(
            &json!({"frame": 2, "keyframe": false, "bodies": [], "removed": [
                {"id": 1, "generation": 0, "name": "a"},
            ]}),
        );
        assert_eq!(r["bodies"].as_array().unwrap().len(), 1);
        let k = s.apply(&json!({"frame": 3, "keyframe": true, "removed": [], "bodies": []}));
        assert!(k["bodies"].as_array().unwrap().is_empty() && s.is_empty());
    }
}
