//! Issue #20's limits on what a scenario may hold, through the real binary: no logged value
//! is non-finite, and the wrap world's size rule is exactly "half the world".

use crate::util::ricochet;

/// Writes `text` as a scenario in a fresh directory; returns the directory (kept alive by
/// the caller) and the scenario's path.
fn scenario(text: &str) -> (tempfile::TempDir, String) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("s.toml");
    std::fs::write(&path, text).unwrap();
    let path = path.to_str().unwrap().to_owned();
    (dir, path)
}

/// Issue #20: `mass = 1e300` made `/stats.kinetic_energy` Infinity with exit 0. A mass is
/// bounded now, but a velocity past 1e146 is still finite while `m v² / 2` of the heaviest
/// mass is not: the run stops there as for any overflow, with a complete log of the frames
/// before, and no logged kinetic energy is non-finite.
///
/// Exact math: `v_k = 1e146 + k * (1e162 / 1e15) / 60`, and `0.5 * 1e15 * v_k²` passes
/// `f64::MAX` (1.797e308) at `v_k > 5.996e146`, that is `k > 29.98`: frame 30 overflows, the
/// log holds frames 0 to 29 (rounding moves `k` by far less than the 0.02 margin).
#[test]
fn a_kinetic_energy_past_f64_stops_the_run_with_the_frames_before() {
    let (dir, path) = scenario(
        "frames = 60\nlayers = [\"rock\"]\n[[bodies]]\nname = \"heavy\"\nlayer = \"rock\"\n\
         shape = { kind = \"circle\", radius = 1 }\nmass = 1e15\nvelocity = [1e146, 0]\n\
         force = [1e162, 0]\n",
    );
    let log = dir.path().join("s.mcap");
    let log = log.to_str().unwrap();
    let o = ricochet(&["run", &path, "-o", log], b"");
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("frame 30: body heavy #0:0 has a non-finite kinetic_energy"),
        "{stderr}"
    );
    assert!(stderr.contains("holds frames 0 to 29"), "{stderr}");
    let dump = ricochet(&["dump", log, "--topic", "/stats"], b"");
    assert_eq!(dump.status.code(), Some(0));
    let mut frames = 0;
    for line in String::from_utf8(dump.stdout).unwrap().lines() {
        let v: serde_json::Value = serde_json::from_str(line).unwrap();
        let ke = &v["data"]["kinetic_energy"];
        // The JSON form of a non-finite double is a string ("Infinity").
        let ke = ke
            .as_f64()
            .unwrap_or_else(|| panic!("not a finite number: {line}"));
        assert!(ke.is_finite() && ke > 0.0, "{line}");
        frames += 1;
    }
    assert_eq!(frames, 30, "frames 0 to 29 logged");
}

/// The wrap world's rule is "reach at most half the world from the position": a circle of
/// radius 5 in a 10 x 10 wrap world is accepted, one a millionth larger is not; a box
/// that does not turn is measured per axis (a 10 x 1 AABB fits), one that turns by its
/// corners (a 10 x 1 OBB reaches sqrt(5² + 0.5²) > 5 at some angle, and does not).
#[test]
fn a_body_may_reach_exactly_half_a_wrap_world() {
    let world = "frames = 1\nlayers = [\"rock\"]\n[world]\n\
                 bounds = { min = [0, 0], max = [10, 10], wrap = true }\n[[bodies]]\n\
                 layer = \"rock\"\nposition = [5, 5]\n";
    for (shape, ok) in [
        ("{ kind = \"circle\", radius = 5 }", true),
        ("{ kind = \"circle\", radius = 5.000001 }", false),
        ("{ kind = \"aabb\", half_extents = [5, 0.5] }", true),
        ("{ kind = \"obb\", half_extents = [5, 0.5] }", false),
        (
            "{ kind = \"circle\", radius = 1, center = [4.5, 0] }",
            false,
        ),
    ] {
        let (_dir, path) = scenario(&format!("{world}shape = {shape}\n"));
        let o = ricochet(&["check", &path], b"");
        let stderr = String::from_utf8_lossy(&o.stderr);
        let want = if ok { 0 } else { 2 };
        assert_eq!(o.status.code(), Some(want), "{shape}: {stderr}");
        if !ok {
            assert!(stderr.contains("bodies[0].shape"), "{stderr}");
            assert!(stderr.contains("wrap-around world"), "{stderr}");
        }
    }
}
