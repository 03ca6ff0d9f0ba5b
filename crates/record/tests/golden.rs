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
    let golden = dir.path().join("levels/none.mcap");
    let mut sim = Simulation::new(&level().unwrap());
    let err = golden::check_or_bless(&golden, &mut sim, FRAMES, false);
    // The directory does not exist: the new log can't be written there either.
    assert!(err.is_err());
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
