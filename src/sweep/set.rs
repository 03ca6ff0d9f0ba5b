//! `--set KEY=V1,V2,…`: which scalar of the scenario file a sweep changes, and the values.
//!
//! A key is a dotted path through the file, the way a reader finds the value in it:
//!
//! | key                                   | the value in the file                                   |
//! |---------------------------------------|---------------------------------------------------------|
//! | `world.dt` (or `dt`)                  | the timestep, seconds (`hz` is replaced)                |
//! | `world.hz` (or `hz`)                  | the timestep as steps per second                        |
//! | `frames`                              | the run's length, in frames at the file's own timestep  |
//! | `world.gravity.y`                     | `[world] gravity = [x, y]`: `.x`/`.y` pick a component  |
//! | `world.sleep_after`, `world.bounds.max.x` | any field of `[world]` and its tables               |
//! | `templates.NAME.FIELD`                | a field of `[templates.NAME]` (`mass`, `velocity.x`, `controller.speed`, `shape`) |
//! | `bodies.NAME.FIELD`                   | the same field of every `[[bodies]]` entry named NAME   |
//!
//! Values are numbers (`-30`, `0.5`, `1e-3`) or fractions (`1/60`); a `shape` takes the
//! short form of `shape.rs`, or `file` for the file's own shape. A value is written into the
//! file's text and the file is loaded as usual, so a wrong field or value gets the loader's
//! `file:line:column` error, like any scenario file.

use toml_edit::{DocumentMut, InlineTable, Item, TableLike, Value};

use super::shape;
use super::time::Ratio;

/// One value of a setting.
#[derive(Clone, Debug)]
pub enum Setting {
    /// A number: the text as given, and the value (fractions divided out).
    Number {
        /// As written on the command line.
        text: String,
        /// Its value.
        value: f64,
        /// Its value as a whole number, when written as one (`600`).
        integer: Option<i64>,
    },
    /// A timestep, exactly.
    Timestep {
        /// As written on the command line.
        text: String,
        /// Seconds per step.
        dt: Ratio,
    },
    /// A shape in its short form.
    Shape {
        /// As written on the command line.
        text: String,
        /// The scenario file's table for it.
        table: InlineTable,
    },
    /// The file's own value (`file`): nothing is changed.
    File,
}

impl Setting {
    /// The value as the user wrote it (for tables and the CSV).
    #[must_use]
    pub fn text(&self) -> &str {
        match self {
            Setting::Number { text, .. }
            | Setting::Timestep { text, .. }
            | Setting::Shape { text, .. } => text,
            Setting::File => "file",
        }
    }
}

/// Where a `--set` writes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Target {
    /// The timestep (`world.dt`, `dt`, `world.hz`, `hz`).
    Timestep,
    /// Any other field, by its path.
    Field(Vec<String>),
}

/// One `--set KEY=V1,V2,…`.
#[derive(Clone, Debug)]
pub struct Sweep {
    /// The key as written.
    pub key: String,
    /// Where it writes.
    pub target: Target,
    /// The values, in the order given.
    pub values: Vec<Setting>,
}

/// A number or a fraction `A/B`.
#[must_use]
pub fn number(text: &str) -> Option<f64> {
    let t = text.trim();
    let v = match t.split_once('/') {
        Some((a, b)) => a.trim().parse::<f64>().ok()? / b.trim().parse::<f64>().ok()?,
        None => t.parse::<f64>().ok()?,
    };
    v.is_finite().then_some(v)
}

const ROOTS: &str =
    "world.dt, world.hz, frames, world.FIELD, templates.NAME.FIELD or bodies.NAME.FIELD";

/// Parses `KEY=V1,V2,…`.
pub fn parse(arg: &str) -> Result<Sweep, String> {
    let (key, values) = arg
        .split_once('=')
        .ok_or_else(|| format!("`{arg}` is not KEY=V1,V2,…"))?;
    let key = key.trim().to_owned();
    let segs: Vec<String> = key.split('.').map(str::to_owned).collect();
    if segs.iter().any(String::is_empty) {
        return Err(format!("`{key}` is not a key: {ROOTS}"));
    }
    let target = match segs
        .iter()
        .map(String::as_str)
        .collect::<Vec<_>>()
        .as_slice()
    {
        ["dt" | "hz"] | ["world", "dt" | "hz"] => Target::Timestep,
        ["frames"] | ["world", _, ..] | ["templates" | "bodies", _, _, ..] => {
            Target::Field(segs.clone())
        }
        _ => return Err(format!("`{key}` is not a key: {ROOTS}")),
    };
    let hz = segs.last().is_some_and(|s| s == "hz");
    let is_shape = segs.last().is_some_and(|s| s == "shape");
    let mut out = Vec::new();
    for text in values.split(',') {
        let text = text.trim();
        if text.is_empty() {
            return Err(format!("`{arg}` has an empty value"));
        }
        let value = match &target {
            Target::Timestep => {
                let v = number(text).ok_or_else(|| format!("`{text}` is not a number"))?;
                let dt = if hz {
                    Ratio::of(1.0 / v).filter(|_| v > 0.0)
                } else {
                    Ratio::of(v)
                };
                let dt = dt.ok_or_else(|| {
                    format!(
                        "`{text}`: a timestep must be > 0 and a fraction of a second with a \
                         denominator up to 1,000,000 (1/60, 0.02)"
                    )
                })?;
                Setting::Timestep {
                    text: text.to_owned(),
                    dt,
                }
            }
            Target::Field(_) if is_shape => {
                if text == "file" {
                    Setting::File
                } else {
                    Setting::Shape {
                        text: text.to_owned(),
                        table: shape::parse(text)?,
                    }
                }
            }
            Target::Field(_) if text == "file" => Setting::File,
            Target::Field(_) => Setting::Number {
                text: text.to_owned(),
                value: number(text).ok_or_else(|| {
                    format!("`{text}` is not a number (write 0.5, -30, 1e-3 or 1/60)")
                })?,
                integer: text.parse::<i64>().ok(),
            },
        };
        out.push(value);
    }
    Ok(Sweep {
        key,
        target,
        values: out,
    })
}

/// Writes one value into the document.
pub fn apply(doc: &mut DocumentMut, target: &Target, value: &Setting) -> Result<(), String> {
    match (target, value) {
        (_, Setting::File) => Ok(()),
        (Target::Timestep, Setting::Timestep { dt, .. }) => {
            set_timestep(doc, *dt);
            Ok(())
        }
        (Target::Field(path), _) => set_field(doc, path, &toml_value(value)),
        (Target::Timestep, _) => Err("a timestep takes a number".to_owned()),
    }
}

fn toml_value(value: &Setting) -> Value {
    match value {
        Setting::Number {
            integer: Some(i), ..
        } => Value::from(*i),
        Setting::Number { value, .. } => Value::from(*value),
        Setting::Timestep { dt, .. } => Value::from(dt.seconds()),
        Setting::Shape { table, .. } => Value::InlineTable(table.clone()),
        Setting::File => Value::from("file"),
    }
}

/// `hz = N` stays on its line when the step is `1/N`, so errors keep their line numbers;
/// otherwise `hz` gives way to `dt`.
fn set_timestep(doc: &mut DocumentMut, dt: Ratio) {
    let root = doc.as_table_mut();
    if root.contains_key("hz") {
        if dt.num == 1 {
            replace(root, "hz", Value::from(dt.den as i64));
            return;
        }
        root.remove("hz");
    }
    replace(root, "dt", Value::from(dt.seconds()));
}

/// Sets `key` in `table`, keeping the old value's spacing and comment, or adds it (an
/// unknown key is the loader's to refuse).
fn replace(table: &mut dyn TableLike, key: &str, mut value: Value) {
    if let Some(Item::Value(old)) = table.get(key) {
        *value.decor_mut() = old.decor().clone();
    }
    table.insert(key, Item::Value(value));
}

fn set_field(doc: &mut DocumentMut, path: &[String], value: &Value) -> Result<(), String> {
    let root = doc.as_table_mut();
    match path[0].as_str() {
        "frames" => {
            replace(root, "frames", value.clone());
            Ok(())
        }
        "world" => {
            let world = root
                .get_mut("world")
                .and_then(Item::as_table_like_mut)
                .ok_or("the file has no [world] table")?;
            walk(world, "world", &path[1..], value)
        }
        "templates" => {
            let name = &path[1];
            let templates = root.get_mut("templates").and_then(Item::as_table_like_mut);
            let names: Vec<String> = templates
                .as_ref()
                .map(|t| t.iter().map(|(k, _)| k.to_owned()).collect())
                .unwrap_or_default();
            let t = templates
                .and_then(|t| t.get_mut(name))
                .and_then(Item::as_table_like_mut)
                .ok_or_else(|| {
                    format!(
                        "the file has no template `{name}` (its templates: {})",
                        list(&names)
                    )
                })?;
            walk(t, &format!("templates.{name}"), &path[2..], value)
        }
        "bodies" => {
            let name = &path[1];
            let mut names = Vec::new();
            let mut found = 0;
            for body in entries(root.get_mut("bodies")) {
                let this = body_name(body);
                if this == *name {
                    walk(body, &format!("bodies.{name}"), &path[2..], value)?;
                    found += 1;
                } else if !names.contains(&this) {
                    names.push(this);
                }
            }
            if found == 0 {
                return Err(format!(
                    "the file has no body named `{name}` (its bodies: {})",
                    list(&names)
                ));
            }
            Ok(())
        }
        _ => Err(format!("`{}` is not a key: {ROOTS}", path.join("."))),
    }
}

fn list(names: &[String]) -> String {
    if names.is_empty() {
        "none".to_owned()
    } else {
        names.join(", ")
    }
}

/// A body's name as the loader gives it: `name`, else its template's, else `body`.
fn body_name(body: &dyn TableLike) -> String {
    ["name", "template"]
        .iter()
        .find_map(|k| body.get(k).and_then(Item::as_str))
        .unwrap_or("body")
        .to_owned()
}

/// The entries of an array of tables (`[[bodies]]`, `[[script]]`) or of an inline array of
/// tables (`script = [{…}, …]`).
pub fn entries(item: Option<&mut Item>) -> Vec<&mut dyn TableLike> {
    match item {
        Some(Item::ArrayOfTables(a)) => a.iter_mut().map(|t| t as &mut dyn TableLike).collect(),
        Some(Item::Value(Value::Array(a))) => a
            .iter_mut()
            .filter_map(|v| v.as_inline_table_mut().map(|t| t as &mut dyn TableLike))
            .collect(),
        _ => Vec::new(),
    }
}

/// Follows `rest` down from `table` (named `at`) and sets the last key; `.x`/`.y` after a
/// two-number array set one component.
fn walk(table: &mut dyn TableLike, at: &str, rest: &[String], value: &Value) -> Result<(), String> {
    match rest {
        [] => Err(format!("`{at}` is a table: name one of its fields")),
        [key] => {
            replace(table, key, value.clone());
            Ok(())
        }
        [key, axis] if axis == "x" || axis == "y" => {
            let here = format!("{at}.{key}");
            match table.get_mut(key) {
                Some(Item::Value(Value::Array(a))) if a.len() == 2 => {
                    let i = usize::from(axis == "y");
                    let mut v = value.clone();
                    *v.decor_mut() = a.get(i).map(|o| o.decor().clone()).unwrap_or_default();
                    a.replace(i, v);
                    Ok(())
                }
                Some(item) if item.is_table_like() => walk(
                    item.as_table_like_mut().ok_or("unreachable")?,
                    &here,
                    &rest[1..],
                    value,
                ),
                Some(_) => Err(format!("`{here}` is not an [x, y] pair in the file")),
                None => Err(format!(
                    "`{here}` is not in the file: write it there first (its .x and .y are \
                     swept from the file's values)"
                )),
            }
        }
        [key, ..] => {
            let here = format!("{at}.{key}");
            let inner = table
                .get_mut(key)
                .and_then(Item::as_table_like_mut)
                .ok_or_else(|| format!("`{here}` is not a table in the file"))?;
            walk(inner, &here, &rest[1..], value)
        }
    }
}

/// Rescales every frame count of the file by `factor` (the file's timestep over the run's),
/// so each keeps its time in seconds: `frames` (600 when absent), every script event's
/// `frame`, every `lifetime`, and `world.sleep_after`. Counts round to the nearest frame;
/// returns how many did not scale exactly. A count that is not a whole number ≥ 0 is left
/// for the loader to refuse.
pub fn rescale_frames(doc: &mut DocumentMut, factor: Ratio) -> u64 {
    if factor == (Ratio { num: 1, den: 1 }) {
        return 0;
    }
    let mut inexact = 0;
    let mut scale = |table: &mut dyn TableLike, key: &str, default: Option<i64>| {
        let old = match table.get(key) {
            Some(item) => item.as_integer(),
            None => default,
        };
        if let Some(n) = old.and_then(|n| u64::try_from(n).ok()) {
            let (new, exact) = factor.scale(n);
            inexact += u64::from(!exact);
            replace(
                table,
                key,
                Value::from(i64::try_from(new).unwrap_or(i64::MAX)),
            );
        }
    };
    let root = doc.as_table_mut();
    scale(root, "frames", Some(600));
    if let Some(world) = root.get_mut("world").and_then(Item::as_table_like_mut) {
        scale(world, "sleep_after", None);
    }
    if let Some(templates) = root.get_mut("templates").and_then(Item::as_table_like_mut) {
        for (_, t) in templates.iter_mut() {
            if let Some(t) = t.as_table_like_mut() {
                scale(t, "lifetime", None);
            }
        }
    }
    for body in entries(root.get_mut("bodies")) {
        scale(body, "lifetime", None);
    }
    for event in entries(root.get_mut("script")) {
        scale(event, "frame", None);
    }
    inexact
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_write_where_a_reader_looks() {
        let text = "hz = 60\nlayers = [\"a\"]\n[world]\ngravity = [0, -30] # down\n\
                    [templates.t]\nmass = 1\n[[bodies]]\nname = \"p\"\nposition = [1, 2]\n\
                    [[bodies]]\ntemplate = \"t\"\n";
        let mut doc: DocumentMut = text.parse().unwrap();
        let set = |doc: &mut DocumentMut, arg: &str| {
            let s = parse(arg).unwrap();
            apply(doc, &s.target, &s.values[0])
        };
        set(&mut doc, "world.gravity.y=-9.5").unwrap();
        set(&mut doc, "bodies.p.position.x=1/4").unwrap();
        set(&mut doc, "bodies.t.mass=2").unwrap();
        set(&mut doc, "templates.t.shape=circle:1").unwrap();
        set(&mut doc, "world.dt=1/120").unwrap();
        let out = doc.to_string();
        assert!(out.starts_with("hz = 120\n"), "{out}");
        assert!(out.contains("gravity = [0, -9.5] # down"), "{out}");
        assert!(out.contains("position = [0.25, 2]"), "{out}");
        assert!(out.contains("template = \"t\"\nmass = 2"), "{out}");
        assert!(
            out.contains(r#"shape = { kind = "circle", radius = 1.0 }"#),
            "{out}"
        );
        set(&mut doc, "dt=2/3").unwrap();
        assert!(doc.to_string().contains("dt = 0.666"), "{doc}");
        assert!(!doc.to_string().contains("hz"), "{doc}");
        assert!(
            set(&mut doc, "bodies.q.mass=1")
                .unwrap_err()
                .contains("its bodies: p, t")
        );
        assert!(
            set(&mut doc, "templates.x.mass=1")
                .unwrap_err()
                .contains("templates: t")
        );
        assert!(
            set(&mut doc, "world.gravity.z=1")
                .unwrap_err()
                .contains("not a table")
        );
        assert!(parse("wold.dt=1").is_err());
        assert!(parse("world.dt=0").is_err());
        assert!(parse("world.dt=abc").is_err());
    }
}
