//! `ricochet accuracy`: the measured errors agree with what the integrator and the swept
//! tests promise. Runs the study through the library ([`ricochet_study::accuracy`]) once,
//! and the command once to check that it writes what the library measures. No wall time is
//! asserted.

use std::sync::OnceLock;

use ricochet_study::accuracy::{Row, Study, chart, measure, report};

use crate::util::{ricochet, root};

/// Gravity in the accuracy scenes, units/s².
const G: f64 = ricochet_scenes::accuracy::G;
/// The projectile is compared at t = 2 s.
const T: f64 = ricochet_scenes::accuracy::PROJECTILE_T;

/// One run of the study, shared by the tests below (deterministic apart from wall times).
fn study() -> &'static Study {
    static STUDY: OnceLock<Study> = OnceLock::new();
    STUDY.get_or_init(|| {
        let study = measure(|_| {}).unwrap_or_else(|e| panic!("the accuracy study failed: {e:#}"));
        for (pass, what) in report::checks(&study.rows, study.script_matches) {
            assert!(pass, "FAIL {what}");
        }
        let svg = chart::svg_text(&study.rows);
        assert!(svg.starts_with("<svg ") && svg.trim_end().ends_with("</svg>"));
        assert!(svg.contains("<polyline"), "the chart has lines");
        study
    })
}

fn rows() -> &'static [Row] {
    &study().rows
}

/// A CSV without its last column (the wall time, which differs from run to run).
fn without_wall(csv: &str) -> Vec<String> {
    csv.lines()
        .map(|l| l.rsplit_once(',').map_or(l, |(head, _)| head).to_owned())
        .collect()
}

fn select<'a>(scene: &str, method: &str, kind: &str) -> Vec<&'a Row> {
    let found: Vec<&Row> = rows()
        .iter()
        .filter(|r| r.scene == scene && r.method == method && r.kind == kind)
        .collect();
    assert!(!found.is_empty(), "no rows for {scene} {method} {kind}");
    found
}

#[test]
fn projectile_error_halves_when_dt_halves_first_order() {
    let rows = select("projectile", "euler", "position");
    let dts: Vec<f64> = rows.iter().map(|r| r.dt()).collect();
    let expected = [30.0, 60.0, 120.0, 240.0, 480.0, 960.0].map(|hz| 1.0 / hz);
    assert_eq!(dts.len(), expected.len());
    for (dt, want) in dts.iter().zip(expected) {
        assert!((dt - want).abs() < 1e-15, "dt {dt}, expected {want}");
    }
    for w in rows.windows(2) {
        let ratio = w[0].error / w[1].error;
        assert!(
            (1.9..=2.1).contains(&ratio),
            "error({}) / error({}) = {ratio}, expected 2 within 5%",
            w[0].dt(),
            w[1].dt()
        );
    }
    // Semi-implicit Euler is x_n - x(t_n) = n g dt²/2 exactly, so at t = 2 s: g t dt / 2.
    for r in &rows {
        let theory = G * T * r.dt() / 2.0;
        assert!(
            (r.error - theory).abs() <= 1e-9 * theory,
            "dt {}: error {}, theory g t dt / 2 = {theory}",
            r.dt(),
            r.error
        );
    }
    // And the simulation is that recurrence, up to rounding.
    for r in select("projectile", "euler", "vs_recurrence") {
        assert!(
            r.error < 1e-9,
            "dt {}: {} from the recurrence",
            r.dt(),
            r.error
        );
    }
}

#[test]
fn projectile_substeps_are_smaller_steps() {
    let rows = select("projectile", "euler+substeps", "position");
    assert_eq!(
        rows.iter().map(|r| r.substeps).collect::<Vec<_>>(),
        [1, 2, 4]
    );
    for w in rows.windows(2) {
        let ratio = w[0].error / w[1].error;
        assert!((1.9..=2.1).contains(&ratio), "substep ratio {ratio}");
    }
}

#[test]
fn drop_lands_on_the_exact_frame_and_rests_flush() {
    for method in ["euler", "euler+substeps"] {
        for r in select("drop", method, "landing_frame") {
            assert_eq!(
                r.error,
                0.0,
                "{method} dt {} x {}: landing frame off",
                r.dt(),
                r.substeps
            );
        }
        for r in select("drop", method, "rest_height") {
            assert!(
                r.error <= ricochet_sim::SLOP,
                "{method} dt {} x {}: rest height off by {}",
                r.dt(),
                r.substeps,
                r.error
            );
        }
    }
}

#[test]
fn swept_bullets_hit_exactly_the_first_rock_and_discrete_ones_do_not() {
    for method in ["swept", "swept+substeps"] {
        for r in select("bullets", method, "wrong_first_hits") {
            assert_eq!(r.error, 0.0, "{method} dt {} x {}", r.dt(), r.substeps);
        }
    }
    // The measure is not vacuous: at 1/30 s, 10 units per frame, discrete tests go wrong.
    let coarse = &select("bullets", "discrete", "wrong_first_hits")[0];
    assert!(coarse.dt() > 0.03 && coarse.error > 0.0, "{coarse:?}");
}

#[test]
fn state_force_orbit_keeps_its_energy_and_prescribed_one_drifts() {
    // Semi-implicit Euler is symplectic: with the force taken from the state, the orbit's
    // energy error is bounded and small; forced from outside, it is not.
    let state = select("orbit", "state", "energy");
    let prescribed = select("orbit", "prescribed", "energy");
    for (s, p) in state.iter().zip(&prescribed) {
        assert!(s.error < 1e-3 && s.error < p.error, "{s:?} {p:?}");
    }
}

#[test]
fn docs_csv_has_the_errors_this_build_measures() {
    let docs = std::fs::read_to_string(root().join("docs").join("accuracy.csv"))
        .expect("docs/accuracy.csv exists");
    let regenerate = "regenerate: cargo run --release -- accuracy --csv docs/accuracy.csv \
                      --svg docs/accuracy.svg";
    // Errors are deterministic (libm, no FMA): the same bits on every machine and build.
    assert_eq!(
        without_wall(&docs),
        without_wall(&report::csv_text(rows())),
        "{regenerate}"
    );
}

/// The command prints the checks and writes the CSV and the chart of the same study.
#[test]
fn the_command_writes_what_the_library_measures() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("accuracy.csv");
    let svg = dir.path().join("accuracy.svg");
    let o = ricochet(
        &[
            "accuracy",
            "--csv",
            csv.to_str().unwrap(),
            "--svg",
            svg.to_str().unwrap(),
        ],
        b"",
    );
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{:?}\n{stdout}", o.status);
    assert!(
        stdout.contains("checks:") && !stdout.contains("FAIL"),
        "{stdout}"
    );
    let written = std::fs::read_to_string(csv).unwrap();
    assert_eq!(
        without_wall(&written),
        without_wall(&report::csv_text(rows()))
    );
    assert!(std::fs::read_to_string(svg).unwrap().contains("<polyline"));
}
