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

mod drawing;
mod log;

use std::collections::BTreeMap;

use ricochet_scenes::Rng;

use drawing::alive;
use log::{Log, PER_BODY_LIMIT};

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
