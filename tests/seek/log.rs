//! What a seek shows, as Foxglove holds a log once open (`Log`, `Panel`), and the checks of
//! a time's drawing against `/bodies`, `/contacts` and the scenario (`Log::check`). See
//! `seek.rs`.

use std::collections::{BTreeMap, BTreeSet};
use std::f64::consts::TAU;
use std::path::Path;

use ricochet_geom::Vec2;
use ricochet_scenes::Rng;
use ricochet_sim::Scenario;
use serde_json::Value;

use super::drawing::*;
use crate::util::{full_bodies, record_with, root};

/// Allowed error, relative to max(1, |value|): a few f32 roundings.
pub(super) const TOL: f64 = 4.0 * f32::EPSILON as f64;

/// At most this many bodies at frame 0: an entity per body (`scene::PER_BODY_LIMIT`).
pub(super) const PER_BODY_LIMIT: usize = 1000;

/// At most this many body parts in one batched entity (`scene::CHUNK_PARTS`).
pub(super) const CHUNK_PARTS: usize = 1024;

/// The thickness of drawn shapes along z, at f32 precision.
pub(super) const DEPTH: f64 = 0.05f32 as f64;

/// The two topics of bodies, as indexed in [`Log::scenes`].
pub(super) const TOPICS: [&str; 2] = ["/scene", "/scene/static"];

pub(super) fn close(shown: f64, want: f64) -> bool {
    (shown - want).abs() <= TOL * shown.abs().max(want.abs()).max(1.0)
}

pub(super) fn close2(shown: Vec2, want: Vec2) -> bool {
    close(shown.x, want.x) && close(shown.y, want.y)
}

/// Angles are compared modulo a turn.
pub(super) fn close_angle(shown: f64, want: f64) -> bool {
    wrap(shown - want).abs() <= TOL * want.abs().max(1.0)
}

/// `a` in [-π, π].
pub(super) fn wrap(a: f64) -> f64 {
    a - TAU * (a / TAU).round()
}

pub(super) fn num(v: &Value, key: &str) -> f64 {
    let n = v[key].as_f64();
    n.unwrap_or_else(|| panic!("a number {key} in {v}"))
}

pub(super) fn pair(v: &Value) -> Vec2 {
    Vec2::new(v[0].as_f64().unwrap(), v[1].as_f64().unwrap())
}

/// A pose in the plane: what a primitive's `pose` or a `/tf` transform says.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Planar {
    pub(super) at: Vec2,
    pub(super) yaw: f64,
}

impl Planar {
    /// From a translation and a rotation about z; an error unless both are in the plane (z
    /// = 0, a unit quaternion about z).
    pub(super) fn from_json(position: &Value, q: &Value) -> Result<Planar, String> {
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

    pub(super) fn of(prim: &Value) -> Result<Planar, String> {
        let pose = &prim["pose"];
        Planar::from_json(&pose["position"], &pose["orientation"])
    }
}

/// By frame, the frame whose drawing a seek to it shows, from the drawing's pace as
/// README.md states it ("Drawing a big scene"): a scene drawn per body draws every frame;
/// else frame 0 draws; a drawing of `n` encoded
/// bytes (the scene topics' messages of its frame, as the file holds them) lets the next
/// frame draw `ceil(n / 12 KiB)` frames later; a frame allowed to draw that sends nothing
/// changed nothing drawn, so it shows its own bodies as the last drawing does. With
/// `--draw-every-frame`, every frame shows itself.
pub(super) fn shown_frames(log: &Path, dt_ns: u64, frames: usize, every_frame: bool) -> Vec<usize> {
    const BUDGET: u64 = 12 * 1024;
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
pub(super) struct Log {
    pub(super) name: String,
    pub(super) scenario: Scenario,
    pub(super) dt_ns: u64,
    /// `log_time` of the last message.
    pub(super) end: u64,
    /// `/scene` and `/scene/static` messages, by `log_time`.
    pub(super) scenes: [Vec<(u64, Value)>; 2],
    /// `/tf` messages, by `log_time`.
    pub(super) tf: Vec<(u64, Value)>,
    /// `/scene/contacts` messages, by `log_time`.
    pub(super) arrows: Vec<(u64, Value)>,
    /// `/contacts`, by frame.
    pub(super) contacts: Vec<Value>,
    /// `/bodies` rebuilt in full, by frame.
    pub(super) bodies: Vec<Value>,
    /// More than [`PER_BODY_LIMIT`] bodies at frame 0: batched entities.
    pub(super) batched: bool,
    /// By frame, the frame whose drawing the panel shows then (see [`shown_frames`]).
    pub(super) shown: Vec<usize>,
    /// Where the camera looks with no focus body and no bounds: the centre of the bodies'
    /// extent at frame 0.
    pub(super) extent_centre: Vec2,
}

/// What the panel shows at a time.
#[derive(Debug, PartialEq)]
pub(super) struct Panel {
    /// The entities of `/scene` and of `/scene/static`, by id.
    pub(super) scenes: [BTreeMap<String, Value>; 2],
    /// The `view` transform, if one was sent by then.
    pub(super) view: Option<Value>,
    /// The entities of `/scene/contacts`, by id.
    pub(super) arrows: BTreeMap<String, Value>,
}

impl Log {
    /// Records a shipped scenario.
    pub(super) fn shipped(scenario: &str) -> Log {
        Log::record(&root().join(format!("scenarios/{scenario}.toml")))
    }

    /// Records the scenario at `path` with `ricochet run`, and reads the log.
    pub(super) fn record(path: &Path) -> Log {
        Log::record_with(path, &[])
    }

    /// Records the scenario at `path` with `ricochet run` and `args`, and reads the log.
    pub(super) fn record_with(path: &Path, args: &[&str]) -> Log {
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
    pub(super) fn times(&self, rng: &mut Rng) -> Vec<u64> {
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
    pub(super) fn panel(&self, t: u64, played: bool) -> Panel {
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
    pub(super) fn check(&self, t: u64) -> Vec<String> {
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
    pub(super) fn check_batches(
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
    pub(super) fn check_view(
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
