//! Where a scenario error is: `file:line:column`, the field path, and the problem.

use std::ops::Range;

use ricochet_geom::Vec2;

pub use crate::check::ScenarioError;

pub(crate) struct Ctx<'a> {
    pub(crate) file: &'a str,
    pub(crate) text: &'a str,
}

impl Ctx<'_> {
    /// An error at `span`, narrowed to the line of `field`'s own key when that key is
    /// written inside the span (so `bodies[2].mass` points at `mass = -1`, not at
    /// `[[bodies]]`).
    pub(crate) fn err(
        &self,
        span: Range<usize>,
        field: impl Into<String>,
        problem: impl Into<String>,
    ) -> ScenarioError {
        let field = field.into();
        let start = self
            .key_in(&span, &field)
            .unwrap_or(span.start)
            .min(self.text.len());
        let before = &self.text[..start];
        let line = before.matches('\n').count() + 1;
        let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        ScenarioError {
            file: self.file.to_owned(),
            line,
            column,
            field,
            problem: problem.into(),
        }
    }

    /// The field path of the value at `offset`, from the text alone, for errors the TOML
    /// parser reports without one (an integer beyond `i64`, a wrong type): the table header
    /// above it, counted for arrays of tables (`bodies[1]`), then the keys leading to the
    /// offset on its line, inline tables included (`bodies[0].shape.radius`). Empty when the
    /// offset is not after a `key =`.
    pub(crate) fn field_at(&self, offset: usize) -> String {
        let offset = offset.min(self.text.len());
        let Some(line_start) = self
            .text
            .get(..offset)
            .map(|t| t.rfind('\n').map_or(0, |n| n + 1))
        else {
            return String::new();
        };
        let mut keys: Vec<&str> = Vec::new();
        let mut depth = 0usize;
        let line = &self.text[line_start..offset];
        let bytes = line.as_bytes();
        let mut k = 0;
        while k < bytes.len() {
            match bytes[k] {
                b'"' | b'\'' => {
                    let quote = bytes[k];
                    k += 1;
                    while k < bytes.len() && bytes[k] != quote {
                        k += if bytes[k] == b'\\' { 2 } else { 1 };
                    }
                }
                b'{' => depth += 1,
                b'}' => {
                    depth = depth.saturating_sub(1);
                    keys.truncate(depth + 1);
                }
                c if c.is_ascii_alphanumeric() || c == b'_' || c == b'-' => {
                    let start = k;
                    while k < bytes.len()
                        && (bytes[k].is_ascii_alphanumeric()
                            || bytes[k] == b'_'
                            || bytes[k] == b'-')
                    {
                        k += 1;
                    }
                    let rest = line[k..].trim_start();
                    if rest.starts_with('=') && !rest.starts_with("==") {
                        keys.truncate(depth);
                        keys.push(&line[start..k]);
                    }
                    continue;
                }
                _ => {}
            }
            k += 1;
        }
        if keys.is_empty() {
            return String::new();
        }
        let above = &self.text[..line_start];
        let header = above
            .lines()
            .rev()
            .map(str::trim)
            .find(|l| l.starts_with('['));
        let table = match header {
            Some(h) if h.starts_with("[[") => {
                let name = h
                    .trim_start_matches("[[")
                    .split("]]")
                    .next()
                    .unwrap_or("")
                    .trim();
                let count = above.lines().filter(|l| l.trim() == h).count();
                format!("{name}[{}]", count.saturating_sub(1))
            }
            Some(h) => h
                .trim_start_matches('[')
                .split(']')
                .next()
                .unwrap_or("")
                .trim()
                .to_owned(),
            None => String::new(),
        };
        let path = keys.join(".");
        if table.is_empty() {
            path
        } else {
            format!("{table}.{path}")
        }
    }

    /// Where the last key of `field` (`mass` in `bodies[2].mass`, `half_extents` in
    /// `bodies[0].shape.half_extents[1]`) is written as `key =` in the table at `span`.
    fn key_in(&self, span: &Range<usize>, field: &str) -> Option<usize> {
        let last = field.rsplit('.').next()?;
        let key = last.split('[').next()?;
        if key.is_empty() {
            return None;
        }
        // A table's span covers only its `[[header]]`: search on to the next header.
        let end = self.text[span.end.min(self.text.len())..]
            .find("\n[")
            .map_or(self.text.len(), |at| span.end + at);
        let text = self.text.get(span.start..end)?;
        let mut from = 0;
        while let Some(at) = text[from..].find(key) {
            let pos = from + at;
            let before = text[..pos].chars().next_back();
            let after = text[pos + key.len()..].trim_start();
            let starts_word = before.is_none_or(|c| !(c.is_alphanumeric() || c == '_'));
            if starts_word && after.starts_with('=') {
                return Some(span.start + pos);
            }
            from = pos + key.len();
        }
        None
    }
}

pub(crate) fn finite(v: f64) -> bool {
    v.is_finite()
}

/// A position within the coordinates the geometry accepts (`ricochet_geom::MAX_COORDINATE`).
pub(crate) fn within_world(
    fail: impl Fn(&str, String) -> ScenarioError,
    p: Vec2,
) -> Result<Vec2, ScenarioError> {
    if p.abs().max_element() > ricochet_geom::MAX_COORDINATE {
        return Err(fail(
            "position",
            format!(
                "{} is beyond ±{:e}, the largest coordinate Ricochet accepts",
                ricochet_geom::Numbers([p.x, p.y]),
                ricochet_geom::MAX_COORDINATE
            ),
        ));
    }
    Ok(p)
}

pub(crate) fn vec2(v: [f64; 2]) -> Vec2 {
    Vec2::new(v[0], v[1])
}

pub(crate) fn unknown<'a>(
    ctx: &Ctx<'_>,
    span: Range<usize>,
    field: String,
    what: &str,
    name: &str,
    known: impl Iterator<Item = &'a String>,
) -> ScenarioError {
    ctx.err(
        span,
        field,
        crate::check::problems::unknown_problem(what, name, known),
    )
}
