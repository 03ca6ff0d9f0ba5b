//! The `cull` stage (`crates/sim/src/stages/cull.rs`): moving bodies outside the active
//! region are frozen, and resume exactly where they were. See `common/mod.rs` for how the
//! expected values are found.

mod common;

use common::*;
use ricochet_sim::{GameEvent, Removal, Simulation, Stage};

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
        assert!(
            (0..c.world().len()).all(|i| !c.world().frozen(i)),
            "frame {}",
            b.frame
        );
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
        assert_eq!(w.frozen(i), frozen, "frame {frame}: {} frozen", self.name);
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
            w.velocity(i),
            ricochet_geom::Vec2::new(0.0, 1.0),
            "frame {frame}"
        );
        assert_eq!(
            w.lifetime(i),
            self.lifetime,
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
                s.world().lifetime(1),
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
