//! Foxglove's seek, emulated: what the 3D panel shows at any time of a log must be the
//! bodies of `/bodies` at that frame, each where its shape is at its exact pose.
//!
//! When Foxglove (Lichtblick 1.10.8, the open-source Foxglove Studio) seeks to a time `t` it
//! does not replay the log: it takes, per TOPIC, the last message with `log_time <= t` (not
//! per entity: an entity sent once and never again would be gone after a seek); and for
//! `/tf` it reads the transform messages logged up to `t`, never past it
//! (`Renderer.handleAllFramesMessages` reads preloaded messages with `receiveTime <=
//! currentTime`). Ricochet sends each of `/scene` (the moving bodies) and `/scene/static`
//! (the static ones) whole, a delete-all then every entity of its topic, so that one
//! message is all of the topic's bodies. So the panel shows, at `t`:
//! - the entities of the last `/scene` and of the last `/scene/static` at or before `t`, each
//!   message's deletions applied, then its entities (each topic has entities of its own: a
//!   deletion on one never touches the other's, and the same id on both is two entities);
//! - every entity in `world` (not `frame_locked`), its primitives placed in world
//!   coordinates: no body frames, no interpolation. Between frames `f` and `f + 1` the scene
//!   is frame `f`'s;
//! - the camera's frame `view` from the last `/tf` at or before `t` (each stamped at its own
//!   log time, so none is ahead to interpolate towards);
//! - the contact normals of the last `/scene/contacts` at or before `t`.
//!
//! At every frame's time, and at 50 times drawn by a fixed-seed RNG (every third snapped to a
//! frame), plus the first and the last, in every shipped scenario and in a generated scene of
//! over 1000 bodies, [`Log::check`] compares that with `/bodies` (rebuilt in full), `/contacts`
//! and the scenario at frame `f = floor(t / dt_ns)`:
//! - per-body style (at most [`PER_BODY_LIMIT`] bodies at frame 0): the entities shown are
//!   exactly the live bodies, each `body/ID:GENERATION` on `/scene/static` if it is static,
//!   else on `/scene`, with metadata `name`, `id`, `layer`, `kind` and, for a moving body,
//!   `velocity` and `angular_velocity` (to the bit) as `/bodies` has them;
//! - batched style (more bodies at frame 0, whatever the count later): each topic's entities
//!   are `LAYER/0`, `LAYER/1`, ... for each layer with bodies on that topic, holding in order
//!   exactly the live bodies of that layer in id order, each entity as many as fit in
//!   [`CHUNK_PARTS`] body parts (never more, and the next body would not fit), its metadata
//!   `layer`, `bodies`, `first` and `last` saying which;
//! - in both, every primitive is where `ricochet_geom::place` puts the body's shape at its
//!   exact pose at `f`, within f32 rounding: a circle a cylinder at its centre, not turned;
//!   an AABB an upright cube at its (turned) centre; an OBB a cube turned by the body's angle
//!   plus its own; a capsule a cube over its segment (centre the midpoint, turned along it,
//!   as long as the segment and as wide as the disc) and a cylinder at each end; polygons
//!   fans in the entity's one triangle list (identity pose, points in the world). Every
//!   number drawn is an f32 (rounded to f32 precision);
//! - the view frame is upright at the active region's focus body (the lowest id of that
//!   name) while it is alive, else at the centre of the world's bounds, else at the centre of
//!   the bodies' extent at frame 0;
//! - the contact normals are frame `f`'s contacts: 2 points each, from the point along the
//!   normal by max(depth, 0.8), in one line list (none when the frame has none).
//!
//! Seeking depends on nothing but `t`: the times are checked in the drawn (random) order, and
//! another test seeks back and forth and compares with fresh seeks and with playing from 0.

use std::collections::{BTreeMap, BTreeSet};
use std::f64::consts::TAU;
use std::path::Path;

use ricochet_geom::{PlacedPrimitive, Pose, Vec2, place};
use ricochet_scenes::Rng;
use ricochet_sim::Scenario;
use serde_json::Value;

use crate::util::{full_bodies, record_with, root, shape_def};

/// Allowed error, relative to max(1, |value|): a few f32 roundings.
const TOL: f64 = 4.0 * f32::EPSILON as f64;

/// At most this many bodies at frame 0: an entity per body (`scene::PER_BODY_LIMIT`).
const PER_BODY_LIMIT: usize = 1000;

/// At most this many body parts in one batched entity (`scene::CHUNK_PARTS`).
const CHUNK_PARTS: usize = 1024;

/// The thickness of drawn shapes along z, at f32 precision.
const DEPTH: f64 = 0.05f32 as f64;

/// The two topics of bodies, as indexed in [`Log::scenes`].
const TOPICS: [&str; 2] = ["/scene", "/scene/static"];

fn close(shown: f64, want: f64) -> bool {
    (shown - want).abs() <= TOL * shown.abs().max(want.abs()).max(1.0)
}

fn close2(shown: Vec2, want: Vec2) -> bool {
    close(shown.x, want.x) && close(shown.y, want.y)
}

/// Angles are compared modulo a turn.
fn close_angle(shown: f64, want: f64) -> bool {
    wrap(shown - want).abs() <= TOL * want.abs().max(1.0)
}

/// `a` in [-π, π].
fn wrap(a: f64) -> f64 {
    a - TAU * (a / TAU).round()
}

fn num(v: &Value, key: &str) -> f64 {
    let n = v[key].as_f64();
    n.unwrap_or_else(|| panic!("a number {key} in {v}"))
}

fn pair(v: &Value) -> Vec2 {
    Vec2::new(v[0].as_f64().unwrap(), v[1].as_f64().unwrap())
}

/// A pose in the plane: what a primitive's `pose` or a `/tf` transform says.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Planar {
    at: Vec2,
    yaw: f64,
}

impl Planar {
    /// From a translation and a rotation about z; an error unless both are in the plane (z
    /// = 0, a unit quaternion about z).
    fn from_json(position: &Value, q: &Value) -> Result<Planar, String> {
        let (qz, qw) = (num(q, "z"), num(q, "w"));
        let flat = num(q, "x") == 0.0 && num(q, "y") == 0.0 && num(position, "z") == 0.0;
        if !flat || !close(qz * qz + qw * qw, 1.0) {
            return Err(format!("a pose out of the plane: {position} {q}"));
        }
        let at = Vec2::new(num(position, "x"), num(position, "y"));
        Ok(Planar {
            at,
            yaw: 2.0 * libm::atan2(qz, qw),
        })
    }

    fn of(prim: &Value) -> Result<Planar, String> {
        let pose = &prim["pose"];
        Planar::from_json(&pose["position"], &pose["orientation"])
    }
}

/// By frame, the frame whose drawing a seek to it shows, from the drawing's pace as
/// README.md states it ("Drawing a big scene"): a scene drawn per body draws every frame;
/// else frame 0 draws; a drawing of `n` encoded
/// bytes (the scene topics' messages of its frame, as the file holds them) lets the next
/// frame draw `ceil(n / 16 KiB)` frames later; a frame allowed to draw that sends nothing
/// changed nothing drawn, so it shows its own bodies as the last drawing does. With
/// `--draw-every-frame`, every frame shows itself.
fn shown_frames(log: &Path, dt_ns: u64, frames: usize, every_frame: bool) -> Vec<usize> {
    const BUDGET: u64 = 16 * 1024;
    let file = ricochet_log::LogFile::open(log).unwrap();
    let mut bytes = vec![0_u64; frames];
    let mut messages = file.messages().unwrap();
    while let Some(m) = messages.next_raw() {
        let m = m.unwrap();
        if TOPICS.contains(&m.topic()) || ["/tf", "/scene/contacts"].contains(&m.topic()) {
            bytes[(m.log_time() / dt_ns) as usize] += m.bytes().len() as u64;
        }
    }
    let (mut next, mut last) = (0, 0);
    (0..frames)
        .map(|f| {
            if every_frame || f >= next {
                assert!(every_frame || f > 0 || bytes[0] > 0, "frame 0 draws");
                last = f;
                if bytes[f] > 0 {
                    next = f + bytes[f].div_ceil(BUDGET).max(1) as usize;
                }
            } else {
                assert_eq!(bytes[f], 0, "frame {f} draws before its pace allows");
            }
            last
        })
        .collect()
}

/// A recorded log, indexed as Foxglove holds it once open, with what it must show.
struct Log {
    name: String,
    scenario: Scenario,
    dt_ns: u64,
    /// `log_time` of the last message.
    end: u64,
    /// `/scene` and `/scene/static` messages, by `log_time`.
    scenes: [Vec<(u64, Value)>; 2],
    /// `/tf` messages, by `log_time`.
    tf: Vec<(u64, Value)>,
    /// `/scene/contacts` messages, by `log_time`.
    arrows: Vec<(u64, Value)>,
    /// `/contacts`, by frame.
    contacts: Vec<Value>,
    /// `/bodies` rebuilt in full, by frame.
    bodies: Vec<Value>,
    /// More than [`PER_BODY_LIMIT`] bodies at frame 0: batched entities.
    batched: bool,
    /// By frame, the frame whose drawing the panel shows then (see [`shown_frames`]).
    shown: Vec<usize>,
    /// Where the camera looks with no focus body and no bounds: the centre of the bodies'
    /// extent at frame 0.
    extent_centre: Vec2,
}

/// What the panel shows at a time.
#[derive(Debug, PartialEq)]
struct Panel {
    /// The entities of `/scene` and of `/scene/static`, by id.
    scenes: [BTreeMap<String, Value>; 2],
    /// The `view` transform, if one was sent by then.
    view: Option<Value>,
    /// The entities of `/scene/contacts`, by id.
    arrows: BTreeMap<String, Value>,
}

impl Log {
    /// Records a shipped scenario.
    fn shipped(scenario: &str) -> Log {
        Log::record(&root().join(format!("scenarios/{scenario}.toml")))
    }

    /// Records the scenario at `path` with `ricochet run`, and reads the log.
    fn record(path: &Path) -> Log {
        Log::record_with(path, &[])
    }

    /// Records the scenario at `path` with `ricochet run` and `args`, and reads the log.
    fn record_with(path: &Path, args: &[&str]) -> Log {
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        let text = std::fs::read_to_string(path).unwrap();
        let scenario = ricochet_sim::load_scenario(&text, &name).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join(format!("{name}.mcap"));
        record_with(path, &out, args);
        let log = ricochet_log::read_log_file(&out).unwrap();
        let bodies = full_bodies(&log);
        // Frame 1's `/bodies` (checked below: one a frame, from 0) is at `dt_ns`.
        let frame_1 = log.iter().filter(|m| m.topic == "/bodies").nth(1);
        let dt_ns = frame_1.unwrap().log_time;
        let (mut scenes, mut tf, mut arrows) = ([Vec::new(), Vec::new()], Vec::new(), Vec::new());
        let mut contacts = Vec::new();
        for m in &log {
            let at = (m.log_time, m.data.clone());
            match m.topic.as_str() {
                "/scene" => scenes[0].push(at),
                "/scene/static" => scenes[1].push(at),
                "/tf" => tf.push(at),
                "/scene/contacts" => arrows.push(at),
                "/contacts" => contacts.push(m.data.clone()),
                "/bodies" => assert_eq!(m.log_time, m.data["frame"].as_u64().unwrap() * dt_ns),
                _ => {}
            }
        }
        let sorted = |s: &Vec<(u64, Value)>| s.is_sorted_by_key(|s| s.0);
        assert!(
            scenes.iter().chain([&tf, &arrows]).all(sorted),
            "in time order"
        );
        let numbered = bodies.iter().enumerate().all(|(f, b)| b["frame"] == f);
        assert!(numbered, "/bodies: frames 0, 1, 2...");
        assert_eq!(contacts.len(), bodies.len(), "/contacts: one a frame");
        let first = bodies[0]["bodies"].as_array().unwrap();
        let batched = first.len() > PER_BODY_LIMIT;
        let positions: Vec<Vec2> = first.iter().map(|b| pair(&b["position"])).collect();
        let extent_centre = positions.first().map_or(Vec2::ZERO, |&p0| {
            let (mut lo, mut hi) = (p0, p0);
            for p in &positions {
                lo = Vec2::new(lo.x.min(p.x), lo.y.min(p.y));
                hi = Vec2::new(hi.x.max(p.x), hi.y.max(p.y));
            }
            (lo + hi) * 0.5
        });
        let end = log.last().unwrap().log_time;
        let every_frame = args.contains(&"--draw-every-frame") || !batched;
        let shown = shown_frames(&out, dt_ns, bodies.len(), every_frame);
        Log {
            shown,
            name,
            scenario,
            dt_ns,
            end,
            scenes,
            tf,
            arrows,
            contacts,
            bodies,
            batched,
            extent_centre,
        }
    }

    /// 50 times uniform in [0, end], every third snapped to a frame, then 0 and `end`.
    fn times(&self, rng: &mut Rng) -> Vec<u64> {
        let mut times: Vec<u64> = (0..50)
            .map(|i| {
                let t = (rng.range(0.0, self.end as f64 + 1.0) as u64).min(self.end);
                let snap = if i % 3 == 0 { self.dt_ns } else { 1 };
                t / snap * snap
            })
            .collect();
        times.extend([0, self.end]);
        assert!(
            times.iter().any(|t| t % self.dt_ns > 0),
            "times between frames"
        );
        times
    }

    /// What the panel shows at `t`: after the last message of each topic at or before `t`,
    /// as a seek shows it, or, `played`, after every message from the start, as playing
    /// from 0 shows it.
    fn panel(&self, t: u64, played: bool) -> Panel {
        let entities = |messages: &[(u64, Value)]| {
            let upto = messages.partition_point(|s| s.0 <= t);
            let from = if played { 0 } else { upto.saturating_sub(1) };
            let mut entities = BTreeMap::new();
            for (_, update) in &messages[from..upto] {
                apply(&mut entities, update);
            }
            entities
        };
        // The last transform of `view` read by `t`: every one is stamped at its log time
        // (checked), so none is ahead of `t`.
        let upto = self.tf.partition_point(|s| s.0 <= t);
        let view = self.tf[..upto].last().map(|(log_time, m)| {
            let transforms = m["transforms"].as_array().unwrap();
            assert_eq!(transforms.len(), 1, "/tf at {log_time}: one frame, {m}");
            let tf = &transforms[0];
            assert_eq!(ns(&tf["timestamp"]), *log_time, "stamped at its time: {tf}");
            tf.clone()
        });
        Panel {
            scenes: [entities(&self.scenes[0]), entities(&self.scenes[1])],
            view,
            arrows: entities(&self.arrows),
        }
    }

    /// Seeks to `t` and compares what is shown with `/bodies`, `/contacts` and the scenario:
    /// one line per difference.
    fn check(&self, t: u64) -> Vec<String> {
        let frame = self.shown[(t / self.dt_ns) as usize];
        let frac = (t % self.dt_ns) as f64 / self.dt_ns as f64;
        let at = format!(
            "{} at t = {t} ns (frame {} + {frac:.3}, drawn at {frame})",
            self.name,
            t / self.dt_ns
        );
        let panel = self.panel(t, false);
        let mut problems = Vec::new();
        let mut report = |p: String| problems.push(format!("{at}: {p}"));
        let bodies = alive(&self.bodies[frame]);
        for (k, topic) in TOPICS.iter().enumerate() {
            let ours: Vec<&Value> = bodies
                .values()
                .filter(|b| b["static"].as_bool() == Some(k == 1))
                .collect();
            let shown = &panel.scenes[k];
            let mut report = |p: String| report(format!("{topic}: {p}"));
            for (id, e) in shown {
                check_entity(id, e, &mut report);
            }
            if self.batched {
                self.check_batches(shown, &ours, &mut report);
            } else {
                check_per_body(shown, &ours, k == 1, &mut report);
            }
        }
        self.check_view(panel.view.as_ref(), &bodies, &mut report);
        check_arrows(&panel.arrows, &self.contacts[frame], &mut report);
        problems
    }

    /// Batched: each layer's bodies (`ours`, in id order), in entities `LAYER/K`.
    fn check_batches(
        &self,
        shown: &BTreeMap<String, Value>,
        ours: &[&Value],
        report: &mut impl FnMut(String),
    ) {
        let mut seen = BTreeSet::new();
        for layer in self.scenario.world.layers.names() {
            let bodies: Vec<&Value> = ours
                .iter()
                .copied()
                .filter(|b| b["layer"] == layer.as_str())
                .collect();
            let mut next = 0;
            for k in 0.. {
                let id = format!("{layer}/{k}");
                let Some(e) = shown.get(&id) else { break };
                seen.insert(id.clone());
                let meta = metadata(e);
                let n = meta
                    .get(1)
                    .filter(|(key, _)| key == "bodies")
                    .and_then(|(_, v)| v.parse::<usize>().ok())
                    .unwrap_or(0);
                let held = &bodies[next.min(bodies.len())..(next + n).min(bodies.len())];
                if n == 0 || held.len() < n {
                    report(format!(
                        "{id} holds {meta:?}: bodies {next}.. of the {} of layer {layer}",
                        bodies.len()
                    ));
                    return;
                }
                let want = [
                    ("layer", layer.clone()),
                    ("bodies", n.to_string()),
                    ("first", body_id(held[0])),
                    ("last", body_id(held[n - 1])),
                ]
                .map(|(k, v)| (k.to_owned(), v));
                if meta != want {
                    report(format!("{id}: metadata {meta:?}, the bodies {want:?}"));
                }
                let parts: usize = held.iter().map(|b| parts(b)).sum();
                if parts > CHUNK_PARTS {
                    report(format!("{id}: {parts} body parts, over {CHUNK_PARTS}"));
                }
                if let Some(b) = bodies.get(next + n)
                    && parts + self::parts(b) <= CHUNK_PARTS
                {
                    report(format!(
                        "{id}: {parts} parts, and the next body {} would fit",
                        body_id(b)
                    ));
                }
                compare_drawing(e, held, &mut |p| report(format!("{id}: {p}")));
                next += n;
            }
            if next != bodies.len() {
                let missing: Vec<String> = bodies[next..].iter().map(|b| body_id(b)).collect();
                report(format!("layer {layer}: bodies not shown {missing:?}"));
            }
        }
        let extra: Vec<&String> = shown.keys().filter(|id| !seen.contains(*id)).collect();
        if !extra.is_empty() {
            report(format!("entities not a layer's batch in order: {extra:?}"));
        }
    }

    /// The camera's frame: upright, at the focus body, else the bounds' centre, else the
    /// bodies' extent's centre at frame 0.
    fn check_view(
        &self,
        view: Option<&Value>,
        bodies: &BTreeMap<(u64, u64), Value>,
        report: &mut impl FnMut(String),
    ) {
        let world = &self.scenario.world;
        let focus = world.active_region.as_ref().and_then(|a| {
            let mut named = bodies.values().filter(|b| b["name"] == a.focus.as_str());
            named.next().map(|b| pair(&b["position"]))
        });
        let bounds = world.bounds.map(|b| (b.min + b.max) * 0.5);
        let want = focus.or(bounds).unwrap_or(self.extent_centre);
        let Some(tf) = view else {
            report("no /tf view frame".to_owned());
            return;
        };
        let shown = Planar::from_json(&tf["translation"], &tf["rotation"]);
        let named = tf["parent_frame_id"] == "world" && tf["child_frame_id"] == "view";
        match shown {
            Ok(p) if named && close2(p.at, want) && p.yaw == 0.0 => {}
            _ => report(format!("/tf: {tf}, the camera looks at {want}, upright")),
        }
        check_f32(tf, "/tf", report);
    }
}

/// Per-body: each of `ours` an entity of its own, named and described as its body.
fn check_per_body(
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
fn check_entity(id: &str, e: &Value, report: &mut impl FnMut(String)) {
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
fn check_f32(v: &Value, what: &str, report: &mut impl FnMut(String)) {
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
fn check_arrows(
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
fn same(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits()
}

/// `[x, y]` as `ricochet_geom::Numbers` writes it.
fn parse_pair(s: &str) -> Option<Vec2> {
    let (x, y) = s.strip_prefix('[')?.strip_suffix(']')?.split_once(", ")?;
    Some(Vec2::new(x.parse().ok()?, y.parse().ok()?))
}

/// An entity's metadata, as (key, value) pairs in order.
fn metadata(e: &Value) -> Vec<(String, String)> {
    let meta = e["metadata"].as_array().unwrap().iter();
    let s = |v: &Value| v.as_str().unwrap().to_owned();
    meta.map(|kv| (s(&kv["key"]), s(&kv["value"]))).collect()
}

/// A body's `ID:GENERATION`.
fn body_id(b: &Value) -> String {
    format!("{}:{}", b["id"], b["generation"].as_u64().unwrap_or(0))
}

/// How many parts (primitives) a body's shape has.
fn parts(b: &Value) -> usize {
    let shape = shape_def(&b["shape"]).to_shape().unwrap();
    shape.primitives().len()
}

/// Nanoseconds since the epoch of a decoded `google.protobuf.Timestamp` (RFC 3339, UTC, as in
/// "1970-01-01T00:00:00.016666667Z"; Ricochet's logs start at the epoch).
fn ns(ts: &Value) -> u64 {
    let s = ts.as_str().unwrap_or_else(|| panic!("a timestamp: {ts}"));
    let (date, time) = s.strip_suffix('Z').and_then(|s| s.split_once('T')).unwrap();
    let day: u64 = date.strip_prefix("1970-01-").unwrap().parse().unwrap();
    let (hms, frac) = time.split_once('.').unwrap_or((time, ""));
    let secs = (hms.split(':')).fold(0, |acc, part| acc * 60 + part.parse::<u64>().unwrap());
    let nanos: u64 = format!("{frac:0<9}").parse().unwrap();
    ((day - 1) * 86_400 + secs) * 1_000_000_000 + nanos
}

/// Foxglove applying a `SceneUpdate`: its deletions, then its entities (added or replaced).
fn apply(entities: &mut BTreeMap<String, Value>, update: &Value) {
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
fn alive(full: &Value) -> BTreeMap<(u64, u64), Value> {
    let bodies = full["bodies"].as_array().unwrap().iter();
    let generation = |b: &Value| b["generation"].as_u64().unwrap_or(0);
    bodies
        .map(|b| ((b["id"].as_u64().unwrap(), generation(b)), b.clone()))
        .collect()
}

/// One drawn cube or cylinder: where, how turned (`None`: any way), how large, and whose.
struct Solid {
    at: Vec2,
    yaw: Option<f64>,
    size: Vec2,
    what: String,
}

/// Compares entity `e`'s primitives with the shapes of `bodies` (in order) placed at their
/// poses: the cubes, the cylinders and the one triangle list, each in the bodies' order.
fn compare_drawing(e: &Value, bodies: &[&Value], report: &mut impl FnMut(String)) {
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

/// Every frame's time and the drawn times, checked in that (partly random) order.
fn check_every_time(log: &Log, seed: u64) {
    let mut times = log.times(&mut Rng::new(seed));
    times.extend((0..log.bodies.len() as u64).map(|f| f * log.dt_ns));
    let problems: Vec<String> = times.iter().flat_map(|&t| log.check(t)).collect();
    let n = problems.len();
    let first = problems[..n.min(12)].join("\n");
    assert!(n == 0, "{}: {n} differences, the first:\n{first}", log.name);
}

#[test]
fn a_seek_shows_the_bodies_of_that_frame() {
    for (seed, scenario) in [
        (0x5eec, "asteroids"),
        (0xf0c5, "platformer"),
        (0x1e7e, "level"),
        (0xa4cd, "arcade"),
        (0x54a9, "shapes"),
        (0x7a1d, "validation"),
    ] {
        let log = Log::shipped(scenario);
        assert!(!log.batched, "{scenario}: a body per entity");
        check_every_time(&log, seed);
    }
}

/// A scene of 1212 bodies on three layers: moving circles, boxes, capsules, polygons and
/// compounds (one of 300 parts), spinning; static walls; some with lifetimes, so the count
/// falls under 1000 (the style stays batched) and `rock`'s batches shift; spawns reusing
/// freed ids.
fn crowd() -> String {
    let mut text = String::from(
        "name = \"crowd\"\nhz = 60\nframes = 90\nlayers = [\"rock\", \"dust\", \"wall\"]\n\
         [world]\ngravity = [0, 0]\n\
         [templates.pebble]\nlayer = \"rock\"\nshape = { kind = \"capsule\", a = [-0.2, 0], b = [0.2, 0], radius = 0.1 }\nangular_velocity = 1.5\n",
    );
    let shapes = [
        "{ kind = \"circle\", radius = 0.4 }",
        "{ kind = \"aabb\", half_extents = [0.3, 0.2], center = [0.1, 0] }",
        "{ kind = \"obb\", half_extents = [0.4, 0.1], angle = 0.3 }",
        "{ kind = \"capsule\", a = [-0.3, 0], b = [0.3, 0.1], radius = 0.15 }",
        "{ kind = \"polygon\", vertices = [[0, 0], [0.5, 0], [0.6, 0.4], [0.1, 0.5]] }",
        "{ kind = \"compound\", parts = [{ kind = \"circle\", radius = 0.2, center = [0.3, 0] }, \
         { kind = \"polygon\", vertices = [[0, 0], [0.3, 0], [0, 0.3]] }, \
         { kind = \"aabb\", half_extents = [0.1, 0.1], center = [-0.3, 0] }] }",
    ];
    let mut body = |name: String, layer: &str, shape: &str, at: (f64, f64), extra: &str| {
        text.push_str(&format!(
            "[[bodies]]\nname = \"{name}\"\nlayer = \"{layer}\"\nshape = {shape}\nposition = [{}, {}]\n{extra}",
            at.0, at.1
        ));
    };
    for i in 0..800 {
        let at = ((i % 40) as f64 * 2.0, (i / 40) as f64 * 2.0);
        let spin = (i % 7) as f64 * 0.4 - 1.2;
        let life = if i % 5 == 0 {
            format!("lifetime = {}\n", 10 + i % 70)
        } else {
            String::new()
        };
        let extra = format!(
            "velocity = [0.5, {}]\nangular_velocity = {spin}\n{life}",
            (i % 3) as f64 * 0.1
        );
        body(
            format!("rock{i}"),
            "rock",
            shapes[i % shapes.len()],
            at,
            &extra,
        );
    }
    let parts: Vec<String> = (0..300)
        .map(|k| {
            format!(
                "{{ kind = \"circle\", radius = 0.1, center = [{}, 0] }}",
                k as f64 * 0.05
            )
        })
        .collect();
    let chain = format!("{{ kind = \"compound\", parts = [{}] }}", parts.join(", "));
    body(
        "chain".into(),
        "rock",
        &chain,
        (-20.0, 0.0),
        "angular_velocity = 0.2\n",
    );
    for i in 0..395 {
        let at = ((i % 20) as f64 * 2.0 + 1.0, -((i / 20) as f64) * 2.0 - 5.0);
        let extra = if i % 11 == 0 {
            "kind = \"kinematic\"\nvelocity = [-1, 0]\n".to_owned()
        } else {
            format!("velocity = [0, 0.3]\nlifetime = {}\n", 20 + i % 60)
        };
        body(
            format!("dust{i}"),
            "dust",
            shapes[(i * 5) % shapes.len()],
            at,
            &extra,
        );
    }
    for i in 0..16 {
        let at = (i as f64 * 6.0 - 40.0, 60.0);
        let extra = format!("kind = \"static\"\nangle = {}\n", i as f64 * 0.2);
        body(
            format!("wall{i}"),
            "wall",
            shapes[i % shapes.len()],
            at,
            &extra,
        );
    }
    for f in [30, 50, 70] {
        text.push_str(&format!(
            "[[script]]\nframe = {f}\naction = \"spawn\"\ntemplate = \"pebble\"\nname = \"pebble\"\nposition = [0, -3]\nvelocity = [1, 1]\n"
        ));
    }
    text
}

/// With `--draw-every-frame`, a big scene is drawn in every frame it changes: a seek to any
/// frame shows that frame's bodies.
#[test]
fn a_big_scene_drawn_every_frame_shows_every_frame() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("crowd.toml");
    std::fs::write(&path, crowd()).unwrap();
    let paced = Log::record(&path);
    let drawn_late = (0..paced.shown.len()).filter(|&f| paced.shown[f] != f);
    assert!(drawn_late.count() > 10, "the crowd's drawing is paced");
    let log = Log::record_with(&path, &["--draw-every-frame"]);
    assert!(log.shown.iter().enumerate().all(|(f, &s)| s == f));
    check_every_time(&log, 0xe7e4);
}

#[test]
fn a_seek_in_a_scene_of_over_1000_bodies_shows_its_batches() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("crowd.toml");
    std::fs::write(&path, crowd()).unwrap();
    let log = Log::record(&path);
    assert!(log.batched, "over {PER_BODY_LIMIT} bodies: batches");
    // What the scene exercises: several batches of a layer, a static topic, fewer bodies
    // than the limit later on, and an id reused.
    let last = alive(log.bodies.last().unwrap());
    assert!(
        last.len() < PER_BODY_LIMIT,
        "{} bodies at the end",
        last.len()
    );
    assert!(
        last.keys().any(|&(_, generation)| generation > 0),
        "an id reused"
    );
    let shown = log.panel(log.end, false);
    assert!(
        shown.scenes[0].contains_key("rock/1"),
        "{:?}",
        shown.scenes[0].keys()
    );
    assert!(
        shown.scenes[1].contains_key("wall/0"),
        "{:?}",
        shown.scenes[1].keys()
    );
    check_every_time(&log, 0xc40d);
}

/// A scene whose frames change nothing but a velocity: a body stopped dead (it does not
/// move that frame), and one set going again from rest later, by which time the first is
/// still; a static wall.
const STOPS: &str = r#"
name = "stops"
hz = 60
frames = 40
layers = ["puck", "wall"]
[world]
gravity = [0, 0]
[[bodies]]
name = "runner"
layer = "puck"
shape = { kind = "circle", radius = 0.5 }
velocity = [2, 0]
[[bodies]]
name = "sitter"
layer = "puck"
shape = { kind = "capsule", a = [-0.5, 0], b = [0.5, 0], radius = 0.2 }
position = [0, 3]
[[bodies]]
name = "wall"
layer = "wall"
kind = "static"
shape = { kind = "obb", half_extents = [1, 0.2], angle = 0.5 }
position = [0, -3]
[[script]]
frame = 10
action = "set_velocity"
body = "runner"
velocity = [0, 0]
[[script]]
frame = 20
action = "set_velocity"
body = "sitter"
velocity = [0, 0.5]
[[script]]
frame = 21
action = "set_velocity"
body = "sitter"
velocity = [0, 0]
"#;

#[test]
fn a_seek_shows_a_velocity_that_changed_alone() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("stops.toml");
    std::fs::write(&path, STOPS).unwrap();
    let log = Log::record(&path);
    // Frames 10 and 21 change velocities only: nothing moves or turns.
    let state = |f: usize| -> Vec<_> {
        let bodies = alive(&log.bodies[f]).into_values();
        let poses = bodies.map(|b| {
            (
                b["position"].clone(),
                b["angle"].clone(),
                b["velocity"].clone(),
            )
        });
        poses.collect()
    };
    for f in [10, 21] {
        let (before, now) = (state(f - 1), state(f));
        let same_poses = before
            .iter()
            .zip(&now)
            .all(|(a, b)| a.0 == b.0 && a.1 == b.1);
        let sped = before.iter().zip(&now).any(|(a, b)| a.2 != b.2);
        assert!(same_poses && sped, "frame {f}: {before:?} then {now:?}");
    }
    check_every_time(&log, 0x5709);
}

#[test]
fn seeking_back_and_forth_shows_what_a_fresh_seek_and_playing_show() {
    let (log, fresh) = (Log::shipped("asteroids"), Log::shipped("asteroids"));
    let times = log.times(&mut Rng::new(7));
    let want: BTreeMap<u64, _> = times.iter().map(|&t| (t, fresh.panel(t, false))).collect();
    // The drawn times jump back and forth; each pair is also seen the other way round.
    for pair in times.windows(2) {
        for t in [pair[0], pair[1], pair[0]] {
            assert!(
                log.panel(t, false) == want[&t],
                "seeking to {t} after {pair:?}"
            );
        }
    }
    for t in times {
        assert!(log.panel(t, true) == want[&t], "played to {t}");
    }
}
