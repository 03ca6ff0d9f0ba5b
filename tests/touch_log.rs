//! `/events` of the shipped platformer tells touches, not pushes: every line is a touch's
//! begin or end, or a game event, and the begins and ends are exactly the touches that
//! `/contacts` and `/bodies` show, recomputed here from the rule in `docs/touches.md`:
//!
//! - the pairs touching at the end of frame `f` are those with a contact record in `f`,
//!   plus those touching at `f - 1`, both bodies alive, still within `SLOP` at `f`'s poses
//!   (from `/bodies`, through `ricochet_geom::contact`); the platformer has no sleep, no
//!   active region and no wrap, so the "both at rest" clause and the seam never apply;
//! - a begin for each pair touching at `f` and not at `f - 1`, an end for the reverse.

use std::collections::{BTreeMap, BTreeSet};

use ricochet_geom::{Pose, Shape, Vec2};
use serde_json::Value;

use crate::util::{full_bodies, record, root, shape_def};

/// The engine's `SLOP` (crates/sim/src/stages/mod.rs): resting flush within it is touching.
const SLOP: f64 = 1e-9;

/// `index:generation` of a body.
type Id = (u64, u64);

fn id_of(v: &Value, index: &str, generation: &str) -> Id {
    (
        v[index].as_u64().unwrap(),
        v[generation].as_u64().unwrap_or(0),
    )
}

/// Every `#index:generation` in a line, in order.
fn ids_in(text: &str) -> Vec<Id> {
    text.split('#')
        .skip(1)
        .map(|rest| {
            let (i, after) = rest.split_once(':').expect("index:generation");
            let g: String = after.chars().take_while(char::is_ascii_digit).collect();
            (i.parse().unwrap(), g.parse().unwrap())
        })
        .collect()
}

/// A body's shape and pose from a full `/bodies` entry.
fn placed(b: &Value) -> (Shape, Pose) {
    let shape = shape_def(&b["shape"]).to_shape().unwrap();
    let p = &b["position"];
    let at = Vec2::new(p[0].as_f64().unwrap(), p[1].as_f64().unwrap());
    (shape, Pose::new(at, b["angle"].as_f64().unwrap()))
}

#[test]
fn the_platformers_events_are_its_touches_and_game_events() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("platformer.mcap");
    record(&root().join("scenarios/platformer.toml"), &out);
    let log = ricochet_log::read_log_file(&out).unwrap();
    let frames = full_bodies(&log);
    let dt_ns = log
        .iter()
        .find(|m| m.topic == "/bodies")
        .map(|m| (m.data["dt"].as_f64().unwrap() * 1e9).round() as u64)
        .unwrap();
    let mut contacts: BTreeMap<u64, BTreeSet<(Id, Id)>> = BTreeMap::new();
    let mut lines: BTreeMap<u64, Vec<(String, Vec<Id>)>> = BTreeMap::new();
    for m in &log {
        match m.topic.as_str() {
            "/contacts" => {
                let f = m.data["frame"].as_u64().unwrap_or(0);
                let set = contacts.entry(f).or_default();
                for c in m.data["contacts"].as_array().into_iter().flatten() {
                    set.insert((id_of(c, "a", "a_generation"), id_of(c, "b", "b_generation")));
                }
            }
            "/events" => {
                let name = m.data["name"].as_str().unwrap().to_owned();
                let text = m.data["message"].as_str().unwrap();
                lines
                    .entry(m.log_time / dt_ns)
                    .or_default()
                    .push((name, ids_in(text)));
            }
            _ => {}
        }
    }
    let game = ["input", "spawn", "destroy", "expire", "missed", "crush"];
    let mut touching: BTreeSet<(Id, Id)> = BTreeSet::new();
    let (mut begins, mut ends) = (0, 0);
    for (f, full) in frames.iter().enumerate() {
        let f = f as u64;
        let alive: BTreeMap<Id, &Value> = full["bodies"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| (id_of(b, "id", "generation"), b))
            .collect();
        let mut now = contacts.get(&f).cloned().unwrap_or_default();
        for &(a, b) in &touching {
            if let (Some(ba), Some(bb)) = (alive.get(&a), alive.get(&b)) {
                let ((sa, pa), (sb, pb)) = (placed(ba), placed(bb));
                if ricochet_geom::contact(&sa, &pa, &sb, &pb).depth >= -SLOP {
                    now.insert((a, b));
                }
            }
        }
        // Pairs begun in a frame whose body is removed in it end in it too.
        let ended_now: BTreeSet<(Id, Id)> = now
            .iter()
            .filter(|(a, b)| !alive.contains_key(a) || !alive.contains_key(b))
            .copied()
            .collect();
        let want_begin: BTreeSet<(Id, Id)> = now.difference(&touching).copied().collect();
        let still: BTreeSet<(Id, Id)> = now.difference(&ended_now).copied().collect();
        let want_end: BTreeSet<(Id, Id)> = touching
            .difference(&still)
            .copied()
            .chain(ended_now.iter().copied().filter(|p| !touching.contains(p)))
            .collect();
        let mut got_begin = BTreeSet::new();
        let mut got_end = BTreeSet::new();
        for (name, ids) in lines.get(&f).into_iter().flatten() {
            match name.as_str() {
                "touch_begin" | "touch_end" => {
                    let (a, b) = (ids[0].min(ids[1]), ids[0].max(ids[1]));
                    let set = if name == "touch_begin" {
                        &mut got_begin
                    } else {
                        &mut got_end
                    };
                    assert!(
                        set.insert((a, b)),
                        "frame {f}: {name} twice for {a:?} {b:?}"
                    );
                }
                other => assert!(
                    game.contains(&other),
                    "frame {f}: a line that is neither a touch nor a game event: {other}"
                ),
            }
        }
        assert_eq!(got_begin, want_begin, "frame {f}: touch begins");
        assert_eq!(got_end, want_end, "frame {f}: touch ends");
        begins += got_begin.len();
        ends += got_end.len();
        touching = still;
    }
    // The scene has touches, and every body that lands rests silently afterwards: far fewer
    // lines than frames with contacts.
    let frames_with_contacts = contacts.values().filter(|c| !c.is_empty()).count();
    assert!(begins > 5 && ends > 5, "{begins} begins, {ends} ends");
    assert!(
        begins + ends < frames_with_contacts,
        "{begins} begins and {ends} ends in {frames_with_contacts} frames with contacts"
    );
}
