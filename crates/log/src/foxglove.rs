//! Foxglove message types, serialized as JSON that matches the vendored
//! `@foxglove/schemas` 2.1.0 JSON Schemas (`schemas/SceneUpdate.json`,
//! `schemas/Log.json`).
//!
//! Those schemas mark every field required, so every struct here serializes
//! every field, empty lists included. Field names and order follow the
//! schemas. Enumerations (`LineType`, `DeletionType`, `LogLevel`) serialize as
//! their integer values, as the schemas require.
//!
//! Floating-point fields must be finite: `serde_json` writes NaN and the
//! infinities as `null`, which the schemas reject and Foxglove cannot draw.
//! Callers never pass them.

use serde::{Serialize, Serializer};

/// Schema name of [`SceneUpdate`] in MCAP files and in Foxglove.
pub const SCENE_UPDATE_SCHEMA_NAME: &str = "foxglove.SceneUpdate";
/// JSON Schema of [`SceneUpdate`], vendored from `@foxglove/schemas` 2.1.0.
pub const SCENE_UPDATE_SCHEMA: &str = include_str!("../schemas/SceneUpdate.json");
/// Schema name of [`Log`] in MCAP files and in Foxglove.
pub const LOG_SCHEMA_NAME: &str = "foxglove.Log";
/// JSON Schema of [`Log`], vendored from `@foxglove/schemas` 2.1.0.
pub const LOG_SCHEMA: &str = include_str!("../schemas/Log.json");

const NANOS_PER_SEC: u64 = 1_000_000_000;

/// A point in time, `{sec, nsec}` with `nsec < 1e9` (the schema's `time`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default, Serialize)]
pub struct Timestamp {
    /// Whole seconds.
    pub sec: u64,
    /// Nanoseconds past `sec`, below one billion.
    pub nsec: u32,
}

impl Timestamp {
    /// The timestamp `nanos` nanoseconds after zero.
    pub fn from_nanos(nanos: u64) -> Self {
        Self {
            sec: nanos / NANOS_PER_SEC,
            nsec: (nanos % NANOS_PER_SEC) as u32,
        }
    }
}

/// A signed length of time, `{sec, nsec}` with `nsec < 1e9` (the schema's
/// `duration`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default, Serialize)]
pub struct Duration {
    /// Whole seconds (may be negative).
    pub sec: i64,
    /// Nanoseconds added to `sec`, below one billion.
    pub nsec: u32,
}

impl Duration {
    /// Zero length. As a [`SceneEntity::lifetime`] it means "until replaced or
    /// deleted".
    pub const ZERO: Self = Self { sec: 0, nsec: 0 };

    /// The duration of `nanos` nanoseconds.
    pub fn from_nanos(nanos: u64) -> Self {
        Self {
            sec: (nanos / NANOS_PER_SEC) as i64,
            nsec: (nanos % NANOS_PER_SEC) as u32,
        }
    }
}

/// A 3D vector.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct Vector3 {
    /// x coordinate.
    pub x: f64,
    /// y coordinate.
    pub y: f64,
    /// z coordinate.
    pub z: f64,
}

impl Vector3 {
    /// The vector `(x, y, z)`.
    pub fn new(x: f64, y: f64, z: f64) -> Self {
        Self { x, y, z }
    }
}

/// A 3D point.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct Point3 {
    /// x coordinate.
    pub x: f64,
    /// y coordinate.
    pub y: f64,
    /// z coordinate.
    pub z: f64,
}

impl Point3 {
    /// The point `(x, y, z)`.
    pub fn new(x: f64, y: f64, z: f64) -> Self {
        Self { x, y, z }
    }
}

/// A rotation as a unit quaternion.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Quaternion {
    /// x component.
    pub x: f64,
    /// y component.
    pub y: f64,
    /// z component.
    pub z: f64,
    /// w (scalar) component.
    pub w: f64,
}

impl Quaternion {
    /// No rotation.
    pub const IDENTITY: Self = Self {
        x: 0.0,
        y: 0.0,
        z: 0.0,
        w: 1.0,
    };

    /// A rotation by `yaw` radians about the z axis (counter-clockwise seen
    /// from +z). Uses `libm` so the result is bit-identical on every machine.
    pub fn from_yaw(yaw: f64) -> Self {
        let half = yaw * 0.5;
        Self {
            x: 0.0,
            y: 0.0,
            z: libm::sin(half),
            w: libm::cos(half),
        }
    }
}

impl Default for Quaternion {
    fn default() -> Self {
        Self::IDENTITY
    }
}

/// A position and orientation.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct Pose {
    /// Position.
    pub position: Vector3,
    /// Orientation.
    pub orientation: Quaternion,
}

impl Pose {
    /// The pose at `position` with `orientation`.
    pub fn new(position: Vector3, orientation: Quaternion) -> Self {
        Self {
            position,
            orientation,
        }
    }

    /// A pose in the z = 0 plane: at `(x, y, 0)`, rotated by `yaw` about z.
    pub fn planar(x: f64, y: f64, yaw: f64) -> Self {
        Self::new(Vector3::new(x, y, 0.0), Quaternion::from_yaw(yaw))
    }
}

/// An RGBA color, each channel in `0.0..=1.0`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct Color {
    /// Red.
    pub r: f64,
    /// Green.
    pub g: f64,
    /// Blue.
    pub b: f64,
    /// Alpha (opacity).
    pub a: f64,
}

impl Color {
    /// The color `(r, g, b, a)`.
    pub fn rgba(r: f64, g: f64, b: f64, a: f64) -> Self {
        Self { r, g, b, a }
    }
}

/// A key with its value, as entity metadata.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize)]
pub struct KeyValuePair {
    /// Key.
    pub key: String,
    /// Value.
    pub value: String,
}

impl KeyValuePair {
    /// The pair `key = value`.
    pub fn new(key: impl Into<String>, value: impl Into<String>) -> Self {
        Self {
            key: key.into(),
            value: value.into(),
        }
    }
}

/// An arrow.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct ArrowPrimitive {
    /// Position of the arrow's tail and orientation of the arrow (it points
    /// along the pose's +x axis).
    pub pose: Pose,
    /// Length of the shaft.
    pub shaft_length: f64,
    /// Diameter of the shaft.
    pub shaft_diameter: f64,
    /// Length of the head.
    pub head_length: f64,
    /// Diameter of the head.
    pub head_diameter: f64,
    /// Color.
    pub color: Color,
}

/// A box.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct CubePrimitive {
    /// Position of the center and orientation.
    pub pose: Pose,
    /// Size along each axis.
    pub size: Vector3,
    /// Color.
    pub color: Color,
}

/// An ellipsoid.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct SpherePrimitive {
    /// Position of the center and orientation.
    pub pose: Pose,
    /// Diameter along each axis.
    pub size: Vector3,
    /// Color.
    pub color: Color,
}

/// A cylinder or cone, with its axis along z.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct CylinderPrimitive {
    /// Position of the center and orientation.
    pub pose: Pose,
    /// Size of the bounding box.
    pub size: Vector3,
    /// Scale of the bottom face relative to `size` (0 = point, 1 = full).
    pub bottom_scale: f64,
    /// Scale of the top face relative to `size` (0 = point, 1 = full).
    pub top_scale: f64,
    /// Color.
    pub color: Color,
}

/// How a [`LinePrimitive`] joins its points. Serialized as its integer value.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LineType {
    /// Connected segments 0-1, 1-2, ..., (n-1)-n.
    #[default]
    LineStrip = 0,
    /// Closed polygon 0-1, 1-2, ..., (n-1)-n, n-0.
    LineLoop = 1,
    /// Separate segments 0-1, 2-3, 4-5, ...
    LineList = 2,
}

impl Serialize for LineType {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_u8(*self as u8)
    }
}

/// A set of line segments.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct LinePrimitive {
    /// How the points are joined.
    #[serde(rename = "type")]
    pub line_type: LineType,
    /// Origin and orientation of the points' frame.
    pub pose: Pose,
    /// Line thickness.
    pub thickness: f64,
    /// Whether `thickness` is in screen pixels (true) or scene units (false).
    pub scale_invariant: bool,
    /// Points, in the frame of `pose`.
    pub points: Vec<Point3>,
    /// Color of the whole line (used when `colors` is empty).
    pub color: Color,
    /// Per-point colors; empty or as long as `points`.
    pub colors: Vec<Color>,
    /// Indices into `points`; empty means all points in order.
    pub indices: Vec<u32>,
}

/// A set of triangles.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct TriangleListPrimitive {
    /// Origin and orientation of the points' frame.
    pub pose: Pose,
    /// Vertices, three per triangle (unless `indices` is set).
    pub points: Vec<Point3>,
    /// Color of all triangles (used when `colors` is empty).
    pub color: Color,
    /// Per-vertex colors; empty or as long as `points`.
    pub colors: Vec<Color>,
    /// Indices into `points`, three per triangle; empty means all in order.
    pub indices: Vec<u32>,
}

/// A text label.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct TextPrimitive {
    /// Position and orientation of the text.
    pub pose: Pose,
    /// Whether the text always faces the camera.
    pub billboard: bool,
    /// Font size.
    pub font_size: f64,
    /// Whether `font_size` is in screen pixels (true) or scene units (false).
    pub scale_invariant: bool,
    /// Color.
    pub color: Color,
    /// The text.
    pub text: String,
}

/// A 3D model, from a URL or embedded data.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct ModelPrimitive {
    /// Origin and orientation of the model.
    pub pose: Pose,
    /// Scale along each axis.
    pub scale: Vector3,
    /// Solid color used when `override_color` is true.
    pub color: Color,
    /// Whether to draw the model in `color` instead of its own colors.
    pub override_color: bool,
    /// URL of the model; empty when `data` is used.
    pub url: String,
    /// Media type of `data` (e.g. `model/gltf-binary`).
    pub media_type: String,
    /// Embedded model data, base64-encoded; empty when `url` is used.
    pub data: String,
}

/// A visual element of a scene: a set of primitives sharing an id, a frame
/// and a lifetime.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct SceneEntity {
    /// Time the entity refers to.
    pub timestamp: Timestamp,
    /// Frame the entity's poses are in.
    pub frame_id: String,
    /// Identifier, unique per topic; a later entity with the same id
    /// replaces this one.
    pub id: String,
    /// How long the entity stays visible; zero means until replaced or
    /// deleted.
    pub lifetime: Duration,
    /// Whether the entity moves with its frame after it is received.
    pub frame_locked: bool,
    /// Extra key/value data shown in Foxglove.
    pub metadata: Vec<KeyValuePair>,
    /// Arrows.
    pub arrows: Vec<ArrowPrimitive>,
    /// Boxes.
    pub cubes: Vec<CubePrimitive>,
    /// Ellipsoids.
    pub spheres: Vec<SpherePrimitive>,
    /// Cylinders and cones.
    pub cylinders: Vec<CylinderPrimitive>,
    /// Lines.
    pub lines: Vec<LinePrimitive>,
    /// Triangle lists.
    pub triangles: Vec<TriangleListPrimitive>,
    /// Text labels.
    pub texts: Vec<TextPrimitive>,
    /// Models.
    pub models: Vec<ModelPrimitive>,
}

impl SceneEntity {
    /// An entity with no primitives or metadata, a zero (unlimited) lifetime
    /// and `frame_locked` false.
    pub fn new(id: impl Into<String>, frame_id: impl Into<String>, timestamp: Timestamp) -> Self {
        Self {
            timestamp,
            frame_id: frame_id.into(),
            id: id.into(),
            ..Self::default()
        }
    }
}

/// Which entities a [`SceneEntityDeletion`] removes. Serialized as its
/// integer value.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DeletionType {
    /// The entity on the same topic with the given id.
    #[default]
    MatchingId = 0,
    /// All entities on the same topic.
    All = 1,
}

impl Serialize for DeletionType {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_u8(*self as u8)
    }
}

/// A command to remove entities from a scene.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize)]
pub struct SceneEntityDeletion {
    /// Only entities with a timestamp at or before this are deleted.
    pub timestamp: Timestamp,
    /// Which entities to delete.
    #[serde(rename = "type")]
    pub deletion_type: DeletionType,
    /// Id of the entity to delete, for [`DeletionType::MatchingId`].
    pub id: String,
}

impl SceneEntityDeletion {
    /// Deletes the entity with `id`.
    pub fn matching_id(timestamp: Timestamp, id: impl Into<String>) -> Self {
        Self {
            timestamp,
            deletion_type: DeletionType::MatchingId,
            id: id.into(),
        }
    }

    /// Deletes every entity on the topic.
    pub fn all(timestamp: Timestamp) -> Self {
        Self {
            timestamp,
            deletion_type: DeletionType::All,
            id: String::new(),
        }
    }
}

/// An update to a 3D scene: deletions are applied first, then entities are
/// added or replaced.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct SceneUpdate {
    /// Entities to delete.
    pub deletions: Vec<SceneEntityDeletion>,
    /// Entities to add or replace.
    pub entities: Vec<SceneEntity>,
}

/// Severity of a [`Log`]. Serialized as its integer value.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default)]
pub enum LogLevel {
    /// Unknown.
    #[default]
    Unknown = 0,
    /// Debug.
    Debug = 1,
    /// Info.
    Info = 2,
    /// Warning.
    Warning = 3,
    /// Error.
    Error = 4,
    /// Fatal.
    Fatal = 5,
}

impl Serialize for LogLevel {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_u8(*self as u8)
    }
}

/// A text log line, shown in Foxglove's Log panel.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize)]
pub struct Log {
    /// Time of the message.
    pub timestamp: Timestamp,
    /// Severity.
    pub level: LogLevel,
    /// The message.
    pub message: String,
    /// Name of the process or component that logged it.
    pub name: String,
    /// Source file, or empty.
    pub file: String,
    /// Line in `file`, or 0.
    pub line: u32,
}

impl Log {
    /// A message from `name` at `timestamp`, with no source location.
    pub fn new(
        timestamp: Timestamp,
        level: LogLevel,
        name: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        Self {
            timestamp,
            level,
            message: message.into(),
            name: name.into(),
            file: String::new(),
            line: 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timestamp_and_duration_split_nanos() {
        assert_eq!(
            Timestamp::from_nanos(3_000_000_007),
            Timestamp { sec: 3, nsec: 7 }
        );
        assert_eq!(Timestamp::from_nanos(999_999_999).nsec, 999_999_999);
        assert_eq!(
            Duration::from_nanos(1_500_000_000),
            Duration {
                sec: 1,
                nsec: 500_000_000
            }
        );
    }

    #[test]
    fn yaw_quaternion_is_unit_and_about_z() {
        let q = Quaternion::from_yaw(core::f64::consts::FRAC_PI_2);
        assert_eq!((q.x, q.y), (0.0, 0.0));
        assert!((q.z - core::f64::consts::FRAC_1_SQRT_2).abs() < 1e-15);
        assert!((q.w - core::f64::consts::FRAC_1_SQRT_2).abs() < 1e-15);
        assert_eq!(Quaternion::from_yaw(0.0), Quaternion::IDENTITY);
    }

    #[test]
    fn enums_serialize_as_integers() {
        let line = LinePrimitive {
            line_type: LineType::LineList,
            ..LinePrimitive::default()
        };
        let json = serde_json::to_value(&line).unwrap();
        assert_eq!(json["type"], 2);
        let deletion = SceneEntityDeletion::all(Timestamp::default());
        assert_eq!(serde_json::to_value(&deletion).unwrap()["type"], 1);
        let log = Log::new(Timestamp::default(), LogLevel::Warning, "n", "m");
        assert_eq!(serde_json::to_value(&log).unwrap()["level"], 3);
    }
}
