//! Foxglove's seek, emulated: what the 3D panel shows at any time of a log must be the
//! bodies of `/bodies` at that frame.
//!
//! When Foxglove (Lichtblick 1.10.8, the open-source Foxglove Studio) seeks to a time `t` it
//! does not replay the log: it takes, per topic, the last message with `log_time <= t`; and
//! for `/tf` it has preloaded the transform messages from the start of the file up to `t`
//! (never past it: `Renderer.handleAllFramesMessages` reads preloaded messages with
//! `receiveTime <= currentTime`, and a seek backwards clears the tree and reads them again).
//! So the panel shows:
//! - the entities of the last `/scene` (`foxglove.SceneUpdate`: the moving bodies) and of
//!   the last `/scene/static` (the static ones) at or before `t`: each one's deletions
//!   applied, then its entities (Ricochet sends a delete-all then every body, so that one
//!   message is the whole of its bodies);
//! - each entity in its frame (`frame_locked`), placed by the frame's transforms read by then,
//!   kept by their own timestamp (a later one with the same timestamp replaces the earlier;
//!   timestamps may be ahead of `t`: predictions): the transform stamped `t` if there is
//!   one; between two, position lerped and rotation slerped; after the last, the last
//!   (`CoordinateFrame.findClosestTransforms` and `InterpolateTransform`).
//!
//! At every frame's time, and at 50 times drawn by a fixed-seed RNG (every third snapped to a
//! frame), plus the first and the last, in every shipped scenario,
//! [`Log::check`] compares that with `/bodies` (rebuilt in full) at frame `f = floor(t /
//! dt_ns)`:
//! - the entities shown are the bodies alive, each named as its body;
//! - at a frame's time, each entity's frame is at the body's position and angle within f32
//!   rounding (a body with an AABB part, which does not turn, has an upright frame: angle 0,
//!   its other parts drawn turned);
//! - between frames `f` and `f + 1` (`/tf` sends a body on a straight line only as a
//!   prediction ahead, which Foxglove interpolates towards), each entity is either still at
//!   the body's pose at `f`, or moved along its last step, `pose(f) + frac * (pose(f) -
//!   pose(f - 1))`, within f32 rounding;
//! - every primitive, taken to the world through its frame, is where the body's shape placed
//!   at the pose shown is (`ricochet_geom::place`): centres, sizes, turns, vertices.
//!
//! Seeking depends on nothing but `t`: the times are checked in the drawn (random) order, and
//! a second test seeks back and forth and compares with fresh seeks and with playing from 0.

use std::collections::BTreeMap;
use std::f64::consts::TAU;

use ricochet_geom::{PlacedPrimitive, Pose, Vec2, place};
use ricochet_scenes::Rng;
use serde_json::Value;

use crate::util::{full_bodies, record, root, shape_def};

/// Allowed error, relative to max(1, |value|): a few f32 roundings.
const TOL: f64 = 4.0 * f32::EPSILON as f64;

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

/// A pose in the plane: what a `/tf` transform, a primitive's `pose` or a body says.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Planar {
    at: Vec2,
    yaw: f64,
}

impl Planar {
    fn new(at: Vec2, yaw: f64) -> Planar {
        Planar { at, yaw }
    }

    /// From a translation and a rotation about z.
    fn from_json(position: &Value, q: &Value) -> Planar {
        let flat = num(q, "x") == 0.0 && num(q, "y") == 0.0 && num(position, "z") == 0.0;
        assert!(flat, "a pose in the plane: {position} {q}");
        let at = Vec2::new(num(position, "x"), num(position, "y"));
        Planar::new(at, 2.0 * libm::atan2(num(q, "z"), num(q, "w")))
    }

    fn of(pose: &Value) -> Planar {
        Planar::from_json(&pose["position"], &pose["orientation"])
    }

    fn of_body(body: &Value) -> Planar {
        let p = &body["position"];
        let at = Vec2::new(p[0].as_f64().unwrap(), p[1].as_f64().unwrap());
        Planar::new(at, num(body, "angle"))
    }

    fn apply(self, p: Vec2) -> Vec2 {
        let (s, c) = libm::sincos(self.yaw);
        self.at + Vec2::new(c * p.x - s * p.y, s * p.x + c * p.y)
    }

    /// This pose composed with `inner`, a pose in its frame.
    fn then(self, inner: Planar) -> Planar {
        Planar::new(self.apply(inner.at), self.yaw + inner.yaw)
    }
}

/// Foxglove's `Transform.Interpolate` between transforms at `a.0 < t < b.0`: position
/// lerped, rotation slerped the short way round (gl-matrix `quat.slerp`).
fn interpolate(a: (u64, Planar), b: (u64, Planar), t: u64) -> Planar {
    let f = (t - a.0) as f64 / (b.0 - a.0) as f64;
    let (qa, mut qb) = (libm::sincos(a.1.yaw / 2.0), libm::sincos(b.1.yaw / 2.0));
    let mut cos = qa.0 * qb.0 + qa.1 * qb.1;
    if cos < 0.0 {
        (cos, qb) = (-cos, (-qb.0, -qb.1));
    }
    let (s0, s1) = if 1.0 - cos > 1e-6 {
        let omega = libm::acos(cos);
        let s = libm::sin(omega);
        (libm::sin((1.0 - f) * omega) / s, libm::sin(f * omega) / s)
    } else {
        (1.0 - f, f)
    };
    let yaw = 2.0 * libm::atan2(s0 * qa.0 + s1 * qb.0, s0 * qa.1 + s1 * qb.1);
    Planar::new(a.1.at.lerp(b.1.at, f), yaw)
}

/// An entity as the panel shows it: its frame's pose and its primitives in the world.
#[derive(Debug, PartialEq)]
struct Shown {
    name: String,
    /// Foxglove's lookup at `t` (none: the frame has no transform yet).
    pose: Option<Planar>,
    /// Pose and size of each cylinder and of each cube.
    cylinders: Vec<(Planar, Vec2)>,
    cubes: Vec<(Planar, Vec2)>,
    /// The points of each triangle list.
    triangles: Vec<Vec<Vec2>>,
}

/// A recorded log, indexed as Foxglove holds it once open.
struct Log {
    scenario: &'static str,
    dt_ns: u64,
    /// `log_time` of the last message.
    end: u64,
    /// `/scene` and `/scene/static` messages, by `log_time`.
    scenes: [Vec<(u64, Value)>; 2],
    /// Every transform of `/tf` in file order, by child frame: `(log_time, timestamp, pose)`.
    transforms: BTreeMap<String, Vec<(u64, u64, Planar)>>,
    /// `/bodies` rebuilt in full, by frame.
    bodies: Vec<Value>,
}

impl Log {
    fn record(scenario: &'static str) -> Log {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(format!("{scenario}.mcap"));
        record(&root().join(format!("scenarios/{scenario}.toml")), &path);
        let log = ricochet_log::read_log_file(&path).unwrap();
        let bodies = full_bodies(&log);
        // Frame 1's `/bodies` (checked below: one a frame, from 0) is at `dt_ns`.
        let frame_1 = log.iter().filter(|m| m.topic == "/bodies").nth(1);
        let dt_ns = frame_1.unwrap().log_time;
        let mut scenes = [Vec::new(), Vec::new()];
        let mut transforms = BTreeMap::<_, Vec<_>>::new();
        for m in &log {
            match m.topic.as_str() {
                "/scene" => scenes[0].push((m.log_time, m.data.clone())),
                "/scene/static" => scenes[1].push((m.log_time, m.data.clone())),
                "/tf" => {
                    for tf in m.data["transforms"].as_array().unwrap() {
                        assert_eq!(tf["parent_frame_id"], "world", "{tf}");
                        let frame = tf["child_frame_id"].as_str().unwrap().to_owned();
                        let pose = Planar::from_json(&tf["translation"], &tf["rotation"]);
                        let stamp = ns(&tf["timestamp"]);
                        assert_eq!(stamp % dt_ns, 0, "stamped at a frame's time: {tf}");
                        let history = transforms.entry(frame).or_default();
                        history.push((m.log_time, stamp, pose));
                    }
                }
                "/bodies" => assert_eq!(m.log_time, m.data["frame"].as_u64().unwrap() * dt_ns),
                _ => {}
            }
        }
        assert!(
            scenes.iter().all(|s| s.is_sorted_by_key(|s| s.0)),
            "in time order"
        );
        let numbered = bodies.iter().enumerate().all(|(f, b)| b["frame"] == f);
        assert!(numbered, "/bodies: frames 0, 1, 2...");
        let end = log.last().unwrap().log_time;
        Log {
            scenario,
            dt_ns,
            end,
            scenes,
            transforms,
            bodies,
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

    /// The entities at `t`: after the last `/scene` and the last `/scene/static` at or before
    /// `t`, as a seek shows them, or, `played`, after every message of both from the start,
    /// as playing from 0 shows them. (Each topic has entities of its own: a deletion on one
    /// never touches the other's.)
    fn scene(&self, t: u64, played: bool) -> BTreeMap<String, Value> {
        let mut shown = BTreeMap::new();
        for scenes in &self.scenes {
            let upto = scenes.partition_point(|s| s.0 <= t);
            let from = if played { 0 } else { upto.saturating_sub(1) };
            let mut entities = BTreeMap::new();
            for (_, update) in &scenes[from..upto] {
                apply(&mut entities, update);
            }
            for (id, e) in entities {
                assert!(shown.insert(id, e).is_none(), "a body on both topics");
            }
        }
        shown
    }

    /// What the panel shows of `entities` at time `t`.
    fn show(&self, entities: &BTreeMap<String, Value>, t: u64) -> BTreeMap<String, Shown> {
        let show = |(id, e): (&String, &Value)| (id.clone(), self.show_entity(e, t));
        entities.iter().map(show).collect()
    }

    fn show_entity(&self, e: &Value, t: u64) -> Shown {
        assert_eq!(e["frame_locked"], true, "{}: follows its frame", e["id"]);
        // The frame's transforms read by `t`, by timestamp: a later one replaces an earlier.
        let mut history = BTreeMap::new();
        let all = self.transforms.get(e["frame_id"].as_str().unwrap());
        for &(log_time, stamp, pose) in all.into_iter().flatten() {
            if log_time <= t {
                history.insert(stamp, pose);
            }
        }
        let pair = |(&k, &p): (&u64, &Planar)| (k, p);
        let before = history.range(..=t).next_back().map(pair);
        let after = history.range(t..).next().map(pair);
        // What Foxglove shows: exact, interpolated, or clamped to the nearest.
        let pose = match (before, after) {
            (Some(a), Some(b)) if a.0 < b.0 => Some(interpolate(a, b, t)),
            (Some((_, p)), _) | (None, Some((_, p))) => Some(p),
            (None, None) => None,
        };
        let frame = pose.unwrap_or(Planar::new(Vec2::ZERO, 0.0));
        let world = |prim: &Value| frame.then(Planar::of(&prim["pose"]));
        let list = |key: &str| e[key].as_array().unwrap().iter();
        let size = |prim: &Value| Vec2::new(num(&prim["size"], "x"), num(&prim["size"], "y"));
        let point = |p: &Value| Vec2::new(num(p, "x"), num(p, "y"));
        let points = |tl: &Value| {
            let points = tl["points"].as_array().unwrap().iter();
            points.map(|p| world(tl).apply(point(p))).collect()
        };
        Shown {
            name: e["metadata"][0]["value"].as_str().unwrap_or("").to_owned(),
            pose,
            cylinders: list("cylinders").map(|c| (world(c), size(c))).collect(),
            cubes: list("cubes").map(|c| (world(c), size(c))).collect(),
            triangles: list("triangles").map(points).collect(),
        }
    }

    /// Seeks to `t` and compares what is shown with `/bodies`: one line per difference.
    fn check(&self, t: u64) -> Vec<String> {
        let frame = (t / self.dt_ns) as usize;
        let frac = (t % self.dt_ns) as f64 / self.dt_ns as f64;
        let scenario = self.scenario;
        let at = format!("{scenario} at t = {t} ns (frame {frame} + {frac:.3})");
        let bodies = alive(&self.bodies[frame]);
        let previous = frame
            .checked_sub(1)
            .map(|f| alive(&self.bodies[f]))
            .unwrap_or_default();
        let shown = self.show(&self.scene(t, false), t);
        let mut problems = Vec::new();
        let missing: Vec<_> = bodies
            .keys()
            .filter(|id| !shown.contains_key(*id))
            .collect();
        let extra: Vec<_> = shown
            .keys()
            .filter(|id| !bodies.contains_key(*id))
            .collect();
        if !missing.is_empty() || !extra.is_empty() {
            problems.push(format!(
                "{at}: alive, not shown {missing:?}; shown, dead {extra:?}"
            ));
        }
        for (id, s) in &shown {
            let Some(body) = bodies.get(id) else { continue };
            let mut report = |p: String| problems.push(format!("{at}: {id} \"{}\": {p}", s.name));
            if s.name != body["name"] {
                report(format!("named {} in /bodies", body["name"]));
            }
            let Some(pose) = s.pose else {
                report("no /tf transform at or before t".to_owned());
                continue;
            };
            let body_pose = Planar::of_body(body);
            // A body with an AABB part has an upright frame (its parts are drawn turned).
            let upright = has_aabb(&body["shape"]);
            let flat = |p: Planar| if upright { Planar::new(p.at, 0.0) } else { p };
            let want = flat(body_pose);
            // Between frames: still at `f`, or moved along the last step.
            let moved = match previous.get(id) {
                Some(b) if frac > 0.0 => {
                    let last = flat(Planar::of_body(b));
                    let step = Planar::new(want.at - last.at, want.yaw - last.yaw);
                    Planar::new(want.at + step.at * frac, want.yaw + step.yaw * frac)
                }
                _ => want,
            };
            let same = |a: Planar, b: Planar| {
                close(a.at.x, b.at.x) && close(a.at.y, b.at.y) && close_angle(a.yaw, b.yaw)
            };
            if !same(pose, want) && !same(pose, moved) {
                report(format!(
                    "shown at ({}, {}) turned {}, /bodies ({}, {}) turned {}{}",
                    pose.at.x,
                    pose.at.y,
                    pose.yaw,
                    want.at.x,
                    want.at.y,
                    want.yaw,
                    if frac > 0.0 {
                        " (or along its last step)"
                    } else {
                        ""
                    }
                ));
            }
            // An AABB is drawn upright at the angle the scene was drawn at; between frames its
            // body's frame has turned on by up to a frame's turn.
            let slack = wrap(pose.yaw - want.yaw).abs();
            let placed = if upright {
                Planar::new(pose.at, body_pose.yaw)
            } else {
                pose
            };
            compare_shape(s, body, placed, slack, &mut report);
        }
        problems
    }
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

/// Whether a `/bodies` shape has an AABB part.
fn has_aabb(shape: &Value) -> bool {
    shape.get("aabb").is_some()
        || shape["compound"]["parts"]
            .as_array()
            .is_some_and(|parts| parts.iter().any(has_aabb))
}

/// The bodies of a full `/bodies` message, by the name of their frame.
fn alive(full: &Value) -> BTreeMap<String, Value> {
    let bodies = full["bodies"].as_array().unwrap().iter();
    let generation = |b: &Value| b["generation"].as_u64().unwrap_or(0);
    bodies
        .map(|b| (format!("body/{}:{}", b["id"], generation(b)), b.clone()))
        .collect()
}

/// Compares the shown primitives (in the world, through the body's frame) with the body's
/// shape placed at its pose `at`, part by part and point by point.
///
/// An AABB must be drawn upright, turned no more than `aabb_slack` (0 at a frame's time).
fn compare_shape(
    s: &Shown,
    body: &Value,
    at: Planar,
    aabb_slack: f64,
    report: &mut impl FnMut(String),
) {
    let shape = shape_def(&body["shape"]).to_shape().unwrap();
    let (mut cylinders, mut cubes) = (s.cylinders.iter(), s.cubes.iter());
    let mut triangles = s.triangles.iter();
    // A cylinder or cube of `size`, turned `yaw` if it says, at `centre`.
    let solid = |shown: Option<&(Planar, Vec2)>, size: Vec2, yaw: Option<f64>, centre| {
        let &(pose, got) = shown.ok_or("not drawn")?;
        match yaw.filter(|&yaw| !close_angle(pose.yaw, yaw)) {
            Some(yaw) => Err(format!("turned {} in the world, the shape {yaw}", pose.yaw)),
            None if !close2(got, size) => Err(format!("of size {got}, the shape {size}")),
            None => Ok(vec![(pose.at, centre)]),
        }
    };
    for (k, prim) in shape.primitives().iter().enumerate() {
        // Points shown in the world, each with where the shape puts it.
        let points = match place(prim, &Pose::new(at.at, at.yaw), Vec2::ZERO) {
            PlacedPrimitive::Circle(c) => {
                let d = Vec2::splat(2.0 * c.radius);
                solid(cylinders.next(), d, None, c.center)
            }
            PlacedPrimitive::Aabb(b) => match cubes.next() {
                Some(&(pose, _)) if wrap(pose.yaw).abs() > aabb_slack + TOL => Err(format!(
                    "turned {} in the world, an AABB is upright",
                    pose.yaw
                )),
                cube => {
                    let upright = cube.map(|&(pose, size)| (Planar::new(pose.at, 0.0), size));
                    solid(upright.as_ref(), 2.0 * b.half, Some(0.0), b.center)
                }
            },
            PlacedPrimitive::Obb(b) => {
                let yaw = libm::atan2(b.rot.s, b.rot.c);
                solid(cubes.next(), 2.0 * b.half, Some(yaw), b.center)
            }
            PlacedPrimitive::Polygon(p) => match triangles.next() {
                Some(points) if points.len() == p.count => {
                    Ok(points.iter().copied().zip(p.vertices).collect())
                }
                other => Err(format!("drawn as {other:?}")),
            },
            // A capsule's outline: every point at the radius from the core segment.
            PlacedPrimitive::Capsule(c) => triangles.next().ok_or("not drawn".into()).map(|pts| {
                let d = c.b - c.a;
                let on =
                    |p: Vec2| c.a + d * ((p - c.a).dot(d) / d.dot(d).max(1e-300)).clamp(0.0, 1.0);
                let outline = |p: Vec2| on(p) + (p - on(p)).normalize_or_zero() * c.radius;
                pts.iter().map(|&p| (p, outline(p))).collect()
            }),
        };
        let points = points.unwrap_or_else(|e| {
            report(format!("part {k} ({prim:?}): {e}"));
            Vec::new()
        });
        for (i, (got, want)) in points.into_iter().enumerate() {
            if !close2(got, want) {
                report(format!(
                    "part {k} point {i} at {got} in the world, shape {want}"
                ));
            }
        }
    }
    if cylinders.next().is_some() || cubes.next().is_some() || triangles.next().is_some() {
        report("more primitives drawn than its shape has parts".to_owned());
    }
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
        let log = Log::record(scenario);
        let mut times = log.times(&mut Rng::new(seed));
        // And every frame's time.
        times.extend((0..log.bodies.len() as u64).map(|f| f * log.dt_ns));
        let problems: Vec<String> = times.iter().flat_map(|&t| log.check(t)).collect();
        let n = problems.len();
        let first = problems[..n.min(12)].join("\n");
        assert!(n == 0, "{scenario}: {n} differences, the first:\n{first}");
    }
}

#[test]
fn seeking_back_and_forth_shows_what_a_fresh_seek_and_playing_show() {
    let (log, fresh) = (Log::record("asteroids"), Log::record("asteroids"));
    let times = log.times(&mut Rng::new(7));
    let seek = |log: &Log, t| log.show(&log.scene(t, false), t);
    let want: BTreeMap<u64, _> = times.iter().map(|&t| (t, seek(&fresh, t))).collect();
    // The drawn times jump back and forth; each pair is also seen the other way round.
    for pair in times.windows(2) {
        for t in [pair[0], pair[1], pair[0]] {
            assert!(seek(&log, t) == want[&t], "seeking to {t} after {pair:?}");
        }
    }
    for t in times {
        let played = log.show(&log.scene(t, true), t);
        assert!(played == want[&t], "played to {t}");
    }
}
