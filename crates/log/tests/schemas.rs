//! The Foxglove message types serialize to JSON that the vendored Foxglove
//! schemas accept, with exactly the schemas' fields.

mod common;

use common::{deletion_scene, full_scene, log_line};
use ricochet_log::foxglove::{LOG_SCHEMA, SCENE_UPDATE_SCHEMA};
use serde_json::Value;

fn validator(schema: &str) -> jsonschema::Validator {
    let schema: Value = serde_json::from_str(schema).unwrap();
    jsonschema::validator_for(&schema).unwrap()
}

fn assert_valid(schema: &str, instance: &Value) {
    let validator = validator(schema);
    let errors: Vec<String> = validator
        .iter_errors(instance)
        .map(|error| format!("{} at {}", error, error.instance_path()))
        .collect();
    assert!(errors.is_empty(), "schema violations: {errors:#?}");
}

/// Walks `schema` and `instance` together: every object the schema describes
/// with `properties` must have exactly those keys (the schemas don't forbid
/// extra keys, so a misnamed field would otherwise pass).
fn assert_same_fields(schema: &Value, instance: &Value, at: &str) {
    if let Some(properties) = schema.get("properties").and_then(Value::as_object) {
        let object = instance
            .as_object()
            .unwrap_or_else(|| panic!("{at}: expected an object, got {instance}"));
        let expected: Vec<&String> = properties.keys().collect();
        let got: Vec<&String> = object.keys().collect();
        let mut expected_sorted = expected.clone();
        let mut got_sorted = got.clone();
        expected_sorted.sort();
        got_sorted.sort();
        assert_eq!(got_sorted, expected_sorted, "{at}: fields differ");
        for (key, property) in properties {
            assert_same_fields(property, &object[key], &format!("{at}.{key}"));
        }
    }
    if let Some(items) = schema.get("items") {
        for (index, item) in instance.as_array().into_iter().flatten().enumerate() {
            assert_same_fields(items, item, &format!("{at}[{index}]"));
        }
    }
}

fn check(schema: &str, instance: &Value) {
    assert_valid(schema, instance);
    let schema: Value = serde_json::from_str(schema).unwrap();
    assert_same_fields(&schema, instance, "$");
}

#[test]
fn scene_update_with_every_primitive_matches_schema() {
    let scene = serde_json::to_value(full_scene(1_234_567_890)).unwrap();
    let entity = &scene["entities"][0];
    for list in [
        "arrows",
        "cubes",
        "spheres",
        "cylinders",
        "lines",
        "triangles",
        "texts",
        "models",
        "metadata",
    ] {
        assert_eq!(entity[list].as_array().map(Vec::len), Some(1), "{list}");
    }
    check(SCENE_UPDATE_SCHEMA, &scene);
}

#[test]
fn scene_update_with_deletions_matches_schema() {
    let scene = serde_json::to_value(deletion_scene(2_000_000_001)).unwrap();
    check(SCENE_UPDATE_SCHEMA, &scene);
}

#[test]
fn log_matches_schema() {
    check(LOG_SCHEMA, &serde_json::to_value(log_line(7)).unwrap());
}

#[test]
fn validator_rejects_missing_or_mistyped_fields() {
    let scene_validator = validator(SCENE_UPDATE_SCHEMA);
    let mut scene = serde_json::to_value(full_scene(1)).unwrap();
    assert!(scene_validator.is_valid(&scene));
    scene["entities"][0]
        .as_object_mut()
        .unwrap()
        .remove("frame_id");
    assert!(
        !scene_validator.is_valid(&scene),
        "missing frame_id accepted"
    );

    let mut line_type = serde_json::to_value(full_scene(1)).unwrap();
    line_type["entities"][0]["lines"][0]["type"] = Value::from(7);
    assert!(
        !scene_validator.is_valid(&line_type),
        "line type 7 accepted"
    );

    let mut nan_color = serde_json::to_value(full_scene(1)).unwrap();
    nan_color["entities"][0]["cubes"][0]["color"]["r"] = Value::Null;
    assert!(!scene_validator.is_valid(&nan_color), "null color accepted");

    let log_validator = validator(LOG_SCHEMA);
    let mut log = serde_json::to_value(log_line(1)).unwrap();
    assert!(log_validator.is_valid(&log));
    log.as_object_mut().unwrap().remove("message");
    assert!(!log_validator.is_valid(&log), "missing message accepted");
}

#[test]
fn non_finite_floats_are_rejected_by_the_schema() {
    // Documents why callers must never pass NaN: serde_json writes null.
    let mut scene = full_scene(1);
    scene.entities[0].cubes[0].size.x = f64::NAN;
    let json = serde_json::to_value(&scene).unwrap();
    assert!(!validator(SCENE_UPDATE_SCHEMA).is_valid(&json));
}
