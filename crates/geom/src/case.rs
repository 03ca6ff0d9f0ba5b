//! One case of the shared collision-case format (`{"id", "a", "b"}`, with the shared set's
//! `pair`, `scenario` and `truth`), read from its JSON text: `ricochet collide` and the
//! ground-truth tests read case files through [`crate::CaseReader`].

use serde::Deserialize;
use serde::de::{Deserializer, IgnoredAny, MapAccess, Visitor};

use crate::def::ShapeDef;
use crate::math::{Pose, Vec2};
use crate::shape::Shape;

/// One body of a case: a validated shape at a pose.
#[derive(Clone, Debug, PartialEq)]
pub struct CaseBody {
    /// The shape, local coordinates.
    pub shape: Shape,
    /// Where it is.
    pub pose: Pose,
}

/// One pair to collide.
#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    /// The case's id, echoed as given (a number or a string).
    pub id: serde_json::Value,
    /// Body `a`.
    pub a: CaseBody,
    /// Body `b`.
    pub b: CaseBody,
}

/// The longest text an error message quotes from the input (a key, a value, an id), in
/// characters: a longer one is cut, with its length in bytes.
pub const MAX_QUOTED: usize = 80;

/// The longest id a case may have, as a string, in bytes: ids are echoed on every output
/// line.
pub const MAX_ID_BYTES: usize = 256;

/// `text`, or its first [`MAX_QUOTED`] characters and its length when it is longer.
#[must_use]
pub(crate) fn cut(text: &str) -> String {
    match text.char_indices().nth(MAX_QUOTED) {
        None => text.to_owned(),
        Some((at, _)) => format!("{}... ({} bytes)", &text[..at], text.len()),
    }
}

/// Why a case could not be read. Printed as `case ID (line N): FIELD: PROBLEM`.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{}{}: {field}: {problem}", self.case_label(), self.line_label())]
pub struct CaseError {
    /// The case id, when it could be read.
    pub id: Option<serde_json::Value>,
    /// 1-based line of the case in a JSON-lines file, or of a syntax error.
    pub line: Option<usize>,
    /// Path of the offending field (`b.shape.vertices`), or `json` for a syntax error.
    pub field: String,
    /// What is wrong.
    pub problem: String,
}

impl CaseError {
    fn case_label(&self) -> String {
        match &self.id {
            Some(id) => format!("case {}", cut(&id.to_string())),
            None => "input".to_owned(),
        }
    }

    fn line_label(&self) -> String {
        self.line
            .map(|l| format!(" (line {l})"))
            .unwrap_or_default()
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BodyDef {
    #[serde(default)]
    #[expect(
        dead_code,
        reason = "the cases carry a body id; only the pair's id is echoed"
    )]
    id: Option<Id>,
    shape: ShapeDef,
    position: [f64; 2],
    #[serde(default)]
    angle: f64,
}

// Case files carry extra fields (`pair`, `scenario`, `truth`, from the shared ground-truth
// set): those are allowed, checked for their type and ignored; any other key is an error (a
// misspelt `angle` or a stray `tolerance` must not be silently dropped), here as inside a body
// or a shape, and so is a key given twice (which would otherwise silently win).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CaseDef {
    #[serde(default)]
    id: Option<Id>,
    #[serde(default, rename = "pair")]
    _pair: Option<String>,
    #[serde(default, rename = "scenario")]
    _scenario: Option<String>,
    #[serde(default, rename = "truth")]
    _truth: Option<Object>,
    a: BodyDef,
    b: BodyDef,
}

/// An id: a number, or a string of at most [`MAX_ID_BYTES`].
struct Id(serde_json::Value);

impl<'de> Deserialize<'de> for Id {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Id, D::Error> {
        use serde::de::Error;
        match serde_json::Value::deserialize(d)? {
            v @ serde_json::Value::Number(_) => Ok(Id(v)),
            serde_json::Value::String(s) if s.len() > MAX_ID_BYTES => {
                Err(D::Error::custom(format!(
                    "an id is at most {MAX_ID_BYTES} bytes, this one is {} ({})",
                    s.len(),
                    cut(&s)
                )))
            }
            v @ serde_json::Value::String(_) => Ok(Id(v)),
            other => Err(D::Error::custom(format!(
                "an id is a number or a string, not {}",
                kind(&other)
            ))),
        }
    }
}

/// Any JSON object, its contents ignored (the shared set's `truth`).
struct Object;

impl<'de> Deserialize<'de> for Object {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Object, D::Error> {
        struct Any;
        impl<'de> Visitor<'de> for Any {
            type Value = Object;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("an object")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Object, A::Error> {
                while map.next_entry::<IgnoredAny, IgnoredAny>()?.is_some() {}
                Ok(Object)
            }
        }
        d.deserialize_map(Any)
    }
}

/// What kind of JSON value `v` is, for messages.
fn kind(v: &serde_json::Value) -> &'static str {
    match v {
        serde_json::Value::Null => "null",
        serde_json::Value::Bool(_) => "a boolean",
        serde_json::Value::Number(_) => "a number",
        serde_json::Value::String(_) => "a string",
        serde_json::Value::Array(_) => "an array",
        serde_json::Value::Object(_) => "an object",
    }
}

fn body(def: &BodyDef, name: &str) -> Result<CaseBody, (String, String)> {
    let shape = def
        .shape
        .to_shape()
        .map_err(|e| e.within(&format!("{name}.shape")))
        .map_err(|e| (e.field, e.problem))?;
    for (i, v) in def.position.iter().enumerate() {
        if !(v.is_finite() && v.abs() <= crate::MAX_COORDINATE) {
            return Err((
                format!("{name}.position[{i}]"),
                format!(
                    "must be a finite number within ±{:e}, got {}",
                    crate::MAX_COORDINATE,
                    crate::Number(*v)
                ),
            ));
        }
    }
    if !def.angle.is_finite() {
        return Err((
            format!("{name}.angle"),
            "must be a finite number".to_owned(),
        ));
    }
    Ok(CaseBody {
        shape,
        pose: Pose::new(Vec2::new(def.position[0], def.position[1]), def.angle),
    })
}

/// The id of a case that could not be read whole, if it has a readable one.
fn id_of(text: &[u8]) -> Option<serde_json::Value> {
    #[derive(Deserialize)]
    struct IdOnly {
        #[serde(default)]
        id: Option<Id>,
    }
    serde_json::from_slice::<IdOnly>(text)
        .ok()
        .and_then(|c| c.id)
        .map(|id| id.0)
}

/// Reads one case from its JSON text (`line`: where it starts in its file, 1-based).
pub fn parse_case(text: &[u8], line: Option<usize>) -> Result<Case, CaseError> {
    let fail = |id: Option<serde_json::Value>, field: &str, problem: &str| CaseError {
        id,
        line,
        field: cut(field),
        problem: cut_quoted(problem),
    };
    let first = text.iter().find(|b| !b.is_ascii_whitespace());
    if first != Some(&b'{') {
        let what = match serde_json::from_slice::<serde_json::Value>(text) {
            Ok(v) => kind(&v).to_owned(),
            Err(_) => format!("{:?}", cut(&String::from_utf8_lossy(text))),
        };
        return Err(fail(
            None,
            "case",
            &format!("a case is a JSON object {{\"id\", \"a\", \"b\"}}, not {what}"),
        ));
    }
    // An unknown key's path ends with the key itself (`a.angel`); an empty key at the top
    // has an empty path, written `""`.
    let mut de = serde_json::Deserializer::from_slice(text);
    let def: CaseDef = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let mut field = e.path().to_string();
        if field == "." {
            field.clear();
        }
        let inner = e.into_inner();
        let mut problem = inner.to_string();
        // A wrong value's position inside the case says nothing the field does not.
        if inner.classify() == serde_json::error::Category::Data
            && let Some(at) = problem.rfind(" at line ")
        {
            problem.truncate(at);
        }
        // A key given twice is reported at the object that holds it: name the key.
        if let Some(key) = problem
            .strip_prefix("duplicate field `")
            .and_then(|rest| rest.split('`').next())
        {
            field = if field.is_empty() {
                key.to_owned()
            } else {
                format!("{field}.{key}")
            };
        }
        if field.is_empty() {
            field = "\"\"".to_owned();
        }
        fail(id_of(text), &field, &problem)
    })?;
    de.end()
        .map_err(|e| fail(id_of(text), "json", &e.to_string()))?;
    let Some(Id(id)) = def.id else {
        return Err(fail(None, "id", "every case needs an id"));
    };
    let a = body(&def.a, "a").map_err(|(f, p)| fail(Some(id.clone()), &f, &p))?;
    let b = body(&def.b, "b").map_err(|(f, p)| fail(Some(id.clone()), &f, &p))?;
    Ok(Case { id, a, b })
}

/// A problem as serde words it, any quoted text in it cut (an unknown key or variant is
/// quoted whole: a 100 MB one must not become a 100 MB message).
fn cut_quoted(problem: &str) -> String {
    if problem.len() <= 4 * MAX_QUOTED {
        return problem.to_owned();
    }
    let mut out = String::new();
    let mut rest = problem;
    while let Some(open) = rest.find(['`', '"']) {
        let quote = &rest[open..=open];
        out += &rest[..=open];
        let after = &rest[open + 1..];
        match after.find(quote) {
            Some(close) => {
                out += &cut(&after[..close]);
                out += quote;
                rest = &after[close + 1..];
            }
            None => {
                out += &cut(after);
                rest = "";
            }
        }
    }
    out += &cut(rest);
    out
}

/// Reads a whole case file held in memory: a `{"cases": [...]}` document, or JSON lines of
/// `{"id", "a", "b"}` (see [`crate::CaseReader`], which reads one from any reader in bounded
/// memory). Returns every case, or every error found (a bad case does not hide the next one).
pub fn parse_case_file(text: &str) -> Result<Vec<Case>, Vec<CaseError>> {
    let mut cases = Vec::new();
    let mut errors = Vec::new();
    for item in crate::CaseReader::new(text.as_bytes()) {
        match item {
            Ok(c) => cases.push(c),
            Err(e) => errors.push(e),
        }
    }
    if errors.is_empty() {
        Ok(cases)
    } else {
        Err(errors)
    }
}
