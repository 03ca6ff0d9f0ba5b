//! What the fuzz targets check, as plain functions.
//!
//! This file is compiled twice: by the fuzz crate (`fuzz/`, for `cargo fuzz`), and by the
//! integration tests (`tests/fuzz_corpus.rs` includes it with `#[path]`), which replay the
//! committed corpus through the same functions. So it may use nothing but `std`,
//! `ricochet_geom`, `ricochet_sim` and `ricochet_log`, and each function panics only when the
//! library is wrong.

use ricochet_geom::{Case, Primitive, contact, overlaps, parse_case_file};
use ricochet_log::{LogError, LogFile, read_log};
use ricochet_sim::{Scenario, Simulation, load_scenario};

/// The file name passed to the scenario loader (it only appears in error messages).
pub const SCENARIO_FILE: &str = "fuzz.toml";

/// At most this many frames are stepped per scenario.
pub const MAX_STEPS: u64 = 50;

/// A scenario with more bodies, script events or split children than this is only loaded,
/// not stepped: it would slow every execution down without reaching new code.
pub const MAX_ITEMS: usize = 200;

/// Stepping stops once the world holds more bodies than this. A template that splits into
/// copies of itself (directly or through other templates) multiplies its bodies every frame
/// they collide, so a few lines can ask for millions of bodies within 20 frames: legal input
/// (see `fuzz/README.md`), but no use to the fuzzer.
pub const MAX_LIVE_BODIES: usize = 256;

/// Loads `text` as a scenario: it must give a scenario or an error, never a panic. An error
/// must display as `fuzz.toml:LINE:COLUMN: ...`. A scenario that loads (and is small enough)
/// is simulated for up to [`MAX_STEPS`] frames, which must not panic either.
pub fn scenario(text: &str) {
    let scenario = match load_scenario(text, SCENARIO_FILE) {
        Ok(s) => s,
        Err(e) => {
            assert!(
                e.line >= 1 && e.column >= 1,
                "error location is 1-based: {e:?}"
            );
            let message = e.to_string();
            assert!(
                message.starts_with(&format!("{SCENARIO_FILE}:{}:{}:", e.line, e.column)),
                "error message starts with its location: {message}"
            );
            return;
        }
    };
    if !small_enough(&scenario) {
        return;
    }
    let mut sim = Simulation::new(&scenario);
    // Frame 0 (the initial state) always runs; then up to MAX_STEPS frames of motion.
    let steps = scenario.frames.clamp(1, MAX_STEPS);
    for _ in 0..steps {
        let out = sim.step();
        assert_eq!(out.stats.bodies, sim.world().len(), "frame {}", out.frame);
        if sim.world().len() > MAX_LIVE_BODIES {
            break;
        }
    }
}

/// Whether a loaded scenario is cheap enough to step (see [`MAX_ITEMS`]).
fn small_enough(s: &Scenario) -> bool {
    let children: usize = s
        .templates
        .values()
        .chain(&s.bodies)
        .map(|b| b.split.len())
        .sum();
    s.bodies.len() <= MAX_ITEMS && s.script.len() <= MAX_ITEMS && children <= MAX_ITEMS
}

/// Reads `text` as `ricochet collide` input: it must give cases or errors, never a panic (and
/// at least one error when it fails). Every case is then collided with [`case`].
pub fn collide(text: &str) {
    match parse_case_file(text) {
        Ok(cases) => {
            for c in &cases {
                case(c);
            }
        }
        Err(errors) => {
            assert!(
                !errors.is_empty(),
                "a failed parse names at least one error"
            );
            for e in &errors {
                let _ = e.to_string();
                // An unknown key is named by its path (`tolerance`, `a.angel`, `b.shape`).
                if e.problem.starts_with("unknown field") {
                    assert!(!e.field.is_empty(), "an unknown key names its field: {e}");
                }
            }
        }
    }
}

/// Below this magnitude (and above [`HUGE`]) the narrow phase is not expected to be sound:
/// squared (and, for two capsules, fourth-power) lengths underflow or overflow, and contacts
/// come out with `inf` or NaN parts, zero normals, or an [`overlaps`] answer that disagrees
/// with [`contact`]. Random cases were sound from about `1e-80` to `1e75`; these bounds keep
/// a margin. See "Magnitudes" in `fuzz/README.md`.
pub const TINY: f64 = 1e-60;

/// See [`TINY`].
pub const HUGE: f64 = 1e60;

/// Collides one case as `ricochet collide` does, and runs the cheap [`overlaps`] test too.
/// Neither may panic, whatever the numbers. When every number of the case (coordinates, sizes,
/// angles) is zero or between [`TINY`] and [`HUGE`] in magnitude, the contact must also be
/// sound: finite, with a unit normal, and [`overlaps`] must agree with it except within
/// rounding of a touching pair.
pub fn case(case: &Case) {
    let (a, b) = (&case.a, &case.b);
    let c = contact(&a.shape, &a.pose, &b.shape, &b.pose);
    let hit = overlaps(&a.shape, &a.pose, &b.shape, &b.pose);
    let Some(scale) = moderate_scale(case) else {
        return;
    };
    let id = &case.id;
    assert!(
        c.depth.is_finite() && c.normal.is_finite() && c.point.is_finite(),
        "case {id}: not finite: {c:?} (a: {a:?}, b: {b:?})"
    );
    assert!(
        (c.normal.length() - 1.0).abs() < 1e-9,
        "case {id}: normal is not a unit vector: {c:?} (a: {a:?}, b: {b:?})"
    );
    assert!(
        hit == c.overlaps() || c.depth.abs() <= 1e-9 * scale,
        "case {id}: overlaps() says {hit} but contact() says {c:?} (a: {a:?}, b: {b:?})"
    );
}

/// The largest magnitude among the case's coordinates and sizes, when every number of the case
/// is zero or between [`TINY`] and [`HUGE`] in magnitude.
fn moderate_scale(case: &Case) -> Option<f64> {
    let mut numbers = Vec::new();
    let mut angles = Vec::new();
    for body in [&case.a, &case.b] {
        numbers.extend([body.pose.position.x, body.pose.position.y]);
        angles.push(body.pose.angle);
        for p in body.shape.primitives() {
            match p {
                Primitive::Circle(c) => numbers.extend([c.center.x, c.center.y, c.radius]),
                Primitive::Aabb(b) => {
                    numbers.extend([b.center.x, b.center.y, b.half_extents.x, b.half_extents.y])
                }
                Primitive::Obb(b) => {
                    numbers.extend([b.center.x, b.center.y, b.half_extents.x, b.half_extents.y]);
                    angles.push(b.angle);
                }
                Primitive::Capsule(c) => numbers.extend([c.a.x, c.a.y, c.b.x, c.b.y, c.radius]),
                Primitive::Polygon(p) => {
                    numbers.extend(p.vertices().iter().flat_map(|v| [v.x, v.y]))
                }
                Primitive::Segment(s) => numbers.extend([s.a.x, s.a.y, s.b.x, s.b.y]),
            }
        }
    }
    let moderate = |x: &f64| *x == 0.0 || (TINY..=HUGE).contains(&x.abs());
    (numbers.iter().all(moderate) && angles.iter().all(moderate))
        .then(|| numbers.iter().fold(0.0, |m: f64, x| m.max(x.abs())))
}

/// Reads `bytes` as a log, as `ricochet diff` does: from memory ([`read_log`]) and streamed
/// from a file ([`LogFile`], checking the summary's CRC on open), which must give messages or
/// a truncated or corrupt error, never a panic; when both read it, they read the same messages.
pub fn log(bytes: &[u8]) {
    let in_memory = read_log(bytes);
    if let Err(e) = &in_memory {
        assert!(
            matches!(e, LogError::Truncated { .. } | LogError::Corrupt { .. }),
            "{e:?}"
        );
    }
    let path = std::env::temp_dir().join(format!("ricochet-fuzz-log-{}.mcap", std::process::id()));
    if std::fs::write(&path, bytes).is_err() {
        return;
    }
    let streamed = LogFile::open(&path).and_then(|log| {
        let _ = (log.library(), log.channels().count(), log.message_count());
        log.messages()?.collect::<Result<Vec<_>, _>>()
    });
    let _ = std::fs::remove_file(&path);
    match (&in_memory, &streamed) {
        (Ok(a), Ok(b)) => assert_eq!(a, b, "the two readers read different messages"),
        (_, Err(e)) => assert!(
            matches!(e, LogError::Truncated { .. } | LogError::Corrupt { .. }),
            "{e:?}"
        ),
        (Err(_), Ok(_)) => {}
    }
}
