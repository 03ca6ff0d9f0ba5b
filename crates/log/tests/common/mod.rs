//! Messages and a log shared by the integration tests.

#![allow(
    dead_code,
    reason = "each test binary uses a different part of this module; `expect` would be unfulfilled in the one that uses it all"
)]

use std::path::Path;

use ricochet_log::LogWriter;
use ricochet_log::foxglove::{
    ArrowPrimitive, Color, CubePrimitive, CylinderPrimitive, KeyValuePair, LinePrimitive, LineType,
    Log, LogLevel, ModelPrimitive, Point3, Pose, SceneEntity, SceneEntityDeletion, SceneUpdate,
    SpherePrimitive, TextPrimitive, Timestamp, TriangleListPrimitive, Vector3,
};

/// A scene update with one entity holding one primitive of every kind.
pub fn full_scene(time_ns: u64) -> SceneUpdate {
    let timestamp = Timestamp::from_nanos(time_ns);
    let red = Color::rgba(1.0, 0.0, 0.0, 1.0);
    let pose = Pose::planar(1.5, -2.25, 0.75);
    let mut entity = SceneEntity::new("body/7", "world", timestamp);
    entity.metadata.push(KeyValuePair::new("shape", "ball"));
    entity.arrows.push(ArrowPrimitive {
        pose,
        shaft_length: 1.0,
        shaft_diameter: 0.05,
        head_length: 0.2,
        head_diameter: 0.1,
        color: red,
    });
    entity.cubes.push(CubePrimitive {
        pose,
        size: Vector3::new(2.0, 1.0, 0.1),
        color: red,
    });
    entity.spheres.push(SpherePrimitive {
        pose,
        size: Vector3::new(0.5, 0.5, 0.5),
        color: red,
    });
    entity.cylinders.push(CylinderPrimitive {
        pose,
        size: Vector3::new(1.0, 1.0, 0.1),
        bottom_scale: 1.0,
        top_scale: 1.0,
        color: red,
    });
    entity.lines.push(LinePrimitive {
        line_type: LineType::LineLoop,
        pose,
        thickness: 2.0,
        scale_invariant: true,
        points: vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
        ],
        color: red,
        colors: Vec::new(),
        indices: vec![0, 1, 2],
    });
    entity.triangles.push(TriangleListPrimitive {
        pose,
        points: vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
        ],
        color: red,
        colors: vec![red, red, red],
        indices: Vec::new(),
    });
    entity.texts.push(TextPrimitive {
        pose,
        billboard: true,
        font_size: 12.0,
        scale_invariant: true,
        color: red,
        text: "body 7".to_owned(),
    });
    entity.models.push(ModelPrimitive {
        pose,
        scale: Vector3::new(1.0, 1.0, 1.0),
        color: red,
        override_color: false,
        url: "package://ricochet/ball.glb".to_owned(),
        media_type: String::new(),
        data: String::new(),
    });
    SceneUpdate {
        deletions: Vec::new(),
        entities: vec![entity],
    }
}

/// A scene update that only deletes: one entity by id, then everything.
pub fn deletion_scene(time_ns: u64) -> SceneUpdate {
    let timestamp = Timestamp::from_nanos(time_ns);
    SceneUpdate {
        deletions: vec![
            SceneEntityDeletion::matching_id(timestamp, "body/7"),
            SceneEntityDeletion::all(timestamp),
        ],
        entities: Vec::new(),
    }
}

/// A log line.
pub fn log_line(time_ns: u64) -> Log {
    let mut log = Log::new(
        Timestamp::from_nanos(time_ns),
        LogLevel::Info,
        "ricochet",
        format!("step at {time_ns} ns"),
    );
    log.file = "src/main.rs".to_owned();
    log.line = 42;
    log
}

/// Number of steps [`write_sample_log`] writes.
pub const STEPS: u64 = 20;
/// Simulation time step of [`write_sample_log`], in nanoseconds.
pub const STEP_NS: u64 = 16_666_667;

/// Writes a small log: per step a scene update on `/scene` and a line on
/// `/log`, with a deletion on the last step.
pub fn write_sample_log(path: &Path) {
    let mut writer = LogWriter::create(path, "ricochet-log tests").unwrap();
    let scene = writer.add_scene_channel("/scene").unwrap();
    let log = writer.add_log_channel("/log").unwrap();
    for step in 0..STEPS {
        let time_ns = step * STEP_NS;
        writer.write(scene, time_ns, &full_scene(time_ns)).unwrap();
        writer.write(log, time_ns, &log_line(time_ns)).unwrap();
    }
    let end_ns = STEPS * STEP_NS;
    writer
        .write(scene, end_ns, &deletion_scene(end_ns))
        .unwrap();
    writer.finish().unwrap();
}
