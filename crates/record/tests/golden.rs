//! `golden::check` on the level of `examples/record_game.rs`: the golden in
//! `tests/golden/thrown_ball.mcap` holds the integrator's ball at every frame; a one-ulp
//! change of the kick at frame 60 fails naming that frame; blessing then passes; a missing
//! golden says how to record one. Each test works on a copy in a temporary directory (a
//! check writes beside the golden).

use std::path::{Path, PathBuf};

use ricochet_geom::Vec2;
use ricochet_record::golden::{self, GoldenError};
use ricochet_sim::{Scenario, Simulation};

#[path = "../examples/shared/thrown_ball.rs"]
mod thrown_ball;
use thrown_ball::{FRAMES, GRAVITY, KICK, KICK_FRAME, THROW, kick, level};

/// The golden, copied into `dir`.
fn golden_copy(dir: &Path) -> PathBuf {
    let golden = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden/thrown_ball.mcap");
    let copy = dir.join("thrown_ball.mcap");
    std::fs::copy(golden, &copy).unwrap();
    copy
}

/// The level with the kick one ulp stronger: nothing differs before the kick's frame.
fn one_ulp_heavier() -> Scenario {
    let mut s = level().unwrap();
    s.script = vec![kick(Vec2::new(KICK.x, KICK.y.next_up()))];
    s
}

#[test]
fn the_golden_holds_the_integrators_ball_and_the_level_matches_it() {
    let dir = tempfile::tempdir().unwrap();
    let golden = golden_copy(dir.path());
    // The golden's own frames, against semi-implicit Euler computed here (not against
    // another run): what the check compares with is right.
    let log = ricochet_log::read_log_file(&golden).unwrap();
    let mut states = ricochet_log::BodyStates::default();
    let dt = level().unwrap().world.dt;
    let (mut p, mut v) = (Vec2::new(0.0, 0.0), THROW);
    let mut n = 0u64;
    for m in log.iter().filter(|m| m.topic == "/bodies") {
        if n == KICK_FRAME {
            v = KICK;
        }
        if n > 0 {
            v.y += GRAVITY * dt;
            p = Vec2::new(p.x + v.x * dt, p.y + v.y * dt);
        }
        let all = states.apply(&m.data);
        let ball = all["bodies"]
            .as_array()
            .unwrap()
            .iter()
            .find(|b| b["name"] == "ball")
            .unwrap();
        assert_eq!(
            ball["position"][1].as_f64().unwrap().to_bits(),
            p.y.to_bits(),
            "frame {n}"
        );
        assert_eq!(
            ball["velocity"][1].as_f64().unwrap().to_bits(),
            v.y.to_bits(),
            "frame {n}"
        );
        n += 1;
    }
    assert_eq!(n, FRAMES + 1);

    let mut sim = Simulation::new(&level().unwrap());
    golden::check_or_bless(&golden, &mut sim, FRAMES, false).unwrap();
    assert!(
        !dir.path().join("thrown_ball.new.mcap").exists(),
        "a passing check leaves no new log"
    );
}

#[test]
fn a_one_ulp_change_fails_naming_the_frame() {
    let dir = tempfile::tempdir().unwrap();
    let golden = golden_copy(dir.path());
    let mut sim = Simulation::new(&one_ulp_heavier());
    let err = golden::check_or_bless(&golden, &mut sim, FRAMES, false).unwrap_err();
    let GoldenError::Differs { first, report, new } = &err else {
        panic!("not a divergence: {err}");
    };
    assert_eq!(first.frame, Some(KICK_FRAME), "{report}");
    assert_eq!(first.topic, "/bodies", "{report}");
    assert!(
        first.body.as_deref().unwrap_or("").contains("ball"),
        "{report}"
    );
    assert!(report.contains("first difference: frame 60 "), "{report}");
    assert!(err.to_string().contains("RICOCHET_BLESS=1"), "{err}");
    assert!(
        new.exists(),
        "a failing check keeps its log for `ricochet diff`"
    );
}

#[test]
fn bless_then_passes_and_the_old_level_then_fails() {
    let dir = tempfile::tempdir().unwrap();
    let golden = golden_copy(dir.path());
    let mut heavier = Simulation::new(&one_ulp_heavier());
    golden::check_or_bless(&golden, &mut heavier, FRAMES, true).unwrap();
    let mut again = Simulation::new(&one_ulp_heavier());
    golden::check_or_bless(&golden, &mut again, FRAMES, false).unwrap();
    let mut old = Simulation::new(&level().unwrap());
    let err = golden::check_or_bless(&golden, &mut old, FRAMES, false).unwrap_err();
    assert!(
        matches!(err, GoldenError::Differs { ref first, .. } if first.frame == Some(KICK_FRAME)),
        "{err}"
    );
}

#[test]
fn a_missing_golden_says_how_to_record_it() {
    let dir = tempfile::tempdir().unwrap();
    let golden = dir.path().join("none.mcap");
    let mut sim = Simulation::new(&level().unwrap());
    let err = golden::check_or_bless(&golden, &mut sim, FRAMES, false).unwrap_err();
    assert!(matches!(err, GoldenError::Missing { .. }), "{err}");
    assert!(err.to_string().contains("RICOCHET_BLESS=1"), "{err}");
    // Blessing creates the directory.
    let nested = dir.path().join("levels/one.mcap");
    let mut sim = Simulation::new(&level().unwrap());
    golden::check_or_bless(&nested, &mut sim, FRAMES, true).unwrap();
    assert!(nested.exists());
}

/// Issue #35: a check before the first bless, with no golden folder yet, is the same "no
/// golden log yet" as with the folder, not an I/O error; the check creates no folder, and
/// this run's log is kept where the message says.
#[test]
fn a_missing_golden_folder_says_how_to_record_it_and_creates_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("golden");
    let golden = folder.join("newcomer.mcap");
    let mut sim = Simulation::new(&level().unwrap());
    let err = golden::check_or_bless(&golden, &mut sim, FRAMES, false).unwrap_err();
    let GoldenError::Missing { golden: named, new } = &err else {
        panic!("not the missing-golden message: {err}");
    };
    assert_eq!(named, &golden);
    let text = err.to_string();
    assert!(text.contains("no golden log yet"), "{text}");
    assert!(text.contains("RICOCHET_BLESS=1"), "{text}");
    assert!(text.contains(&new.display().to_string()), "{text}");
    assert!(!folder.exists(), "a check creates no golden folder");
    // The run's log is whole: it reads back with a /bodies message per frame.
    let log = ricochet_log::read_log_file(new).unwrap();
    let frames = log.iter().filter(|m| m.topic == "/bodies").count() as u64;
    assert_eq!(frames, FRAMES + 1);
    std::fs::remove_dir_all(new.parent().unwrap()).unwrap();
    // Blessing then creates the folder, and the next check passes.
    let mut sim = Simulation::new(&level().unwrap());
    golden::check_or_bless(&golden, &mut sim, FRAMES, true).unwrap();
    let mut sim = Simulation::new(&level().unwrap());
    golden::check_or_bless(&golden, &mut sim, FRAMES, false).unwrap();
}

/// Issue #35: a body that diverges between keyframes (whose `/bodies` entry lists no name)
/// is still named `id:generation (name)` in the report, as `ricochet diff` and `ricochet
/// test` name it.
#[test]
fn a_divergence_between_keyframes_names_the_body() {
    // A kick at frame 30 (keyframes are frames 0, 60, 120): the ball's entry that frame is a
    // delta, with its new velocity and no name.
    const AT: u64 = 30;
    let kicked = |velocity: Vec2| {
        let mut s = level().unwrap();
        s.script = vec![ricochet_sim::Event {
            frame: AT,
            ..kick(velocity)
        }];
        s
    };
    let scene = kicked(KICK);
    // A fresh simulation gives the scene's bodies slots in order, generation 0.
    let slot = scene.bodies.iter().position(|b| b.name == "ball").unwrap();
    let expected = format!("{slot}:0 (ball)");

    let dir = tempfile::tempdir().unwrap();
    let golden = dir.path().join("kicked.mcap");
    golden::check_or_bless(&golden, &mut Simulation::new(&scene), FRAMES, true).unwrap();
    let heavier = kicked(Vec2::new(KICK.x, KICK.y.next_up()));
    let err =
        golden::check_or_bless(&golden, &mut Simulation::new(&heavier), FRAMES, false).unwrap_err();
    let GoldenError::Differs { first, report, .. } = &err else {
        panic!("not a divergence: {err}");
    };
    assert_eq!(first.frame, Some(AT), "{report}");
    assert_eq!(first.body.as_deref(), Some(expected.as_str()), "{report}");
    assert!(report.contains(&format!(", body {expected}\n")), "{report}");
}

/// `golden::check(..).unwrap()` in a game's test (the crate doc's own example) and `?` out of
/// a test or `main` print the error with `{:?}`: that is the message, with the report's
/// lines as lines, not the enum's fields with `\n` escapes.
#[test]
fn unwrap_prints_the_message_and_the_report() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("golden/level1.mcap");
    let mut sim = Simulation::new(&level().unwrap());
    let err = golden::check_or_bless(&missing, &mut sim, FRAMES, false).unwrap_err();
    assert_eq!(format!("{err:?}"), err.to_string());
    assert!(format!("{err:?}").contains("RICOCHET_BLESS=1"), "{err:?}");
    if let GoldenError::Missing { new, .. } = &err {
        std::fs::remove_dir_all(new.parent().unwrap()).unwrap();
    }

    let golden = golden_copy(dir.path());
    let mut sim = Simulation::new(&one_ulp_heavier());
    let err = golden::check_or_bless(&golden, &mut sim, FRAMES, false).unwrap_err();
    let shown = format!("{err:?}");
    assert_eq!(shown, err.to_string());
    assert!(
        shown
            .lines()
            .any(|l| l.starts_with("first difference: frame 60 ")),
        "{shown}"
    );
}
