//! Tiled JSON (`.tmj`/`.json` maps, `.tsj` tilesets, `.tj` templates) → the equivalent TMX
//! text, so the `tiled` crate reads both forms. Tile data is passed through as written (a
//! number array becomes CSV; a base64 string keeps its encoding and compression), external
//! tilesets and templates keep their file names (the reader converts them in turn).
//!
//! Objects are strict: a key this converter does not know (a new shape kind) is refused,
//! since skipping it could drop a wall. Unknown map, layer and tileset keys (editor settings)
//! are ignored.

use std::fmt::Write;
use std::path::Path;

use serde_json::{Map, Value};

type Obj = Map<String, Value>;

/// The keys an object may have.
const OBJECT_KEYS: &[&str] = &[
    "id",
    "name",
    "type",
    "class",
    "x",
    "y",
    "width",
    "height",
    "rotation",
    "visible",
    "gid",
    "ellipse",
    "point",
    "polygon",
    "polyline",
    "text",
    "template",
    "properties",
    "capsule",
];

fn esc(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out
}

/// A value as an attribute's text (strings unquoted, numbers as written).
fn text(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        Value::Bool(b) => if *b { "1" } else { "0" }.to_owned(),
        other => other.to_string(),
    }
}

/// ` key="value"` for each key present (JSON name → TMX name).
fn attrs(o: &Obj, keys: &[(&str, &str)]) -> String {
    let mut s = String::new();
    for (json, tmx) in keys {
        if let Some(v) = o.get(*json)
            && !v.is_null()
        {
            let _ = write!(s, " {tmx}=\"{}\"", esc(&text(v)));
        }
    }
    s
}

/// Converts one JSON file to TMX text; `path` says which kind (by extension) and names it in
/// errors.
pub fn to_tmx(json: &str, path: &Path) -> Result<String, String> {
    let v: Value = serde_json::from_str(json).map_err(|e| format!("not Tiled JSON: {e}"))?;
    let Value::Object(o) = v else {
        return Err("not Tiled JSON: the file is not an object".to_owned());
    };
    let mut out = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    match path.extension().and_then(|e| e.to_str()) {
        Some("tsj") => tileset(&o, &mut out, false)?,
        Some("tj") => {
            out.push_str("<template>");
            if let Some(Value::Object(t)) = o.get("tileset") {
                tileset(t, &mut out, true)?;
            }
            let Some(Value::Object(obj)) = o.get("object") else {
                return Err("a template without an `object`".to_owned());
            };
            object(obj, &mut out)?;
            out.push_str("</template>");
        }
        _ => map(&o, &mut out)?,
    }
    Ok(out)
}

fn map(o: &Obj, out: &mut String) -> Result<(), String> {
    let mut a = attrs(
        o,
        &[
            ("version", "version"),
            ("orientation", "orientation"),
            ("renderorder", "renderorder"),
            ("width", "width"),
            ("height", "height"),
            ("tilewidth", "tilewidth"),
            ("tileheight", "tileheight"),
            ("infinite", "infinite"),
            ("class", "class"),
        ],
    );
    if !o.contains_key("orientation") {
        a.push_str(" orientation=\"orthogonal\"");
    }
    // The `tiled` crate requires a version; Tiled always writes one, a generator may not.
    if !o.contains_key("version") {
        a.push_str(" version=\"1.10\"");
    }
    let _ = write!(out, "<map{a}>");
    properties(o, out);
    for t in array(o, "tilesets") {
        tileset(t, out, true)?;
    }
    for l in array(o, "layers") {
        layer(l, out)?;
    }
    out.push_str("</map>");
    Ok(())
}

fn array<'a>(o: &'a Obj, key: &str) -> impl Iterator<Item = &'a Obj> {
    o.get(key)
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
        .filter_map(Value::as_object)
}

fn properties(o: &Obj, out: &mut String) {
    let props: Vec<&Obj> = array(o, "properties").collect();
    if props.is_empty() {
        return;
    }
    out.push_str("<properties>");
    for p in props {
        // A bool property is `true`/`false` in TMX (elsewhere a flag is 1/0).
        let value = match p.get("value") {
            Some(Value::Bool(b)) => format!(" value=\"{b}\""),
            Some(v) => format!(" value=\"{}\"", esc(&text(v))),
            None => String::new(),
        };
        let _ = write!(
            out,
            "<property{}{value}/>",
            attrs(p, &[("name", "name"), ("type", "type")])
        );
    }
    out.push_str("</properties>");
}

fn tileset(o: &Obj, out: &mut String, in_map: bool) -> Result<(), String> {
    if in_map && let Some(src) = o.get("source") {
        let _ = write!(
            out,
            "<tileset{} source=\"{}\"/>",
            attrs(o, &[("firstgid", "firstgid")]),
            esc(&text(src))
        );
        return Ok(());
    }
    let mut a = attrs(
        o,
        &[
            ("firstgid", "firstgid"),
            ("name", "name"),
            ("tilewidth", "tilewidth"),
            ("tileheight", "tileheight"),
            ("tilecount", "tilecount"),
            ("columns", "columns"),
            ("spacing", "spacing"),
            ("margin", "margin"),
            ("class", "class"),
        ],
    );
    if !o.contains_key("name") {
        a.push_str(" name=\"\"");
    }
    let _ = write!(out, "<tileset{a}>");
    if let Some(Value::Object(off)) = o.get("tileoffset") {
        let _ = write!(
            out,
            "<tileoffset{}/>",
            attrs(off, &[("x", "x"), ("y", "y")])
        );
    }
    if o.contains_key("image") {
        let _ = write!(
            out,
            "<image{}/>",
            attrs(
                o,
                &[
                    ("image", "source"),
                    ("imagewidth", "width"),
                    ("imageheight", "height")
                ]
            )
        );
    }
    properties(o, out);
    for t in array(o, "tiles") {
        let _ = write!(
            out,
            "<tile{}>",
            attrs(
                t,
                &[
                    ("id", "id"),
                    ("type", "type"),
                    ("class", "type"),
                    ("probability", "probability")
                ]
            )
        );
        properties(t, out);
        if let Some(Value::Object(g)) = t.get("objectgroup") {
            out.push_str("<objectgroup>");
            for obj in array(g, "objects") {
                object(obj, out)?;
            }
            out.push_str("</objectgroup>");
        }
        out.push_str("</tile>");
    }
    out.push_str("</tileset>");
    Ok(())
}

const LAYER_KEYS: &[(&str, &str)] = &[
    ("id", "id"),
    ("name", "name"),
    ("class", "class"),
    ("visible", "visible"),
    ("opacity", "opacity"),
    ("offsetx", "offsetx"),
    ("offsety", "offsety"),
];

fn layer(o: &Obj, out: &mut String) -> Result<(), String> {
    let kind = o.get("type").and_then(Value::as_str).unwrap_or("");
    let name = o.get("name").map(text).unwrap_or_default();
    match kind {
        "tilelayer" => {
            let _ = write!(
                out,
                "<layer{}{}>",
                attrs(o, LAYER_KEYS),
                attrs(o, &[("width", "width"), ("height", "height")])
            );
            properties(o, out);
            let enc = attrs(
                o,
                &[("encoding", "encoding"), ("compression", "compression")],
            );
            let csv = !o.contains_key("encoding")
                || o.get("encoding").and_then(Value::as_str) == Some("csv");
            let _ = write!(
                out,
                "<data{}>",
                if csv {
                    " encoding=\"csv\"".to_owned()
                } else {
                    enc
                }
            );
            let data = |d: Option<&Value>| -> Result<String, String> {
                match d {
                    Some(Value::Array(a)) => Ok(a.iter().map(text).collect::<Vec<_>>().join(",")),
                    Some(Value::String(s)) => Ok(esc(s)),
                    _ => Err(format!(
                        "layer \"{name}\": tile data is neither an array nor a string"
                    )),
                }
            };
            if let Some(Value::Array(chunks)) = o.get("chunks") {
                for c in chunks.iter().filter_map(Value::as_object) {
                    let _ = write!(
                        out,
                        "<chunk{}>{}</chunk>",
                        attrs(
                            c,
                            &[
                                ("x", "x"),
                                ("y", "y"),
                                ("width", "width"),
                                ("height", "height")
                            ]
                        ),
                        data(c.get("data"))?
                    );
                }
            } else {
                out.push_str(&data(o.get("data"))?);
            }
            out.push_str("</data></layer>");
        }
        "objectgroup" => {
            let _ = write!(out, "<objectgroup{}>", attrs(o, LAYER_KEYS));
            properties(o, out);
            for obj in array(o, "objects") {
                object(obj, out).map_err(|e| format!("layer \"{name}\": {e}"))?;
            }
            out.push_str("</objectgroup>");
        }
        "group" => {
            let _ = write!(out, "<group{}>", attrs(o, LAYER_KEYS));
            properties(o, out);
            for l in array(o, "layers") {
                layer(l, out)?;
            }
            out.push_str("</group>");
        }
        "imagelayer" => {
            let _ = write!(out, "<imagelayer{}/>", attrs(o, LAYER_KEYS));
        }
        other => return Err(format!("layer \"{name}\": unknown layer type \"{other}\"")),
    }
    Ok(())
}

fn object(o: &Obj, out: &mut String) -> Result<(), String> {
    let id = o.get("id").map(text).unwrap_or_default();
    if let Some(k) = o.keys().find(|k| !OBJECT_KEYS.contains(&k.as_str())) {
        return Err(format!(
            "object {id}: unknown key \"{k}\" (a shape kind or field this reader does not know); \
             remove it or save the map as TMX"
        ));
    }
    let a = attrs(
        o,
        &[
            ("id", "id"),
            ("name", "name"),
            ("type", "type"),
            ("class", "class"),
            ("x", "x"),
            ("y", "y"),
            ("width", "width"),
            ("height", "height"),
            ("rotation", "rotation"),
            ("visible", "visible"),
            ("gid", "gid"),
            ("template", "template"),
        ],
    );
    let _ = write!(out, "<object{a}>");
    properties(o, out);
    let flag = |k: &str| o.get(k).and_then(Value::as_bool) == Some(true);
    if flag("ellipse") {
        out.push_str("<ellipse/>");
    }
    if flag("point") {
        out.push_str("<point/>");
    }
    if flag("capsule") {
        out.push_str("<capsule/>");
    }
    for kind in ["polygon", "polyline"] {
        if let Some(Value::Array(pts)) = o.get(kind) {
            let points: Vec<String> = pts
                .iter()
                .filter_map(Value::as_object)
                .map(|p| {
                    format!(
                        "{},{}",
                        p.get("x").map(text).unwrap_or_default(),
                        p.get("y").map(text).unwrap_or_default()
                    )
                })
                .collect();
            let _ = write!(out, "<{kind} points=\"{}\"/>", esc(&points.join(" ")));
        }
    }
    if let Some(Value::Object(t)) = o.get("text") {
        let _ = write!(
            out,
            "<text>{}</text>",
            esc(&t.get("text").map(text).unwrap_or_default())
        );
    }
    out.push_str("</object>");
    Ok(())
}
