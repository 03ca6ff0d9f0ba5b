//! Messages and a log shared by the integration tests.

#![allow(
    dead_code,
    reason = "each test binary uses a different part of this module; `expect` would be unfulfilled in the one that uses it all"
)]

use std::path::Path;

use ricochet_log::LogWriter;
use ricochet_log::messages::fox::{
    ArrowPrimitive, Color, CubePrimitive, CylinderPrimitive, KeyValuePair, LinePrimitive, Log,
    ModelPrimitive, Point3, Pose, Quaternion, SceneEntity, SceneEntityDeletion, SceneUpdate,
    SpherePrimitive, TextPrimitive, TriangleListPrimitive, Vector3, line_primitive, log,
    scene_entity_deletion,
};
use ricochet_log::messages::timestamp;

fn v3(x: f64, y: f64, z: f64) -> Option<Vector3> {
    Some(Vector3 { x, y, z })
}

fn p3(x: f64, y: f64) -> Point3 {
    Point3 { x, y, z: 0.0 }
}

/// A scene update with one entity holding one primitive of every kind.
pub fn full_scene(time_ns: u64) -> SceneUpdate {
    let red = Some(Color {
        r: 1.0,
        g: 0.0,
        b: 0.0,
        a: 1.0,
    });
    let pose = Some(Pose {
        position: v3(1.5, -2.25, 0.0),
        orientation: Some(Quaternion {
            x: 0.0,
            y: 0.0,
            z: 0.25,
            w: 0.75,
        }),
    });
    let triangle = vec![p3(0.0, 0.0), p3(1.0, 0.0), p3(0.0, 1.0)];
    let entity = SceneEntity {
        timestamp: Some(timestamp(time_ns)),
        frame_id: "world".to_owned(),
        id: "body/7".to_owned(),
        lifetime: None,
        frame_locked: true,
        metadata: vec![KeyValuePair {
            key: "shape".to_owned(),
            value: "ball".to_owned(),
        }],
        arrows: vec![ArrowPrimitive {
            pose,
            shaft_length: 1.0,
            shaft_diameter: 0.05,
            head_length: 0.2,
            head_diameter: 0.1,
            color: red,
        }],
        cubes: vec![CubePrimitive {
            pose,
            size: v3(2.0, 1.0, 0.1),
            color: red,
        }],
        spheres: vec![SpherePrimitive {
            pose,
            size: v3(0.5, 0.5, 0.5),
            color: red,
        }],
        cylinders: vec![CylinderPrimitive {
            pose,
            size: v3(1.0, 1.0, 0.1),
            bottom_scale: 1.0,
            top_scale: 1.0,
            color: red,
        }],
        lines: vec![LinePrimitive {
            r#type: line_primitive::Type::LineLoop as i32,
            pose,
            thickness: 2.0,
            scale_invariant: true,
            points: triangle.clone(),
            color: red,
            colors: Vec::new(),
            indices: vec![0, 1, 2],
        }],
        triangles: vec![TriangleListPrimitive {
            pose,
            points: triangle,
            color: red,
            colors: vec![
                Color {
                    r: 1.0,
                    g: 0.0,
                    b: 0.0,
                    a: 1.0
                };
                3
            ],
            indices: Vec::new(),
        }],
        texts: vec![TextPrimitive {
            pose,
            billboard: true,
            font_size: 12.0,
            scale_invariant: true,
            color: red,
            text: "body 7".to_owned(),
        }],
        models: vec![ModelPrimitive {
            pose,
            scale: v3(1.0, 1.0, 1.0),
            color: red,
            override_color: false,
            url: "package://ricochet/ball.glb".to_owned(),
            media_type: String::new(),
            data: Vec::new().into(),
        }],
    };
    SceneUpdate {
        deletions: Vec::new(),
        entities: vec![entity],
    }
}

/// A scene update that only deletes: one entity by id, then everything.
pub fn deletion_scene(time_ns: u64) -> SceneUpdate {
    let deletion = |kind: scene_entity_deletion::Type, id: &str| SceneEntityDeletion {
        timestamp: Some(timestamp(time_ns)),
        r#type: kind as i32,
        id: id.to_owned(),
    };
    SceneUpdate {
        deletions: vec![
            deletion(scene_entity_deletion::Type::MatchingId, "body/7"),
            deletion(scene_entity_deletion::Type::All, ""),
        ],
        entities: Vec::new(),
    }
}

/// A log line.
pub fn log_line(time_ns: u64) -> Log {
    Log {
        timestamp: Some(timestamp(time_ns)),
        level: log::Level::Info as i32,
        message: format!("step at {time_ns} ns"),
        name: "ricochet".to_owned(),
        file: "src/main.rs".to_owned(),
        line: 42,
    }
}

/// Number of steps [`write_sample_log`] writes.
pub const STEPS: u64 = 20;
/// Simulation time step of [`write_sample_log`], in nanoseconds.
pub const STEP_NS: u64 = 16_666_667;

/// Writes a small log: per step a scene update on `/scene` and a line on
/// `/log`, with a deletion on the last step.
pub fn write_sample_log(path: &Path) {
    write_sample_log_with(path, ricochet_log::Threading::Thread);
}

/// [`write_sample_log`], encoding where `threading` says.
pub fn write_sample_log_with(path: &Path, threading: ricochet_log::Threading) {
    write_sample_log_sharing(path, threading, ricochet_log::SHARE_ENCODING_FROM);
}

/// [`write_sample_log_with`], the caller encoding once `share_from` jobs are queued
/// (`LogWriter::share_encoding_from`).
pub fn write_sample_log_sharing(
    path: &Path,
    threading: ricochet_log::Threading,
    share_from: usize,
) {
    let mut writer = LogWriter::create_with(path, "ricochet-log tests", threading).unwrap();
    writer.share_encoding_from(share_from);
    let scene = writer
        .add_foxglove_channel::<SceneUpdate>("/scene")
        .unwrap();
    let log = writer.add_foxglove_channel::<Log>("/log").unwrap();
    for step in 0..STEPS {
        let time_ns = step * STEP_NS;
        writer.write(scene, time_ns, full_scene(time_ns)).unwrap();
        writer.write(log, time_ns, log_line(time_ns)).unwrap();
    }
    let end_ns = STEPS * STEP_NS;
    writer.write(scene, end_ns, deletion_scene(end_ns)).unwrap();
    writer.finish().unwrap();
}
