//! Every body's full state, frame by frame, rebuilt from a log's `/bodies` messages.
//!
//! `/bodies` lists every moving body with every field at a keyframe (a static body only when
//! it appears or changes), and between keyframes only
//! what the integrator does not predict (see `proto/ricochet.proto`): an unlisted position is
//! `previous + velocity * dt`, an unlisted angle `previous + angular_velocity * dt` (IEEE
//! f64, multiply then add), unlisted velocities are unchanged, or, while a body is
//! `falling`, `previous + gravity * dt`. [`BodyStates`] applies the
//! messages in order and gives each frame as if it listed every body in full: what `ricochet
//! diff`, the tests and any reader that wants whole frames need. Memory is one state per
//! live body.

use std::collections::BTreeMap;

use serde_json::{Map, Value, json};

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

fn number(v: Option<&Value>) -> f64 {
    v.and_then(Value::as_f64).unwrap_or(0.0)
}

fn pair(v: Option<&Value>) -> [f64; 2] {
    [
        number(v.and_then(|v| v.get(0))),
        number(v.and_then(|v| v.get(1))),
    ]
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
        let dt = number(message.get("dt"));
        let gravity = pair(message.get("gravity"));
        if keyframe {
            // A keyframe lists every moving body; static ones are listed when they change.
            self.bodies
                .retain(|_, b| b.get("static").and_then(Value::as_bool) == Some(true));
        }
        let list = |name: &str| message.get(name).and_then(Value::as_array);
        for body in list("removed").into_iter().flatten() {
            if let Some(k) = key(body) {
                self.bodies.remove(&k);
            }
        }
        let listed: BTreeMap<(u64, u64), &Map<String, Value>> = list("bodies")
            .into_iter()
            .flatten()
            .filter_map(|b| Some((key(b)?, b.as_object()?)))
            .collect();
        // The bodies known before this frame move as the integrator says, unless listed.
        for (k, state) in &mut self.bodies {
            let delta = listed.get(k);
            let field = |name: &str| delta.and_then(|d| d.get(name)).filter(|v| present(v));
            if let Some(f) = field("falling") {
                state.insert("falling".to_owned(), f.clone());
            }
            if let Some(v) = field("velocity") {
                state.insert("velocity".to_owned(), v.clone());
            } else if state.get("falling").and_then(Value::as_bool) == Some(true) {
                let v = pair(state.get("velocity"));
                let fell = json!([v[0] + gravity[0] * dt, v[1] + gravity[1] * dt]);
                state.insert("velocity".to_owned(), fell);
            }
            if let Some(w) = field("angular_velocity") {
                state.insert("angular_velocity".to_owned(), w.clone());
            }
            if field("still").and_then(Value::as_bool) == Some(true) {
                continue;
            }
            let position = match field("position") {
                Some(p) => p.clone(),
                None => {
                    let (p, v) = (pair(state.get("position")), pair(state.get("velocity")));
                    json!([p[0] + v[0] * dt, p[1] + v[1] * dt])
                }
            };
            let angle = match field("angle") {
                Some(a) => a.clone(),
                None => {
                    let w = number(state.get("angular_velocity"));
                    json!(number(state.get("angle")) + w * dt)
                }
            };
            state.insert("position".to_owned(), position);
            state.insert("angle".to_owned(), angle);
        }
        // New bodies come with every field.
        for (k, fields) in listed {
            if let std::collections::btree_map::Entry::Vacant(slot) = self.bodies.entry(k) {
                let mut state = fields.clone();
                state.remove("still");
                slot.insert(state);
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

    #[test]
    fn unlisted_bodies_move_as_the_integrator_says_and_keyframes_replace_everything() {
        let mut s = BodyStates::default();
        let k = s.apply(&json!({"frame": 0, "keyframe": true, "dt": 0.5, "removed": [], "bodies": [
            {"id": 2, "generation": 0, "name": "b", "position": [1.0, 2.0], "angle": 0.5, "velocity": [3.0, 4.0], "angular_velocity": 1.0},
            {"id": 1, "generation": 0, "name": "a", "position": [0.0, 0.0], "angle": 0.0, "velocity": [0.0, 0.0], "angular_velocity": 0.0},
        ]}));
        assert_eq!(k["bodies"][0]["name"], "a", "sorted by id");
        // Body 2 not listed: 1 + 3 * 0.5, 2 + 4 * 0.5, 0.5 + 1 * 0.5.
        let d = s.apply(
            &json!({"frame": 1, "keyframe": false, "dt": 0.5, "removed": [], "bodies": [
                {"id": 1, "generation": 0, "position": [], "velocity": [2.0, 0.0], "still": false},
            ]}),
        );
        assert_eq!(
            d["bodies"][1],
            json!({"id": 2, "generation": 0, "name": "b", "position": [2.5, 4.0], "angle": 1.0, "velocity": [3.0, 4.0], "angular_velocity": 1.0})
        );
        // Body 1's new velocity moves it this frame already (semi-implicit Euler).
        assert_eq!(d["bodies"][0]["position"], json!([1.0, 0.0]));
        // Still: neither moves, whatever the velocities.
        let st = s.apply(
            &json!({"frame": 2, "keyframe": false, "dt": 0.5, "removed": [], "bodies": [
                {"id": 2, "generation": 0, "position": [], "velocity": [], "still": true},
            ]}),
        );
        assert_eq!(st["bodies"][1]["position"], json!([2.5, 4.0]));
        assert_eq!(st["bodies"][1]["angle"], json!(1.0));
        let r = s.apply(
            &json!({"frame": 3, "keyframe": false, "dt": 0.5, "bodies": [], "removed": [
                {"id": 1, "generation": 0, "name": "a"},
            ]}),
        );
        assert_eq!(r["bodies"].as_array().unwrap().len(), 1);
        let k =
            s.apply(&json!({"frame": 4, "keyframe": true, "dt": 0.5, "removed": [], "bodies": []}));
        assert!(k["bodies"].as_array().unwrap().is_empty() && s.is_empty());
    }

    /// A falling body's velocity advances by `gravity * dt` while it is unlisted, and holds
    /// once `falling: false` is listed: g = [0, -8], dt = 0.25, so each step adds -2 to vy
    /// and the position moves by the new velocity (semi-implicit Euler).
    #[test]
    fn a_falling_body_gains_gravity_each_unlisted_frame_until_it_stops_falling() {
        let mut s = BodyStates::default();
        let g = json!([0.0, -8.0]);
        s.apply(&json!({"frame": 0, "keyframe": true, "dt": 0.25, "gravity": g, "bodies": [
            {"id": 0, "generation": 0, "position": [0.0, 10.0], "angle": 0.0, "velocity": [1.0, 0.0], "angular_velocity": 0.0},
        ]}));
        // Frame 1 switches it to falling: vy = 0 - 2 = -2, y = 10 - 0.5, x = 0 + 0.25.
        let f1 = s.apply(&json!({"frame": 1, "dt": 0.25, "gravity": g, "bodies": [
            {"id": 0, "generation": 0, "falling": true},
        ]}));
        assert_eq!(f1["bodies"][0]["velocity"], json!([1.0, -2.0]));
        assert_eq!(f1["bodies"][0]["position"], json!([0.25, 9.5]));
        // Frame 2, unlisted: vy = -4, y = 9.5 - 1.
        let f2 = s.apply(&json!({"frame": 2, "dt": 0.25, "gravity": g, "bodies": []}));
        assert_eq!(f2["bodies"][0]["velocity"], json!([1.0, -4.0]));
        assert_eq!(f2["bodies"][0]["position"], json!([0.5, 8.5]));
        // Frame 3 lands: velocity [1, 0] listed, then `falling: false` holds it at frame 4.
        s.apply(&json!({"frame": 3, "dt": 0.25, "gravity": g, "bodies": [
            {"id": 0, "generation": 0, "velocity": [1.0, 0.0], "position": [0.75, 8.0]},
        ]}));
        s.apply(&json!({"frame": 4, "dt": 0.25, "gravity": g, "bodies": [
            {"id": 0, "generation": 0, "falling": false},
        ]}));
        let f5 = s.apply(&json!({"frame": 5, "dt": 0.25, "gravity": g, "bodies": []}));
        assert_eq!(f5["bodies"][0]["velocity"], json!([1.0, 0.0]));
        assert_eq!(f5["bodies"][0]["position"], json!([1.25, 8.0]));
    }
}
