//! The JSON Schemas of `/bodies`, `/contacts`, `/stats` and `/validation` as Foxglove-style
//! viewers read them. Lichtblick 1.10.8 (the open-source Foxglove Studio, run on every
//! shipped scenario with `../shared/viewer/view`) does not follow `$ref`/`$defs` and needs a
//! `"type"` beside every `enum`; otherwise it drops the whole topic ("Unsupported type
//! undefined for array item bodies"). These are the rules its problems list taught us.

use serde_json::Value;

use crate::util::root;

fn walk(v: &Value, path: &str, problems: &mut Vec<String>) {
    match v {
        Value::Object(map) => {
            for key in ["$ref", "$defs", "definitions"] {
                if map.contains_key(key) {
                    problems.push(format!("{path}: {key} (viewers don't follow it)"));
                }
            }
            if map.contains_key("enum") && !map.contains_key("type") {
                problems.push(format!("{path}: an enum without a type"));
            }
            for (k, child) in map {
                walk(child, &format!("{path}.{k}"), problems);
            }
        }
        Value::Array(items) => {
            for (i, child) in items.iter().enumerate() {
                walk(child, &format!("{path}[{i}]"), problems);
            }
        }
        _ => {}
    }
}

#[test]
fn channel_schemas_are_self_contained_and_typed() {
    let dir = root().join("src").join("schemas");
    let mut checked = 0;
    let mut problems = Vec::new();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let schema: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        walk(&schema, &name, &mut problems);
        checked += 1;
    }
    assert!(checked >= 4, "Bodies, Contacts, Stats, Validation");
    assert!(problems.is_empty(), "{problems:#?}");
}
