//! `ricochet accuracy`: the measured errors agree with what the integrator and the swept
//! tests promise. Runs the real command and reads its CSV. No wall time is asserted: the
//! timing column is only parsed.

use std::sync::OnceLock;

use crate::util::{ricochet, root};

const HEADER: &str = "scene,method,dt,substeps,error_kind,error,wall_s_per_sim_s";

/// Gravity in the accuracy scenes, units/s².
const G: f64 = 9.81;
/// The projectile is compared at t = 2 s.
const T: f64 = 2.0;

#[derive(Clone, Debug, PartialEq)]
struct Row {
    scene: String,
    method: String,
    dt: f64,
    substeps: u32,
    kind: String,
    error: f64,
}

fn parse(csv: &str) -> Vec<Row> {
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some(HEADER), "the CSV header");
    lines
        .map(|line| {
            let f: Vec<&str> = line.split(',').collect();
            assert_eq!(f.len(), 7, "seven fields: {line}");
            let wall: f64 = f[6]
                .parse()
                .unwrap_or_else(|e| panic!("{line}: wall time: {e}"));
            assert!(!wall.is_nan(), "{line}: the wall time is a number");
            Row {
                scene: f[0].to_owned(),
                method: f[1].to_owned(),
                dt: f[2].parse().unwrap_or_else(|e| panic!("{line}: dt: {e}")),
                substeps: f[3]
                    .parse()
                    .unwrap_or_else(|e| panic!("{line}: substeps: {e}")),
                kind: f[4].to_owned(),
                error: f[5]
                    .parse()
                    .unwrap_or_else(|e| panic!("{line}: error: {e}")),
            }
        })
        .collect()
}

/// The CSV of one `ricochet accuracy` run, shared by the tests below (it is deterministic
/// apart from the timing column).
fn rows() -> &'static [Row] {
    static ROWS: OnceLock<Vec<Row>> = OnceLock::new();
    ROWS.get_or_init(|| {
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
        assert!(
            o.status.success(),
            "ricochet accuracy failed ({:?}):\n{stdout}\n{}",
            o.status,
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(!stdout.contains("FAIL"), "{stdout}");
        let svg = std::fs::read_to_string(svg).unwrap();
        assert!(svg.starts_with("<svg ") && svg.trim_end().ends_with("</svg>"));
        assert!(svg.contains("<polyline"), "the chart has lines");
        parse(&std::fs::read_to_string(csv).unwrap())
    })
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
    let dts: Vec<f64> = rows.iter().map(|r| r.dt).collect();
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
            w[0].dt,
            w[1].dt
        );
    }
    // Semi-implicit Euler is x_n - x(t_n) = n g dt²/2 exactly, so at t = 2 s: g t dt / 2.
    for r in &rows {
        let theory = G * T * r.dt / 2.0;
        assert!(
            (r.error - theory).abs() <= 1e-9 * theory,
            "dt {}: error {}, theory g t dt / 2 = {theory}",
            r.dt,
            r.error
        );
    }
    // And the simulation is that recurrence, up to rounding.
    for r in select("projectile", "euler", "vs_recurrence") {
        assert!(
            r.error < 1e-9,
            "dt {}: {} from the recurrence",
            r.dt,
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
                r.error, 0.0,
                "{method} dt {} x {}: landing frame off",
                r.dt, r.substeps
            );
        }
        for r in select("drop", method, "rest_height") {
            assert!(
                r.error <= ricochet_sim::SLOP,
                "{method} dt {} x {}: rest height off by {}",
                r.dt,
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
            assert_eq!(r.error, 0.0, "{method} dt {} x {}", r.dt, r.substeps);
        }
    }
    // The measure is not vacuous: at 1/30 s, 10 units per frame, discrete tests go wrong.
    let coarse = &select("bullets", "discrete", "wrong_first_hits")[0];
    assert!(coarse.dt > 0.03 && coarse.error > 0.0, "{coarse:?}");
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
    let docs = parse(&docs);
    let regenerate = "regenerate: cargo run --release -- accuracy --csv docs/accuracy.csv \
                      --svg docs/accuracy.svg";
    assert_eq!(docs.len(), rows().len(), "{regenerate}");
    for (d, r) in docs.iter().zip(rows()) {
        // Errors are deterministic (libm, no FMA): the same bits on every machine and build.
        assert_eq!(d, r, "{regenerate}");
    }
}
