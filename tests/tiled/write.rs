//! A small generator of Tiled maps: one level (tiles with flips, and objects of every kind)
//! written in each form Tiled saves (TMX with every tile encoding, infinite TMX, JSON with an
//! external tileset and a template).

use std::io::Write;

use base64::Engine;
use serde_json::{Value, json};

/// Tiles are 10 × 10 px; the finite map is `W` × `H` tiles.
pub const TILE: f64 = 10.0;
pub const W: i32 = 12;
pub const H: i32 = 8;

/// Tiled's gid flag bits.
pub const FLIP_H: u32 = 0x8000_0000;
pub const FLIP_V: u32 = 0x4000_0000;
pub const FLIP_D: u32 = 0x2000_0000;

/// The tiles: cell (x, y) (y down) and gid with flags. gid 1: whole cell; gid 2: the
/// triangle (0,10) (10,10) (10,0); gid 3: the rectangle x 2..8, y 4..10.
pub fn tiles() -> Vec<(i32, i32, u32)> {
    let mut t = Vec::new();
    for x in 0..W {
        t.push((x, 7, 1));
    }
    for x in 3..7 {
        t.push((x, 4, 1));
    }
    t.push((0, 6, 2));
    t.push((1, 6, 2 | FLIP_H));
    t.push((2, 6, 2 | FLIP_V));
    t.push((3, 6, 2 | FLIP_D));
    t.push((4, 6, 2 | FLIP_H | FLIP_D));
    t.push((5, 6, 3));
    t.push((6, 6, 3 | FLIP_D));
    t.push((7, 6, 3 | FLIP_V | FLIP_H));
    t
}

/// A map object, in pixels (y down).
#[derive(Clone, Debug)]
pub enum Obj {
    Rect {
        x: f64,
        y: f64,
        w: f64,
        h: f64,
        rot: f64,
    },
    Ellipse {
        x: f64,
        y: f64,
        w: f64,
        h: f64,
    },
    Polygon {
        x: f64,
        y: f64,
        points: Vec<(f64, f64)>,
    },
    /// A tile object of gid 2 (the triangle), anchored at its bottom-left corner.
    Tile {
        x: f64,
        y: f64,
        w: f64,
        h: f64,
    },
}

pub fn objects() -> Vec<Obj> {
    vec![
        Obj::Rect {
            x: 5.0,
            y: 5.0,
            w: 20.0,
            h: 10.0,
            rot: 0.0,
        },
        Obj::Rect {
            x: 40.0,
            y: 2.0,
            w: 16.0,
            h: 8.0,
            rot: 30.0,
        },
        Obj::Ellipse {
            x: 70.0,
            y: 2.0,
            w: 12.0,
            h: 12.0,
        },
        Obj::Ellipse {
            x: 90.0,
            y: 2.0,
            w: 24.0,
            h: 8.0,
        },
        // A convex pentagon of 5 points.
        Obj::Polygon {
            x: 10.0,
            y: 20.0,
            points: vec![
                (0.0, 0.0),
                (12.0, -2.0),
                (16.0, 8.0),
                (6.0, 14.0),
                (-3.0, 8.0),
            ],
        },
        // A concave "U".
        Obj::Polygon {
            x: 60.0,
            y: 20.0,
            points: vec![
                (0.0, 0.0),
                (6.0, 0.0),
                (6.0, 12.0),
                (14.0, 12.0),
                (14.0, 0.0),
                (20.0, 0.0),
                (20.0, 18.0),
                (0.0, 18.0),
            ],
        },
        Obj::Tile {
            x: 100.0,
            y: 40.0,
            w: 20.0,
            h: 20.0,
        },
    ]
}

/// How a tile layer's data is written.
#[derive(Clone, Copy, Debug)]
pub enum Encoding {
    Csv,
    Base64,
    Zlib,
    Gzip,
    Zstd,
    Xml,
}

fn gids_of(cells: &[(i32, i32, u32)], x0: i32, y0: i32, w: i32, h: i32) -> Vec<u32> {
    let mut g = vec![0u32; (w * h) as usize];
    for &(x, y, gid) in cells {
        if (x0..x0 + w).contains(&x) && (y0..y0 + h).contains(&y) {
            g[((y - y0) * w + (x - x0)) as usize] = gid;
        }
    }
    g
}

fn encode(gids: &[u32], enc: Encoding, w: i32) -> (String, String) {
    let bytes: Vec<u8> = gids.iter().flat_map(|g| g.to_le_bytes()).collect();
    let b64 = |b: &[u8]| base64::engine::general_purpose::STANDARD.encode(b);
    match enc {
        Encoding::Csv => (
            " encoding=\"csv\"".into(),
            gids.chunks(w as usize)
                .map(|r| r.iter().map(u32::to_string).collect::<Vec<_>>().join(","))
                .collect::<Vec<_>>()
                .join(",\n"),
        ),
        Encoding::Base64 => (" encoding=\"base64\"".into(), b64(&bytes)),
        Encoding::Zlib => {
            let mut e = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
            e.write_all(&bytes).unwrap();
            (
                " encoding=\"base64\" compression=\"zlib\"".into(),
                b64(&e.finish().unwrap()),
            )
        }
        Encoding::Gzip => {
            let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
            e.write_all(&bytes).unwrap();
            (
                " encoding=\"base64\" compression=\"gzip\"".into(),
                b64(&e.finish().unwrap()),
            )
        }
        Encoding::Zstd => (
            " encoding=\"base64\" compression=\"zstd\"".into(),
            b64(&zstd::encode_all(&bytes[..], 0).unwrap()),
        ),
        Encoding::Xml => (
            String::new(),
            gids.iter()
                .map(|g| format!("<tile gid=\"{g}\"/>"))
                .collect(),
        ),
    }
}

/// The tileset's tiles as TMX (the collision groups of gids 2 and 3).
pub const TSX_TILES: &str = r#"<tile id="0" type="ground"/>
<tile id="1"><properties><property name="solid" type="bool" value="true"/></properties><objectgroup><object id="1" x="0" y="0"><polygon points="0,10 10,10 10,0"/></object></objectgroup></tile>
<tile id="2"><objectgroup><object id="1" x="2" y="4" width="6" height="6"/></objectgroup></tile>"#;

pub fn tileset_xml(inner_attrs: &str) -> String {
    format!(
        "<tileset{inner_attrs} name=\"t\" tilewidth=\"10\" tileheight=\"10\" tilecount=\"3\" columns=\"3\">{TSX_TILES}</tileset>"
    )
}

fn objects_xml(template: Option<&str>) -> String {
    let mut s = String::new();
    for (i, o) in objects().iter().enumerate() {
        let id = i + 1;
        match o {
            Obj::Rect { x, y, w, h, rot } => {
                s += &format!(
                    "<object id=\"{id}\" x=\"{x}\" y=\"{y}\" width=\"{w}\" height=\"{h}\" rotation=\"{rot}\"/>"
                );
            }
            Obj::Ellipse { x, y, w, h } => {
                s += &format!(
                    "<object id=\"{id}\" x=\"{x}\" y=\"{y}\" width=\"{w}\" height=\"{h}\"><ellipse/></object>"
                );
            }
            Obj::Polygon { x, y, points } => {
                let p: Vec<String> = points.iter().map(|(a, b)| format!("{a},{b}")).collect();
                s += &format!(
                    "<object id=\"{id}\" x=\"{x}\" y=\"{y}\"><polygon points=\"{}\"/></object>",
                    p.join(" ")
                );
            }
            Obj::Tile { x, y, w, h } => match template {
                // The template gives the gid and the size.
                Some(t) => {
                    s += &format!("<object id=\"{id}\" template=\"{t}\" x=\"{x}\" y=\"{y}\"/>")
                }
                None => {
                    s += &format!(
                        "<object id=\"{id}\" gid=\"2\" x=\"{x}\" y=\"{y}\" width=\"{w}\" height=\"{h}\"/>"
                    )
                }
            },
        }
    }
    s
}

/// A finite TMX map; `tileset` is the `<tileset>` element (embedded or a `source`).
pub fn tmx(enc: Encoding, tileset: &str, template: Option<&str>) -> String {
    let (attrs, data) = encode(&gids_of(&tiles(), 0, 0, W, H), enc, W);
    format!(
        "<?xml version=\"1.0\"?>\n<map version=\"1.10\" orientation=\"orthogonal\" renderorder=\"right-down\" \
         width=\"{W}\" height=\"{H}\" tilewidth=\"10\" tileheight=\"10\" infinite=\"0\">{tileset}\
         <layer id=\"1\" name=\"Ground\" width=\"{W}\" height=\"{H}\"><data{attrs}>{data}</data></layer>\
         <objectgroup id=\"2\" name=\"Shapes\">{}</objectgroup></map>",
        objects_xml(template)
    )
}

/// An infinite TMX map holding the same tiles moved by (`dx`, `dy`) cells, in 16 × 16 chunks.
pub fn infinite_tmx(enc: Encoding, dx: i32, dy: i32) -> String {
    let cells: Vec<(i32, i32, u32)> = tiles()
        .into_iter()
        .map(|(x, y, g)| (x + dx, y + dy, g))
        .collect();
    let mut chunks = String::new();
    for cy in [-1, 0] {
        for cx in [-1, 0] {
            let (attrs, data) = encode(&gids_of(&cells, cx * 16, cy * 16, 16, 16), enc, 16);
            let _ = &attrs;
            chunks += &format!(
                "<chunk x=\"{}\" y=\"{}\" width=\"16\" height=\"16\">{data}</chunk>",
                cx * 16,
                cy * 16
            );
        }
    }
    let (attrs, _) = encode(&[0], enc, 1);
    format!(
        "<?xml version=\"1.0\"?>\n<map version=\"1.10\" orientation=\"orthogonal\" renderorder=\"right-down\" \
         width=\"{W}\" height=\"{H}\" tilewidth=\"10\" tileheight=\"10\" infinite=\"1\">{}\
         <layer id=\"1\" name=\"Ground\" width=\"{W}\" height=\"{H}\"><data{attrs}>{chunks}</data></layer>\
         <objectgroup id=\"2\" name=\"Shapes\">{}</objectgroup></map>",
        tileset_xml(" firstgid=\"1\""),
        objects_xml(None)
    )
}

fn json_tiles() -> Value {
    json!([
        {"id": 0, "type": "ground"},
        {"id": 1, "properties": [{"name": "solid", "type": "bool", "value": true}],
         "objectgroup": {"type": "objectgroup", "name": "", "objects": [
            {"id": 1, "x": 0, "y": 0, "polygon": [{"x": 0, "y": 10}, {"x": 10, "y": 10}, {"x": 10, "y": 0}]}]}},
        {"id": 2, "objectgroup": {"type": "objectgroup", "name": "", "objects": [
            {"id": 1, "x": 2, "y": 4, "width": 6, "height": 6}]}}
    ])
}

/// The `.tsj` tileset.
pub fn tsj() -> String {
    json!({"type": "tileset", "name": "t", "tilewidth": 10, "tileheight": 10, "tilecount": 3,
           "columns": 3, "tiles": json_tiles()})
    .to_string()
}

/// The `.tj` template: a tile object of gid 2, 20 × 20, from the external tileset.
pub fn tj() -> String {
    json!({"type": "template", "tileset": {"firstgid": 1, "source": "t.tsj"},
           "object": {"id": 0, "gid": 2, "width": 20, "height": 20, "x": 0, "y": 0}})
    .to_string()
}

/// The map as Tiled JSON, its tile data an array (`base64: None`) or a base64 string
/// compressed with zlib; its tileset in `t.tsj`, its tile object from `o.tj`.
pub fn tmj(zlib: bool) -> String {
    let gids = gids_of(&tiles(), 0, 0, W, H);
    let mut layer = json!({"type": "tilelayer", "name": "Ground", "width": W, "height": H, "x": 0, "y": 0,
                           "opacity": 1, "visible": true, "id": 1});
    if zlib {
        let (_, data) = encode(&gids, Encoding::Zlib, W);
        layer["data"] = json!(data);
        layer["encoding"] = json!("base64");
        layer["compression"] = json!("zlib");
    } else {
        layer["data"] = json!(gids);
    }
    let objs: Vec<Value> = objects()
        .iter()
        .enumerate()
        .map(|(i, o)| {
            let id = i + 1;
            match o {
                Obj::Rect { x, y, w, h, rot } => json!({"id": id, "x": x, "y": y, "width": w, "height": h, "rotation": rot}),
                Obj::Ellipse { x, y, w, h } => json!({"id": id, "x": x, "y": y, "width": w, "height": h, "ellipse": true}),
                Obj::Polygon { x, y, points } => json!({"id": id, "x": x, "y": y,
                    "polygon": points.iter().map(|(a, b)| json!({"x": a, "y": b})).collect::<Vec<_>>()}),
                Obj::Tile { x, y, .. } => json!({"id": id, "template": "o.tj", "x": x, "y": y}),
            }
        })
        .collect();
    json!({"type": "map", "version": "1.10", "orientation": "orthogonal", "renderorder": "right-down",
           "width": W, "height": H, "tilewidth": 10, "tileheight": 10, "infinite": false,
           "tilesets": [{"firstgid": 1, "source": "t.tsj"}],
           "layers": [layer, {"type": "objectgroup", "name": "Shapes", "id": 2, "objects": objs}]})
    .to_string()
}
