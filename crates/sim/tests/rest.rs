//! Skipping bodies nothing is happening to (`crates/sim/src/stages/cull.rs` and
//! `sleep.rs`): the `cull` stage (the active region) and the `sleep` stage.
//!
//! Both are optimisations: they must never change what happens to a body that is simulated.
//! So the expected values here come from the same scene run without the feature (frame by
//! frame, digest by digest), or from exact arithmetic on the same `f64` operations the
//! stages do (semi-implicit Euler: `x += v * dt`, frame 0 does not move).

use ricochet_geom::Vec2;
use ricochet_scenes::tiles::Tiles;
use ricochet_sim::{
    Action, Event, FrameOutput, GameEvent, Phase, Removal, ScriptAction, Simulation, Stage,
    StageSet, Stats, load_scenario,
};

fn sim(text: &str) -> Simulation {
    let s = load_scenario(text, "rest.toml").unwrap_or_else(|e| panic!("{e}\n{text}"));
    Simulation::new(&s)
}

/// The stats without the stage lists (a run with `cull` or `sleep` lists that stage).
fn stats_without_stages(s: &Stats) -> Stats {
    Stats {
        stages_run: StageSet::EMPTY,
        stages_skipped: StageSet::EMPTY,
        ..s.clone()
    }
}

/// `World::active` is documented as the moving bodies that are neither frozen nor asleep.
fn active_as_documented(sim: &Simulation) -> Vec<u32> {
    let w = sim.world();
    w.movers()
        .iter()
        .copied()
        .filter(|&i| !w.frozen[i as usize] && !w.asleep[i as usize])
        .collect()
}

/// Steps both simulations `frames + 1` times (frames 0 to `frames`) and asserts that every
/// frame ends with the same world digest, contacts, events and removed bodies.
/// `check` sees each frame's two outputs and simulations (plain first, feature second).
fn run_side_by_side(
    plain: &mut Simulation,
    featured: &mut Simulation,
    frames: u64,
    mut check: impl FnMut(&FrameOutput, &FrameOutput, &Simulation, &Simulation),
) {
    for frame in 0..=frames {
        let a = plain.step();
        let b = featured.step();
        assert_eq!(a.frame, frame);
        assert_eq!(b.frame, frame);
        assert_eq!(
            plain.world().digest(),
            featured.world().digest(),
            "frame {frame}: digests differ\nplain: {:?}\nfeatured: {:?}",
            plain.world().position,
            featured.world().position
        );
        assert_eq!(a.contacts, b.contacts, "frame {frame}: contacts differ");
        assert_eq!(a.events, b.events, "frame {frame}: events differ");
        assert_eq!(a.removed, b.removed, "frame {frame}: removed bodies differ");
        check(&a, &b, plain, featured);
    }
}

/// A walled box of mixed shapes under gravity: AABB boxes (per-axis `separate` with the
/// floor and each other), circles, capsules, polygons and OBBs (`separate` along the normal,
/// also against the boxes), a gravity-free `ghost` that reports what it passes through,
/// bullets with a lifetime that are destroyed by what they hit, and script spawns.
/// `world_extra` goes into `[world]` (after `gravity`), `region` after it.
fn busy_scene(world_extra: &str, region: &str) -> String {
    format!(
        r#"
hz = 60
layers = ["tile", "box", "ball", "ghost", "bullet"]
collide = [
  {{ a = "box", b = "tile", response = "separate" }},
  {{ a = "box", b = "box", response = "separate" }},
  {{ a = "ball", b = "tile", response = "separate" }},
  {{ a = "ball", b = "ball", response = "separate" }},
  {{ a = "ball", b = "box", response = "separate" }},
  {{ a = "ghost", b = "ball", response = "report" }},
  {{ a = "ghost", b = "box", response = "report" }},
  {{ a = "bullet", b = "ball", response = "destroy", destroy = "a" }},
  {{ a = "bullet", b = "tile", response = "destroy", destroy = "a" }},
]
script = [
  {{ frame = 40, action = "spawn", template = "bullet", position = [-9, 4], velocity = [14, 3] }},
  {{ frame = 90, action = "spawn", template = "bullet", position = [9, 2], velocity = [-16, 1] }},
  {{ frame = 120, action = "apply_impulse", body = "crate", impulse = [6, 9] }},
  {{ frame = 150, action = "spawn", template = "pebble", position = [0.3, 12], velocity = [-2, 0] }},
  {{ frame = 200, action = "set_velocity", body = "ghost", velocity = [-4, 0.5] }},
]

[world]
gravity = [0, -20]
{world_extra}
{region}

[templates.bullet]
layer = "bullet"
shape = {{ kind = "circle", radius = 0.1 }}
gravity_scale = 0
lifetime = 45

[templates.pebble]
layer = "ball"
shape = {{ kind = "circle", radius = 0.3 }}

[[bodies]]
name = "floor"
layer = "tile"
kind = "static"
shape = {{ kind = "aabb", half_extents = [12, 1] }}
position = [0, -1]

[[bodies]]
name = "left wall"
layer = "tile"
kind = "static"
shape = {{ kind = "aabb", half_extents = [1, 15] }}
position = [-13, 14]

[[bodies]]
name = "right wall"
layer = "tile"
kind = "static"
shape = {{ kind = "aabb", half_extents = [1, 15] }}
position = [13, 14]

[[bodies]]
name = "crate"
layer = "box"
shape = {{ kind = "aabb", half_extents = [0.5, 0.5] }}
position = [-3.2, 2.5]
velocity = [1.5, 0]

[[bodies]]
name = "crate_b"
layer = "box"
shape = {{ kind = "aabb", half_extents = [0.6, 0.4] }}
position = [-2.7, 5.1]

[[bodies]]
name = "crate_c"
layer = "box"
shape = {{ kind = "aabb", half_extents = [0.45, 0.7] }}
position = [4.1, 1.3]
velocity = [-3, 2]

[[bodies]]
name = "ball"
layer = "ball"
shape = {{ kind = "circle", radius = 0.5 }}
position = [-6, 6]
velocity = [4, 0]

[[bodies]]
name = "capsule"
layer = "ball"
shape = {{ kind = "capsule", a = [-0.6, 0], b = [0.6, 0], radius = 0.25 }}
position = [2, 8]
velocity = [-1, 0]
angular_velocity = 1.5

[[bodies]]
name = "wedge"
layer = "ball"
shape = {{ kind = "polygon", vertices = [[0.8, -0.4], [0, 0.6], [-0.8, -0.4]] }}
position = [6, 4]
velocity = [-2.5, 3]
angular_velocity = -0.7

[[bodies]]
name = "plank"
layer = "ball"
shape = {{ kind = "obb", half_extents = [0.9, 0.2], angle = 0.3 }}
position = [-1, 11]
velocity = [0.5, -1]

[[bodies]]
name = "ghost"
layer = "ghost"
shape = {{ kind = "circle", radius = 0.8 }}
position = [-10, 1]
velocity = [3, 0]
gravity_scale = 0
"#
    )
}

/// Sums of what a run produced, so a comparison is known to compare something.
#[derive(Default)]
struct Totals {
    contacts: usize,
    events: usize,
    removed: usize,
    contact_events: usize,
    hits: usize,
    per_axis: usize,
}

impl Totals {
    fn add(&mut self, out: &FrameOutput) {
        self.contacts += out.contacts.len();
        self.events += out.events.len();
        self.removed += out.removed.len();
        self.contact_events += out
            .events
            .iter()
            .filter(|e| matches!(e, GameEvent::Contact { .. }))
            .count();
        self.hits += out
            .events
            .iter()
            .filter(|e| matches!(e, GameEvent::PushedApart { .. }))
            .count();
        self.per_axis += out
            .contacts
            .iter()
            .filter(|c| matches!(c.phase, Phase::X | Phase::Y))
            .count();
    }

    /// The busy scene really collides in every way it is meant to.
    fn assert_busy(&self) {
        assert!(self.contact_events > 0, "no `report` contacts");
        assert!(self.hits > 0, "no separation along the normal");
        assert!(self.per_axis > 0, "no per-axis separation");
        assert!(self.removed >= 2, "no bullet was removed");
    }
}

#[test]
fn culling_that_freezes_nothing_changes_nothing() {
    // The region follows the ghost, which crosses the room; it covers the whole room (24
    // by 30 units) from anywhere the ghost goes in 300 frames.
    let region = "[world.active_region]\nfocus = \"ghost\"\nhalf_extents = [1000, 1000]";
    let mut plain = sim(&busy_scene("", ""));
    let mut culled = sim(&busy_scene("", region));
    let mut totals = Totals::default();
    run_side_by_side(&mut plain, &mut culled, 300, |a, b, _, c| {
        totals.add(a);
        assert_eq!(b.stats.frozen, 0, "frame {}: froze a body", b.frame);
        assert!(c.world().frozen.iter().all(|f| !f), "frame {}", b.frame);
        assert!(
            b.stats.stages_run.contains(Stage::Cull),
            "frame {}",
            b.frame
        );
        assert!(
            !a.stats.stages_run.contains(Stage::Cull),
            "frame {}",
            a.frame
        );
        assert_eq!(
            stats_without_stages(&a.stats),
            stats_without_stages(&b.stats),
            "frame {}",
            a.frame
        );
    });
    totals.assert_busy();
}

#[test]
fn sleeping_that_never_triggers_changes_nothing() {
    let mut plain = sim(&busy_scene("", ""));
    let mut sleepy = sim(&busy_scene("sleep_after = 1000", ""));
    let mut totals = Totals::default();
    let mut moving_frames = 0;
    run_side_by_side(&mut plain, &mut sleepy, 300, |a, b, _, s| {
        totals.add(a);
        assert_eq!(b.stats.asleep, 0, "frame {}: a body fell asleep", b.frame);
        assert!(s.world().asleep.iter().all(|f| !f), "frame {}", b.frame);
        if b.frame > 0 {
            assert!(
                b.stats.stages_run.contains(Stage::Sleep),
                "frame {}",
                b.frame
            );
        }
        assert_eq!(
            stats_without_stages(&a.stats),
            stats_without_stages(&b.stats),
            "frame {}",
            a.frame
        );
        moving_frames += usize::from(b.frame > 0 && b.stats.kinetic_energy > 0.0);
    });
    totals.assert_busy();
    // Things move the whole run (the ghost never stops).
    assert_eq!(moving_frames, 300, "frames 1 to 300 all have motion");
}

/// A static floor (top at y = 0, 20 wide) under gravity `[0, -20]`, for boxes solid to it
/// and to each other.
fn boxes_on_a_floor() -> Tiles {
    Tiles::new("box", -20.0)
        .solid()
        .tile("floor", [10.0, 1.0], [0.0, -1.0])
}

/// Boxes dropped onto a static floor (top at y = 0) under gravity `[0, -20]`: `lone` on its
/// own, and `low` with `high` falling onto it (a stack of two); boxes are solid to each
/// other. More bodies can be added to the builder.
fn boxes(sleep_after: Option<u32>) -> Tiles {
    boxes_on_a_floor()
        .sleep_after(sleep_after)
        .aabb("lone", [0.5, 0.5], [-4.3, 3.1])
        .aabb("low", [0.7, 0.35], [2.15, 1.7])
        .aabb("high", [0.4, 0.6], [2.4, 3.9])
}

/// Dense index of the live body named `name` (the lowest id with that name).
fn index(sim: &Simulation, name: &str) -> usize {
    sim.world()
        .find(name)
        .unwrap_or_else(|| panic!("no body named {name}"))
}

/// Asserts what the docs promise a sleeper: zero velocity, `grounded` kept, not integrated.
fn assert_sleepers_rest(sim: &Simulation, frame: u64) {
    let w = sim.world();
    for i in 0..w.len() {
        if w.asleep[i] {
            assert_eq!(
                w.velocity[i],
                ricochet_geom::Vec2::ZERO,
                "frame {frame}: {}",
                w.name[i]
            );
            assert!(
                w.grounded[i],
                "frame {frame}: {} sleeps ungrounded",
                w.name[i]
            );
            assert!(
                !w.active().contains(&(i as u32)),
                "frame {frame}: {}",
                w.name[i]
            );
        }
    }
    assert_eq!(
        w.asleep.iter().filter(|a| **a).count(),
        w.sleeping(),
        "frame {frame}"
    );
}

#[test]
fn resting_boxes_fall_asleep_without_changing_any_state() {
    let mut plain = Simulation::new(&boxes(None).scenario());
    let mut sleepy = Simulation::new(&boxes(Some(10)).scenario());
    // The lone box and the bottom of the stack rest on the static floor and sleep; the top
    // of the stack rests on a dynamic box, so it never sleeps (it would float if that box
    // moved away).
    let n_boxes = 2;
    let (mut contacts_plain, mut contacts_sleepy) = (0, 0);
    let mut all_asleep = 0;
    for frame in 0..=300u64 {
        let a = plain.step();
        let b = sleepy.step();
        // Skipping a body at a fixed point of the step changes nothing: not one bit.
        assert_eq!(
            plain.world().digest(),
            sleepy.world().digest(),
            "frame {frame}: digests differ\nplain: {:?} {:?}\nsleepy: {:?} {:?}",
            plain.world().position,
            plain.world().velocity,
            sleepy.world().position,
            sleepy.world().velocity,
        );
        assert_eq!(
            a.stats.asleep, 0,
            "frame {frame}: nothing sleeps without sleep_after"
        );
        assert_eq!(b.stats.asleep, sleepy.world().sleeping(), "frame {frame}");
        assert_sleepers_rest(&sleepy, frame);
        contacts_plain += a.contacts.len();
        contacts_sleepy += b.contacts.len();
        all_asleep += usize::from(b.stats.asleep == n_boxes);
    }
    assert!(
        all_asleep > 0,
        "the two boxes on the floor were never both asleep"
    );
    assert_eq!(sleepy.world().sleeping(), n_boxes, "all asleep at the end");
    // Every box resting in the plain run is pushed out of what holds it once a frame.
    assert!(
        contacts_sleepy < contacts_plain,
        "sleeping skipped no resting contact: {contacts_sleepy} vs {contacts_plain}"
    );
    assert!(
        contacts_plain - contacts_sleepy >= all_asleep * n_boxes,
        "{contacts_plain} - {contacts_sleepy} contacts; all asleep for {all_asleep} frames"
    );
}

/// A small box that falls from high above `lone` (top at y = 1 once it rests) and lands on
/// it long after `lone` fell asleep.
fn with_dropper(scene: Tiles) -> Simulation {
    Simulation::new(&scene.aabb("dropper", [0.3, 0.3], [-4.1, 80.0]).scenario())
}

#[test]
fn a_sleeping_box_wakes_when_something_lands_on_it() {
    let mut plain = with_dropper(boxes(None));
    let mut sleepy = with_dropper(boxes(Some(10)));
    let (lone, dropper) = (index(&sleepy, "lone"), index(&sleepy, "dropper"));
    let (e_lone, e_dropper) = (sleepy.world().entity[lone], sleepy.world().entity[dropper]);
    // Free fall from rest, semi-implicit Euler: after n moves it has fallen
    // n(n+1)/2 g dt². It overlaps `lone` once its bottom (y - 0.3) passes 1: after 78.7.
    let dt = 1.0 / 60.0;
    let landing = (1..)
        .find(|&n: &u64| (n * (n + 1)) as f64 / 2.0 * 20.0 * dt * dt > 80.0 - 0.3 - 1.0)
        .unwrap();
    assert_eq!(
        landing, 168,
        "n(n+1) > 78.7 * 360 = 28332 first for n = 168"
    );
    let mut landed_at = None;
    let mut asleep_before = false;
    for frame in 0..=300u64 {
        let a = plain.step();
        let b = sleepy.step();
        assert_eq!(
            plain.world().digest(),
            sleepy.world().digest(),
            "frame {frame}: digests differ\nplain: {:?} {:?}\nsleepy: {:?} {:?}",
            plain.world().position,
            plain.world().velocity,
            sleepy.world().position,
            sleepy.world().velocity,
        );
        assert!(a.contacts.len() >= b.contacts.len(), "frame {frame}");
        assert_sleepers_rest(&sleepy, frame);
        let hit = b
            .contacts
            .iter()
            .any(|c| (c.a, c.b) == (e_lone, e_dropper) && c.phase == Phase::Y);
        if hit && landed_at.is_none() {
            landed_at = Some(frame);
            assert!(asleep_before, "frame {frame}: lone was not asleep when hit");
            assert!(
                !sleepy.world().asleep[lone],
                "frame {frame}: lone still asleep after the landing"
            );
            assert!(
                b.events
                    .iter()
                    .any(|e| matches!(e, GameEvent::PushedOut { axis: 1, .. })),
                "{:?}",
                b.events
            );
        }
        asleep_before = sleepy.world().asleep[lone];
    }
    assert_eq!(
        landed_at,
        Some(landing),
        "the dropper lands when free fall says"
    );
    // Both settle again: the two boxes on the floor end asleep; the stack's top and the
    // dropper rest on dynamic boxes, so they never sleep.
    assert_eq!(sleepy.world().sleeping(), 2);
}

/// The exact semi-implicit Euler step of one coordinate: `x += v * dt`.
fn advance(x: &mut f64, v: f64, dt: f64) {
    *x += v * dt;
}

/// Whether the region (centre `focus`, half extents `h`) overlaps the circle at `c` with
/// radius `r`, touching included: the four comparisons `cull` makes (`Bounds::overlaps` of
/// `Bounds::around`), on the same `f64` values. The broad-phase bounds are padded outwards
/// by about 1e-13, which only matters for a near miss: no comparison may be one.
fn region_overlaps(focus: (f64, f64), h: f64, c: (f64, f64), r: f64) -> bool {
    let edges = [
        (focus.0 - h, c.0 + r),
        (c.0 - r, focus.0 + h),
        (focus.1 - h, c.1 + r),
        (c.1 - r, focus.1 + h),
    ];
    for (lo, hi) in edges {
        assert!(
            lo <= hi || lo - hi > 1e-9,
            "a near miss: {lo} > {hi} by {}",
            lo - hi
        );
    }
    edges.iter().all(|(lo, hi)| lo <= hi)
}

/// A focus `player` moving right at 10 units/s, no gravity, nothing collides (no
/// `[[collide]]`), a region of half extents [20, 20]; `bodies` and `script` are added.
fn region_scene(bodies: &str, script: &str) -> String {
    format!(
        r#"
hz = 60
layers = ["player", "rock"]
{script}

[world.active_region]
focus = "player"
half_extents = [20, 20]

[[bodies]]
name = "player"
layer = "player"
shape = {{ kind = "circle", radius = 0.5 }}
velocity = [10, 0]
{bodies}
"#
    )
}

/// A body the region may freeze: a circle moving up at 1 unit/s, as the model sees it.
struct Model {
    name: &'static str,
    x: f64,
    y: f64,
    r: f64,
    lifetime: Option<u32>,
}

impl Model {
    /// One frame: frozen (returned) when the region misses it at the frame's start, else
    /// moved (not at frame 0) and its lifetime counted down.
    fn frame(&mut self, frame: u64, focus: Option<(f64, f64)>, dt: f64) -> bool {
        let frozen = focus.is_some_and(|f| !region_overlaps(f, 20.0, (self.x, self.y), self.r));
        if !frozen {
            if frame > 0 {
                advance(&mut self.y, 1.0, dt);
            }
            if let Some(l) = &mut self.lifetime {
                *l -= 1;
            }
        }
        frozen
    }

    fn assert_matches(&self, sim: &Simulation, frame: u64, frozen: bool) {
        let i = index(sim, self.name);
        let w = sim.world();
        assert_eq!(w.frozen[i], frozen, "frame {frame}: {} frozen", self.name);
        assert_eq!(
            (w.position[i].x.to_bits(), w.position[i].y.to_bits()),
            (self.x.to_bits(), self.y.to_bits()),
            "frame {frame}: {} at {} instead of ({}, {})",
            self.name,
            w.position[i],
            self.x,
            self.y
        );
        assert_eq!(
            w.velocity[i],
            ricochet_geom::Vec2::new(0.0, 1.0),
            "frame {frame}"
        );
        assert_eq!(
            w.lifetime[i], self.lifetime,
            "frame {frame}: {} lifetime",
            self.name
        );
    }
}

#[test]
fn a_frozen_body_resumes_exactly_where_it_was() {
    let dt = 1.0 / 60.0;
    // Where the player is at the start of frame f: f - 1 moves of 10 * dt (frame 0 and
    // frame 1 start at 0).
    let player_at = |moves: u32| {
        let mut x = 0.0;
        for _ in 0..moves {
            advance(&mut x, 10.0, dt);
        }
        x
    };
    // The rock (radius 0.625) is placed so that the region's right edge touches its left
    // edge exactly after 479 moves (at the start of frame 480): touching is overlapping.
    // px + 20 and px + 20.625 are exact (a multiple of the ulp of px, in the same binade).
    let rock_x = player_at(479) + 20.625;
    assert_eq!(rock_x - 0.625, player_at(479) + 20.0, "an exact touch");
    assert!(player_at(478) + 20.0 < rock_x - 0.625 - 0.1);
    let mut s = sim(&region_scene(
        &format!(
            r#"
[[bodies]]
name = "rock"
layer = "rock"
shape = {{ kind = "circle", radius = 0.625 }}
position = [{rock_x:?}, 0]
velocity = [0, 1]
lifetime = 1000
"#
        ),
        "",
    ));
    assert_eq!(s.dt(), dt);
    assert_eq!(
        s.world().position[1].x,
        rock_x,
        "the file holds the exact value"
    );
    let mut rock = Model {
        name: "rock",
        x: rock_x,
        y: 0.0,
        r: 0.625,
        lifetime: Some(1000),
    };
    let mut px = 0.0;
    let (mut first_thawed, mut refrozen) = (None, None);
    for frame in 0..=800u64 {
        let frozen = rock.frame(frame, Some((px, 0.0)), dt);
        if frame > 0 {
            advance(&mut px, 10.0, dt);
        }
        if !frozen && first_thawed.is_none() {
            first_thawed = Some(frame);
        }
        if frozen && first_thawed.is_some() && refrozen.is_none() {
            refrozen = Some(frame);
        }
        let out = s.step();
        assert_eq!(
            s.world().position[0].x.to_bits(),
            px.to_bits(),
            "frame {frame}: player"
        );
        assert_eq!(out.stats.frozen, usize::from(frozen), "frame {frame}");
        rock.assert_matches(&s, frame, frozen);
        if first_thawed.is_none() {
            // Bit for bit where it started, with its lifetime paused.
            assert_eq!(s.world().position[1], ricochet_geom::Vec2::new(rock_x, 0.0));
            assert_eq!(
                s.world().lifetime[1],
                Some(1000),
                "frame {frame}: lifetime paused"
            );
        }
    }
    assert_eq!(
        first_thawed,
        Some(480),
        "479 moves bring the region to the rock"
    );
    // The region's left edge px - 20 passes the rock's right edge, px(479) + 21.25, after
    // 479 + 6 * 41.25 = 726.5 moves: from frame 728 (727 moves) it is frozen again.
    assert_eq!(refrozen, Some(728));
    // It moved on frames 480 to 727 only: 248 steps of 1/60 up, 248 frames of lifetime.
    assert!((rock.y - 248.0 / 60.0).abs() < 1e-12, "{}", rock.y);
    assert_eq!(rock.lifetime, Some(1000 - 248));
}

#[test]
fn the_region_follows_the_focus_and_nothing_is_frozen_without_it() {
    let mut s = sim(&region_scene(
        r#"
[[bodies]]
name = "post"
layer = "rock"
shape = { kind = "circle", radius = 0.5 }
position = [-5.25, 0]
velocity = [0, 1]

[[bodies]]
name = "rock"
layer = "rock"
shape = { kind = "circle", radius = 0.5 }
position = [100.25, 0]
velocity = [0, 1]
lifetime = 40
"#,
        r#"script = [{ frame = 150, action = "destroy", body = "player" }]"#,
    ));
    let dt = s.dt();
    let mut post = Model {
        name: "post",
        x: -5.25,
        y: 0.0,
        r: 0.5,
        lifetime: None,
    };
    let mut rock = Model {
        name: "rock",
        x: 100.25,
        y: 0.0,
        r: 0.5,
        lifetime: Some(40),
    };
    let mut px = 0.0;
    let mut post_frozen_frames = Vec::new();
    for frame in 0..=240u64 {
        // The script runs before `cull`: from frame 150 there is no focus.
        let focus = (frame < 150).then_some((px, 0.0));
        let post_frozen = post.frame(frame, focus, dt);
        let rock_frozen = rock.frame(frame, focus, dt);
        if frame > 0 {
            advance(&mut px, 10.0, dt);
        }
        if post_frozen {
            post_frozen_frames.push(frame);
        }
        let out = s.step();
        let frozen = usize::from(post_frozen) + usize::from(rock_frozen);
        assert_eq!(out.stats.frozen, frozen, "frame {frame}");
        if frame >= 150 {
            assert_eq!(out.stats.frozen, 0, "frame {frame}: frozen without a focus");
            assert!(s.world().find("player").is_none());
        } else {
            assert_eq!(
                s.world().position[0].x.to_bits(),
                px.to_bits(),
                "frame {frame}"
            );
        }
        post.assert_matches(&s, frame, post_frozen);
        if rock.lifetime == Some(0) {
            // Expired this frame, 40 unfrozen frames after the focus went.
            assert_eq!(frame, 150 + 39);
            assert_eq!(out.removed.len(), 1, "{:?}", out.removed);
            assert_eq!(out.removed[0].name, "rock");
            assert!(
                out.events.iter().any(|e| matches!(
                    e,
                    GameEvent::Removed {
                        cause: Removal::Expired,
                        ..
                    }
                )),
                "{:?}",
                out.events
            );
            rock.lifetime = None;
            rock.name = "gone";
        } else if rock.name == "rock" {
            rock.assert_matches(&s, frame, rock_frozen);
            assert_eq!(rock_frozen, frame < 150, "frame {frame}");
        } else {
            assert!(s.world().find("rock").is_none(), "frame {frame}");
        }
    }
    // By hand: the region's left edge px - 20 passes the post's right edge -4.75 after 91.5
    // moves of 1/6, so from frame 93 (92 moves) until the focus is destroyed at frame 150.
    assert_eq!(post_frozen_frames, (93..150).collect::<Vec<u64>>());
    assert_eq!(rock.name, "gone", "the rock's paused lifetime ran out");
    // The post moved on frames 1 to 92 and 150 to 240: 183 steps.
    assert!((post.y - 183.0 / 60.0).abs() < 1e-12, "{}", post.y);
}

/// Steps a scene with and without `sleep_after = 10` and asserts the digests agree on every
/// frame.
fn sleeping_changes_nothing(scene: Tiles, frames: u64) -> (Simulation, Simulation) {
    let mut plain = Simulation::new(&scene.clone().scenario());
    let mut sleepy = Simulation::new(&scene.sleep_after(Some(10)).scenario());
    for frame in 0..=frames {
        plain.step();
        let out = sleepy.step();
        assert_eq!(
            plain.world().digest(),
            sleepy.world().digest(),
            "frame {frame}: digests differ (asleep {:?}, active {:?})\nplain:  {:?}\nsleepy: {:?}",
            sleepy.world().asleep,
            sleepy.world().active(),
            plain.world().position,
            sleepy.world().position,
        );
        assert_eq!(out.stats.asleep, sleepy.world().sleeping(), "frame {frame}");
    }
    (plain, sleepy)
}

#[test]
fn a_woken_body_is_simulated_from_the_next_frame() {
    // `sitter` rests on the ledge, 0.01 from its right edge (x = 2), and falls asleep; the
    // gravity-free `bowler` rolls into it at frame 43 and pushes it half the depth (0.055)
    // past the edge. Without sleeping it rolls off the corner and falls from frame 44.
    let scene = Tiles::new("ball", -20.0)
        .solid()
        .tile("ledge", [25.0, 1.0], [-23.0, -1.0])
        .ball("sitter", 0.5, [1.99, 0.5])
        .ball("bowler", 0.5, [-20.4, 0.5])
        .with(|b| {
            b.velocity = Vec2::new(30.0, 0.0);
            b.gravity_scale = 0.0;
        });
    let (plain, sleepy) = sleeping_changes_nothing(scene, 80);
    assert!(plain.world().position[index(&plain, "sitter")].y < 0.2);
    assert_eq!(sleepy.world().active(), active_as_documented(&sleepy));
}

#[test]
fn a_box_asleep_on_a_box_falls_when_that_box_slides_away() {
    // Two unit boxes stacked flush on the floor; both rest from frame 1 and sleep from
    // frame 10. At frame 60 the script sends `low` sliding right at 3 units/s; from frame
    // 79 it no longer holds `top` up (x overlap 0.5 - 0.5000000000000002 < 0), and without
    // sleeping `top` falls from then on.
    let scene = boxes_on_a_floor()
        .aabb("low", [0.5, 0.5], [0.0, 0.5])
        .aabb("top", [0.5, 0.5], [0.0, 1.5])
        .event(Event {
            frame: 60,
            action: ScriptAction::Body {
                name: "low".to_owned(),
                action: Action::SetVelocity(Vec2::new(3.0, 0.0)),
            },
        });
    let (plain, sleepy) = sleeping_changes_nothing(scene, 120);
    // Without sleeping, `top` lands on the floor (y = 0.5).
    assert_eq!(plain.world().position[index(&plain, "top")].y, 0.5);
    assert_eq!(sleepy.world().position[index(&sleepy, "top")].y, 0.5);
}
