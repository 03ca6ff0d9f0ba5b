//! `ricochet run`: the log it writes, for every scenario in `scenarios/`.

use std::collections::BTreeMap;
use std::path::Path;

use ricochet_geom::pairs::collide_cores;
use ricochet_geom::{Pose, Shape, Vec2, place};
use ricochet_log::{LogMessage, read_log, read_log_file};
use ricochet_sim::{Response, SLOP, load_scenario};
use serde_json::Value;

use crate::util::{full_bodies, record, ricochet, root, scenarios, shape_def};

/// Runs `ricochet run SCENARIO -o DIR/OUT` and returns OUT's bytes.
fn run(scenario: &Path, dir: &Path, out: &str) -> Vec<u8> {
    let out = dir.join(out);
    record(scenario, &out);
    std::fs::read(out).unwrap()
}

fn topic<'a>(log: &'a [LogMessage], name: &'a str) -> impl Iterator<Item = &'a LogMessage> {
    log.iter().filter(move |m| m.topic == name)
}

#[test]
fn run_with_no_arguments_writes_the_asteroids_demo_with_seven_decodable_channels() {
    let dir = tempfile::tempdir().unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_ricochet"))
        .arg("run")
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let summary = String::from_utf8_lossy(&out.stderr);
    assert!(
        summary.contains("frames/s") && summary.contains("asteroids.mcap"),
        "{summary}"
    );
    let log = read_log_file(&dir.path().join("asteroids.mcap")).expect("a valid, complete log");
    let mut topics: Vec<&str> = log.iter().map(|m| m.topic.as_str()).collect();
    topics.sort_unstable();
    topics.dedup();
    assert_eq!(
        topics,
        [
            "/bodies",
            "/contacts",
            "/events",
            "/scene",
            "/scene/contacts",
            "/scene/static",
            "/stats",
            "/tf"
        ]
    );
    // Every message decoded (read_log_file decodes each with the schema the log embeds);
    // the schemas are the official Foxglove ones and Ricochet's own.
    for (name, schema) in [
        ("/scene", "foxglove.SceneUpdate"),
        ("/scene/contacts", "foxglove.SceneUpdate"),
        ("/scene/static", "foxglove.SceneUpdate"),
        ("/tf", "foxglove.FrameTransforms"),
        ("/events", "foxglove.Log"),
        ("/bodies", "ricochet.Bodies"),
        ("/contacts", "ricochet.Contacts"),
        ("/stats", "ricochet.Stats"),
    ] {
        assert!(
            topic(&log, name).all(|m| m.schema_name == schema),
            "{name} is {schema}"
        );
    }
    // One /bodies, /contacts and /stats message per frame, at frame * dt; /scene (whole) in
    // every frame a moving body moves (the asteroids always drift), /scene/static once (it
    // has no static body: the one message is empty).
    let frames = topic(&log, "/stats").count();
    for name in ["/bodies", "/contacts", "/scene"] {
        assert_eq!(topic(&log, name).count(), frames, "{name}");
    }
    let statics: Vec<_> = topic(&log, "/scene/static").collect();
    assert_eq!(statics.len(), 1, "/scene/static once");
    assert_eq!(statics[0].log_time, 0);
    // /tf: the camera's frame alone, sent when it moves: the demo has no focus body, so the
    // camera looks at the centre of the world's bounds, from frame 0 on.
    let tf: Vec<_> = topic(&log, "/tf").collect();
    assert_eq!(tf.len(), 1, "/tf once");
    let transforms = tf[0].data["transforms"].as_array().unwrap();
    assert_eq!(transforms.len(), 1);
    assert_eq!(transforms[0]["child_frame_id"], "view");
    for (k, m) in topic(&log, "/bodies").enumerate() {
        assert_eq!(m.data["frame"], k as u64);
        assert_eq!(
            m.log_time,
            k as u64 * 16_666_667,
            "frame * round(1e9 / 60) ns"
        );
        assert_eq!(m.publish_time, m.log_time);
    }
}

#[test]
fn every_scenario_gives_identical_bytes_twice() {
    let dir = tempfile::tempdir().unwrap();
    for s in scenarios() {
        let first = run(&s, dir.path(), "first.mcap");
        let second = run(&s, dir.path(), "second.mcap");
        assert!(first == second, "{} is not deterministic", s.display());
    }
}

#[test]
fn the_writer_thread_and_inline_encoding_write_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["asteroids", "shapes"] {
        let scenario = root().join(format!("scenarios/{name}.toml"));
        let threaded = run(&scenario, dir.path(), "threaded.mcap");
        let inline_out = dir.path().join("inline.mcap");
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_ricochet"))
            .args(["run", scenario.to_str().unwrap(), "-o"])
            .arg(&inline_out)
            .env("RICOCHET_INLINE_WRITER", "1")
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let inline = std::fs::read(&inline_out).unwrap();
        assert!(
            threaded.len() > 10_000 && threaded == inline,
            "{name}: {} bytes threaded, {} inline",
            threaded.len(),
            inline.len()
        );
    }
}

/// Shapes by body id, from a /bodies message's bodies and removed bodies.
fn shapes(msg: &Value) -> Vec<(u64, Shape)> {
    let mut out = Vec::new();
    for key in ["removed", "bodies"] {
        for b in msg[key].as_array().unwrap() {
            out.push((
                b["id"].as_u64().unwrap(),
                shape_def(&b["shape"]).to_shape().unwrap(),
            ));
        }
    }
    out
}

fn pose(v: &Value) -> Pose {
    Pose::new(
        Vec2::new(v[0].as_f64().unwrap(), v[1].as_f64().unwrap()),
        v[2].as_f64().unwrap(),
    )
}

/// The contact of two shapes by the general core algorithm, part by part, deepest first:
/// a different code path from the pair functions the simulation calls.
fn recompute(a: &Shape, pa: &Pose, b: &Shape, pb: &Pose) -> (f64, Vec2) {
    let mut best = (f64::NEG_INFINITY, Vec2::ZERO);
    for x in a.primitives() {
        for y in b.primitives() {
            let c = collide_cores(
                &place(x, pa, pa.position).core(),
                &place(y, pb, pa.position).core(),
            );
            if c.depth > best.0 {
                best = (c.depth, c.normal);
            }
        }
    }
    best
}

#[test]
fn every_logged_contact_is_the_exact_contact_at_its_logged_poses() {
    let dir = tempfile::tempdir().unwrap();
    let mut checked = 0;
    for s in scenarios() {
        let log = read_log(&run(&s, dir.path(), "run.mcap")).unwrap();
        let bodies = full_bodies(&log);
        for (frame, m) in topic(&log, "/contacts").enumerate() {
            let known = shapes(&bodies[frame]);
            for c in m.data["contacts"].as_array().unwrap() {
                let (ia, ib) = (c["a"].as_u64().unwrap(), c["b"].as_u64().unwrap());
                assert!(ia < ib, "pairs are ordered a < b: {c}");
                let (pa, pb) = (pose(&c["pose_a"]), pose(&c["pose_b"]));
                let depth = c["depth"].as_f64().unwrap();
                let normal = Vec2::new(
                    c["normal"][0].as_f64().unwrap(),
                    c["normal"][1].as_f64().unwrap(),
                );
                // An id reused within the frame has two candidate shapes: one must match.
                let candidates = |id| known.iter().filter(move |(k, _)| *k == id).map(|(_, s)| s);
                // A one-way landing is not a narrow-phase contact: its depth is the platform's
                // top less the body's bottom (bounding boxes), straight up, and the body may
                // have moved along x past that platform's edge since the bottom crossed its
                // top (scenarios/README.md, "One-way platforms").
                let one_way = c["response"] == "one_way";
                let ok = candidates(ia).any(|sa| {
                    candidates(ib).any(|sb| {
                        let (d, n) = if one_way {
                            (
                                sa.bounds(&pa).max.y - sb.bounds(&pb).min.y,
                                Vec2::new(0.0, 1.0),
                            )
                        } else {
                            recompute(sa, &pa, sb, &pb)
                        };
                        let size = sa
                            .bounds(&pa)
                            .half_extents()
                            .length()
                            .min(sb.bounds(&pb).half_extents().length());
                        let tol = 1e-9 * size.max(1.0);
                        (d - depth).abs() <= tol && (n.dot(normal) > 1.0 - 1e-9 || d <= tol)
                    })
                });
                assert!(
                    ok,
                    "{}: frame {frame}: contact {c} does not match its poses",
                    s.display()
                );
                // A swept contact is logged at the moment of first touch: depth about zero. So
                // is a per-axis stop at the first box a fast box's sweep met (it is placed
                // flush: depth 0, and its `resolved` is the stop).
                let touch = match c["phase"].as_str() {
                    Some("swept") => depth > -1e-6,
                    Some("x" | "y") => {
                        depth >= -1e-9 && c["resolved"] != serde_json::json!([0.0, 0.0])
                    }
                    _ => false,
                };
                assert!(depth > 0.0 || touch, "{c}");
                checked += 1;
            }
        }
    }
    assert!(checked > 50, "the scenarios produce contacts: {checked}");
}

#[test]
fn asteroids_never_tests_an_asteroid_against_an_asteroid_and_stats_show_it() {
    let dir = tempfile::tempdir().unwrap();
    let log = read_log(&run(
        &root().join("scenarios/asteroids.toml"),
        dir.path(),
        "a.mcap",
    ))
    .unwrap();
    let mut tested: BTreeMap<String, u64> = BTreeMap::new();
    for m in topic(&log, "/stats") {
        // asteroid/asteroid is a layer combination present in every frame that the broad
        // phase never looks at (with at least two asteroids and a bullet or the ship).
        if m.data["broad_phase"] != "" {
            assert!(
                m.data["layer_pairs_skipped"].as_u64().unwrap() >= 1,
                "{}",
                m.data
            );
        }
        for (k, v) in m.data["tests_by_layer_pair"].as_object().unwrap() {
            *tested.entry(k.clone()).or_default() += v.as_u64().unwrap();
        }
    }
    assert!(!tested.contains_key("asteroid/asteroid"), "{tested:?}");
    assert!(
        tested.get("asteroid/bullet").copied().unwrap_or(0) > 0,
        "{tested:?}"
    );
    // And no logged contact is between two asteroids.
    for m in topic(&log, "/contacts") {
        assert!(
            m.data["contacts"]
                .as_array()
                .unwrap()
                .iter()
                .all(|c| c["response"] != "ignore")
        );
    }
}

#[test]
fn platformer_never_ends_a_frame_with_solids_overlapping_beyond_slop() {
    let path = root().join("scenarios/platformer.toml");
    let scenario =
        load_scenario(&std::fs::read_to_string(&path).unwrap(), "platformer.toml").unwrap();
    let layers = &scenario.world.layers;
    let dir = tempfile::tempdir().unwrap();
    let log = read_log(&run(&path, dir.path(), "p.mcap")).unwrap();
    let mut pairs = 0;
    for m in full_bodies(&log) {
        let bodies = m["bodies"].as_array().unwrap();
        for (i, a) in bodies.iter().enumerate() {
            for b in &bodies[i + 1..] {
                let (la, lb) = (
                    layers.id(a["layer"].as_str().unwrap()).unwrap(),
                    layers.id(b["layer"].as_str().unwrap()).unwrap(),
                );
                if layers.response(la, lb) != Response::Separate
                    || (a["static"] == true && b["static"] == true)
                {
                    continue;
                }
                let sa = shape_def(&a["shape"]).to_shape().unwrap();
                let sb = shape_def(&b["shape"]).to_shape().unwrap();
                let pa = Pose::new(
                    Vec2::new(
                        a["position"][0].as_f64().unwrap(),
                        a["position"][1].as_f64().unwrap(),
                    ),
                    a["angle"].as_f64().unwrap(),
                );
                let pb = Pose::new(
                    Vec2::new(
                        b["position"][0].as_f64().unwrap(),
                        b["position"][1].as_f64().unwrap(),
                    ),
                    b["angle"].as_f64().unwrap(),
                );
                let c = ricochet_geom::contact(&sa, &pa, &sb, &pb);
                assert!(
                    c.depth <= SLOP,
                    "frame {}: {} and {} overlap by {}",
                    m["frame"],
                    a["name"],
                    b["name"],
                    c.depth
                );
                pairs += 1;
            }
        }
    }
    assert!(pairs > 0);
}

#[test]
fn a_truncated_log_is_reported_as_truncated() {
    let dir = tempfile::tempdir().unwrap();
    let bytes = run(&root().join("scenarios/shapes.toml"), dir.path(), "s.mcap");
    for cut in [bytes.len() / 2, bytes.len() - 1] {
        let err = read_log(&bytes[..cut]).expect_err("a cut log is refused");
        assert!(
            err.to_string().to_lowercase().contains("trunc")
                || err.to_string().contains("cut short"),
            "{err}"
        );
    }
}

#[test]
fn an_unwritable_output_fails_before_the_simulation_starts() {
    let o = ricochet(&["run", "-o", "no/such/dir/out.mcap"], b"");
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("no/such/dir/out.mcap") && !err.contains("frames/s"),
        "{err}"
    );
}

#[test]
fn ctrl_c_still_leaves_a_complete_indexed_log() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("long.mcap");
    let child = std::process::Command::new(env!("CARGO_BIN_EXE_ricochet"))
        .args([
            "run",
            "scenarios/asteroids.toml",
            "--frames",
            "100000000",
            "-o",
        ])
        .arg(&out)
        .current_dir(root())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Wait until frames are being written (to the temporary file, renamed onto `out` when
    // the log is complete), then interrupt as a terminal's Ctrl-C would.
    for _ in 0..200 {
        let written = std::fs::read_dir(dir.path())
            .unwrap()
            .filter_map(|e| e.ok()?.metadata().ok())
            .any(|m| m.len() > 200_000);
        if written {
            break;
        }
        assert!(!out.exists(), "the log appears only when it is complete");
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    let kill = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let result = child.wait_with_output().unwrap();
    assert!(
        result.status.success(),
        "{}",
        String::from_utf8_lossy(&result.stderr)
    );
    assert!(String::from_utf8_lossy(&result.stderr).contains("interrupted"));
    let log = read_log_file(&out).expect("an interrupted run's log is complete and indexed");
    assert!(topic(&log, "/stats").count() > 10);
}
