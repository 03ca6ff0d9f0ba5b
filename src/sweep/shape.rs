//! The short form of a shape on the command line, for sweeping a collider:
//!
//! | short form                     | scenario file                                          |
//! |--------------------------------|--------------------------------------------------------|
//! | `circle:R`                     | `{ kind = "circle", radius = R }`                      |
//! | `aabb:HX HY`                   | `{ kind = "aabb", half_extents = [HX, HY] }`           |
//! | `obb:HX HY` or `obb:HX HY A`   | `{ kind = "obb", half_extents = [HX, HY], angle = A }` |
//! | `capsule:R;AX AY;BX BY`        | `{ kind = "capsule", radius = R, a = [AX, AY], b = [BX, BY] }` |
//! | `polygon:X1 Y1;X2 Y2;X3 Y3...` | `{ kind = "polygon", vertices = [[X1, Y1], ...] }`     |
//!
//! Numbers may be fractions (`1/3`). Points are separated by `;` and coordinates by a space,
//! so quote the argument in a shell. Only the form is read here: the shape goes into the
//! scenario file and the loader checks it (a concave polygon, a radius of 0) like any other.

use toml_edit::{Array, InlineTable, Value};

use super::set::number;

/// The scenario file's inline table for a short form, or what is wrong with it.
pub fn parse(text: &str) -> Result<InlineTable, String> {
    let (kind, rest) = text.split_once(':').ok_or_else(|| {
        format!("`{text}` is not a shape: write circle:R, aabb:HX HY, obb:HX HY, capsule:R;AX AY;BX BY or polygon:X1 Y1;X2 Y2;...")
    })?;
    let kind = kind.trim();
    let nums = |part: &str| -> Result<Vec<f64>, String> {
        part.split_whitespace()
            .map(|n| number(n).ok_or_else(|| format!("`{n}` in `{text}` is not a number")))
            .collect()
    };
    let point = |part: &str| -> Result<Array, String> {
        match nums(part)?.as_slice() {
            &[x, y] => Ok(Array::from_iter([x, y])),
            _ => Err(format!(
                "`{}` in `{text}` is not a point `X Y`",
                part.trim()
            )),
        }
    };
    let mut t = InlineTable::new();
    t.insert("kind", Value::from(kind));
    match kind {
        "circle" => match nums(rest)?.as_slice() {
            &[r] => {
                t.insert("radius", Value::from(r));
            }
            _ => return Err(format!("`{text}`: a circle is circle:RADIUS")),
        },
        "aabb" => {
            t.insert("half_extents", Value::Array(point(rest)?));
        }
        "obb" => match *nums(rest)?.as_slice() {
            [hx, hy] => {
                t.insert("half_extents", Value::Array(Array::from_iter([hx, hy])));
            }
            [hx, hy, angle] => {
                t.insert("half_extents", Value::Array(Array::from_iter([hx, hy])));
                t.insert("angle", Value::from(angle));
            }
            _ => return Err(format!("`{text}`: an obb is obb:HX HY or obb:HX HY ANGLE")),
        },
        "capsule" => {
            let parts: Vec<&str> = rest.split(';').collect();
            let [r, a, b] = parts.as_slice() else {
                return Err(format!("`{text}`: a capsule is capsule:RADIUS;AX AY;BX BY"));
            };
            let &[r] = nums(r)?.as_slice() else {
                return Err(format!("`{text}`: a capsule is capsule:RADIUS;AX AY;BX BY"));
            };
            t.insert("radius", Value::from(r));
            t.insert("a", Value::Array(point(a)?));
            t.insert("b", Value::Array(point(b)?));
        }
        "polygon" => {
            let mut vertices = Array::new();
            for p in rest.split(';') {
                vertices.push(Value::Array(point(p)?));
            }
            t.insert("vertices", Value::Array(vertices));
        }
        other => {
            return Err(format!(
                "`{other}` is not a shape kind: circle, aabb, obb, capsule or polygon"
            ));
        }
    }
    Ok(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn short_forms_become_the_files_tables() {
        let s = |t: &str| parse(t).unwrap().to_string();
        assert_eq!(s("circle:1.2"), r#"{ kind = "circle", radius = 1.2 }"#);
        assert_eq!(
            s("aabb:0.4 0.8"),
            r#"{ kind = "aabb", half_extents = [0.4, 0.8] }"#
        );
        assert_eq!(
            s("capsule:0.5;-1 0;1 0"),
            r#"{ kind = "capsule", radius = 0.5, a = [-1.0, 0.0], b = [1.0, 0.0] }"#
        );
        assert_eq!(
            s("polygon:1.2 0;-0.8 0.7;-0.8 -0.7"),
            r#"{ kind = "polygon", vertices = [[1.2, 0.0], [-0.8, 0.7], [-0.8, -0.7]] }"#
        );
        assert!(parse("square:1").is_err());
        assert!(parse("circle:1 2").is_err());
        assert!(parse("polygon:1 0;2").is_err());
    }
}
