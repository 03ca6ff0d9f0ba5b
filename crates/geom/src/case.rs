//! The shared collision-case format (`{"cases": [...]}` or JSON lines of `{"id", "a", "b"}`),
//! read by `ricochet collide` and by the ground-truth tests.

use serde::Deserialize;

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
            Some(id) => format!("case {id}"),
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
    id: Option<serde_json::Value>,
    shape: ShapeDef,
    position: [f64; 2],
    #[serde(default)]
    angle: f64,
}

// Case files carry extra fields (`pair`, `scenario`, `truth`, from the shared ground-truth
// set): those are allowed and ignored; any other key is an error (a misspelt `angle` or a
// stray `tolerance` must not be silently dropped), here as inside a body or a shape.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CaseDef {
    #[serde(default, rename = "id")]
    _id: Option<serde::de::IgnoredAny>,
    #[serde(default, rename = "pair")]
    _pair: Option<serde::de::IgnoredAny>,
    #[serde(default, rename = "scenario")]
    _scenario: Option<serde::de::IgnoredAny>,
    #[serde(default, rename = "truth")]
    _truth: Option<serde::de::IgnoredAny>,
    a: BodyDef,
    b: BodyDef,
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

fn case(value: serde_json::Value, line: Option<usize>) -> Result<Case, CaseError> {
    let id = value.get("id").cloned();
    let fail = |field: String, problem: String| CaseError {
        id: id.clone(),
        line,
        field,
        problem,
    };
    // An unknown key's path ends with the key itself (`a.angel`); an empty key at the top
    // has an empty path, written `""`.
    let def: CaseDef = serde_path_to_error::deserialize(&value).map_err(|e| {
        let field = match e.path().to_string() {
            p if p.is_empty() => "\"\"".to_owned(),
            p => p,
        };
        fail(field, e.into_inner().to_string())
    })?;
    let Some(id) = id.clone() else {
        return Err(fail("id".to_owned(), "every case needs an id".to_owned()));
    };
    let a = body(&def.a, "a").map_err(|(f, p)| fail(f, p))?;
    let b = body(&def.b, "b").map_err(|(f, p)| fail(f, p))?;
    Ok(Case { id, a, b })
}

/// Reads a case file: a `{"cases": [...]}` document, or JSON lines of `{"id", "a", "b"}`.
/// Returns every case, or every error found (a bad case does not hide the next one).
pub fn parse_case_file(text: &str) -> Result<Vec<Case>, Vec<CaseError>> {
    let mut cases = Vec::new();
    let mut errors = Vec::new();
    let mut push = |r: Result<Case, CaseError>| match r {
        Ok(c) => cases.push(c),
        Err(e) => errors.push(e),
    };
    match serde_json::from_str::<serde_json::Value>(text) {
        Ok(serde_json::Value::Object(mut doc)) if doc.contains_key("cases") => {
            match doc.remove("cases") {
                Some(serde_json::Value::Array(list)) => {
                    for v in list {
                        push(case(v, None));
                    }
                }
                _ => push(Err(CaseError {
                    id: None,
                    line: None,
                    field: "cases".to_owned(),
                    problem: "must be a list of cases".to_owned(),
                })),
            }
        }
        _ => {
            for (i, line) in text.lines().enumerate() {
                if line.trim().is_empty() {
                    continue;
                }
                match serde_json::from_str::<serde_json::Value>(line) {
                    Ok(v) => push(case(v, Some(i + 1))),
                    Err(e) => push(Err(CaseError {
                        id: None,
                        line: Some(i + 1),
                        field: "json".to_owned(),
                        problem: format!("{e}"),
                    })),
                }
            }
        }
    }
    if errors.is_empty() {
        Ok(cases)
    } else {
        Err(errors)
    }
}
