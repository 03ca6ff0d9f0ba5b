//! `[tiled]`: maps in every form Tiled saves become static solids covering exactly the points
//! the map's shapes cover (sampled, the answers computed here from the map's own numbers in
//! pixels), and bad maps are located errors.

mod errors;
mod suite;
mod write;

use std::path::Path;

use ricochet_sim::{QueryFilter, Simulation, Vec2};
use write::{Encoding, FLIP_D, FLIP_H, FLIP_V, H, Obj, TILE};

/// A scenario taking its level from `map`, 1 unit a tile (10 px).
pub fn scenario_text(map: &str, solid: &str, extra: &str) -> String {
    format!(
        "layers = [\"tile\", \"box\"]\n[tiled]\nmap = \"{map}\"\nsolid = {solid}\nlayer = \"tile\"\n{extra}\n\
         [templates.box]\nlayer = \"box\"\nshape = {{ kind = \"circle\", radius = 0.2 }}\n"
    )
}

/// Loads `dir/level.toml` as the binary does.
pub fn load(dir: &Path) -> Result<(ricochet_sim::Scenario, ricochet_tiled::MapSummary), String> {
    load_file(&dir.join("level.toml"))
}

/// Loads the scenario file `path` and its map as the binary does.
pub fn load_file(
    path: &Path,
) -> Result<(ricochet_sim::Scenario, ricochet_tiled::MapSummary), String> {
    let text = std::fs::read_to_string(path).unwrap();
    let (mut s, def) = ricochet_sim::load_scenario_and_map(&text, &path.display().to_string())
        .map_err(|e| e.to_string())?;
    let summary = ricochet_tiled::add_map(&mut s, &def.expect("a [tiled] table"), path)
        .map_err(|e| e.to_string())?;
    Ok((s, summary))
}

/// Whether tile-local pixel `(u, v)` (0..10, y down, before the flips) is in gid `g`'s shape.
fn in_tile_shape(g: u32, u: f64, v: f64) -> bool {
    match g {
        1 => (0.0..=TILE).contains(&u) && (0.0..=TILE).contains(&v),
        // Below the diagonal from (0, 10) to (10, 0).
        2 => (0.0..=TILE).contains(&u) && (0.0..=TILE).contains(&v) && u + v >= TILE,
        3 => (2.0..=8.0).contains(&u) && (4.0..=10.0).contains(&v),
        _ => false,
    }
}

/// Whether map pixel `(px, py)` is in the tile `bits` at cell `(cx, cy)`: the flips undone in
/// the reverse of the order Tiled applies them (diagonal, then horizontal, then vertical).
fn in_tile(cx: i32, cy: i32, bits: u32, px: f64, py: f64) -> bool {
    let (mut u, mut v) = (px - f64::from(cx) * TILE, py - f64::from(cy) * TILE);
    if bits & FLIP_V != 0 {
        v = TILE - v;
    }
    if bits & FLIP_H != 0 {
        u = TILE - u;
    }
    if bits & FLIP_D != 0 {
        std::mem::swap(&mut u, &mut v);
    }
    in_tile_shape(bits & 0x0fff_ffff, u, v)
}

/// Even-odd rule.
fn in_polygon(p: &[(f64, f64)], x: f64, y: f64) -> bool {
    let mut inside = false;
    for i in 0..p.len() {
        let (a, b) = (p[i], p[(i + 1) % p.len()]);
        if (a.1 > y) != (b.1 > y) && x < a.0 + (y - a.1) / (b.1 - a.1) * (b.0 - a.0) {
            inside = !inside;
        }
    }
    inside
}

/// Whether the object covers `(px, py)`: `Some(true)`/`Some(false)`, or `None` in an
/// ellipse's stated tolerance band (inside the ellipse, outside its inscribed 32-gon).
fn in_object(o: &Obj, px: f64, py: f64) -> Option<bool> {
    Some(match o {
        Obj::Rect { x, y, w, h, rot } => {
            let r = -rot.to_radians();
            let (dx, dy) = (px - x, py - y);
            let (u, v) = (
                dx * libm::cos(r) - dy * libm::sin(r),
                dx * libm::sin(r) + dy * libm::cos(r),
            );
            (0.0..=*w).contains(&u) && (0.0..=*h).contains(&v)
        }
        Obj::Ellipse { x, y, w, h } => {
            let q = (((px - x - w / 2.0) / (w / 2.0)).powi(2)
                + ((py - y - h / 2.0) / (h / 2.0)).powi(2))
            .sqrt();
            if w == h {
                q <= 1.0
            } else if q <= libm::cos(std::f64::consts::PI / 32.0) {
                true
            } else if q > 1.0 {
                false
            } else {
                return None;
            }
        }
        Obj::Polygon { x, y, points } => in_polygon(points, px - x, py - y),
        Obj::Tile { x, y, w, h } => {
            let (u, v) = ((px - x) * TILE / w, (py - (y - h)) * TILE / h);
            in_tile_shape(2, u, v)
        }
    })
}

/// The map's answer at pixel `(px, py)` for its tiles moved by `(dx, dy)` cells, `None` near
/// an edge (the answer changes within 0.02 px) or in an ellipse's tolerance band.
fn expected(px: f64, py: f64, dx: i32, dy: i32) -> Option<bool> {
    let at = |px: f64, py: f64| -> Option<bool> {
        let tiles = write::tiles()
            .iter()
            .any(|&(x, y, g)| in_tile(x + dx, y + dy, g, px, py));
        let mut any = tiles;
        for o in write::objects() {
            any |= in_object(&o, px, py)?;
        }
        Some(any)
    };
    let here = at(px, py)?;
    for (ex, ey) in [(0.02, 0.0), (-0.02, 0.0), (0.0, 0.02), (0.0, -0.02)] {
        if at(px + ex, py + ey)? != here {
            return None;
        }
    }
    Some(here)
}

/// Samples the map's area in pixels and compares each answer with the built scene; `dx, dy`
/// as for [`expected`]. Returns how many points were compared.
fn check_cover(dir: &Path, dx: i32, dy: i32) -> usize {
    let (scenario, _) = load(dir).unwrap_or_else(|e| panic!("{e}"));
    let sim = Simulation::new(&scenario);
    // World = (px / 10, (H * 10 - py) / 10): 1 unit a tile, the map's bottom-left at 0.
    let h_px = f64::from(H) * TILE;
    let filter = QueryFilter::default();
    let mut compared = 0;
    let (x_lo, y_lo) = (
        f64::from(dx.min(0)) * TILE - 5.0,
        f64::from(dy.min(0)) * TILE - 5.0,
    );
    let mut py = y_lo + 0.013;
    while py < h_px + 5.0 {
        let mut px = x_lo + 0.017;
        while px < 125.0 {
            if let Some(want) = expected(px, py, dx, dy) {
                let world = Vec2::new(px / TILE, (h_px - py) / TILE);
                let got = !sim.overlap_point(world, &filter).is_empty();
                assert_eq!(
                    got,
                    want,
                    "{}: pixel ({px}, {py}), world {world}",
                    dir.display()
                );
                compared += 1;
            }
            px += 0.7;
        }
        py += 0.7;
    }
    assert!(compared > 10_000, "{compared}");
    compared
}

fn level(files: &[(&str, String)], map: &str) -> tempfile::TempDir {
    level_with(files, map, "[\"Ground\", \"Shapes\"]")
}

fn level_with(files: &[(&str, String)], map: &str, solid: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in files {
        std::fs::write(dir.path().join(name), text).unwrap();
    }
    std::fs::write(dir.path().join("level.toml"), scenario_text(map, solid, "")).unwrap();
    dir
}

#[test]
fn tmx_in_every_tile_encoding_covers_exactly_the_maps_shapes() {
    let embedded = write::tileset_xml(" firstgid=\"1\"");
    for enc in [
        Encoding::Csv,
        Encoding::Base64,
        Encoding::Zlib,
        Encoding::Gzip,
        Encoding::Zstd,
        Encoding::Xml,
    ] {
        let dir = level(&[("m.tmx", write::tmx(enc, &embedded, None))], "m.tmx");
        check_cover(dir.path(), 0, 0);
    }
}

#[test]
fn tmx_with_an_external_tileset_and_a_template_covers_the_same() {
    let tx = "<?xml version=\"1.0\"?><template><tileset firstgid=\"1\" source=\"t.tsx\"/>\
              <object gid=\"2\" width=\"20\" height=\"20\"/></template>";
    let dir = level(
        &[
            (
                "m.tmx",
                write::tmx(
                    Encoding::Csv,
                    "<tileset firstgid=\"1\" source=\"t.tsx\"/>",
                    Some("o.tx"),
                ),
            ),
            (
                "t.tsx",
                format!("<?xml version=\"1.0\"?>{}", write::tileset_xml("")),
            ),
            ("o.tx", tx.to_owned()),
        ],
        "m.tmx",
    );
    check_cover(dir.path(), 0, 0);
}

#[test]
fn infinite_maps_with_negative_chunks_cover_the_moved_tiles() {
    for enc in [Encoding::Csv, Encoding::Zlib] {
        let dir = level(&[("m.tmx", write::infinite_tmx(enc, -5, -3))], "m.tmx");
        check_cover(dir.path(), -5, -3);
    }
}

#[test]
fn tiled_json_maps_with_tsj_and_tj_cover_the_same() {
    for zlib in [false, true] {
        let dir = level(
            &[
                ("m.tmj", write::tmj(zlib)),
                ("t.tsj", write::tsj()),
                ("o.tj", write::tj()),
            ],
            "m.tmj",
        );
        check_cover(dir.path(), 0, 0);
    }
}

#[test]
fn whole_cell_tiles_become_tile_rows_and_spawns_become_bodies() {
    let embedded = write::tileset_xml(" firstgid=\"1\"");
    let mut tmx = write::tmx(Encoding::Csv, &embedded, None);
    tmx = tmx.replace(
        "</map>",
        "<objectgroup name=\"Spawns\"><object id=\"50\" name=\"start\" type=\"player\" x=\"15\" y=\"35\"><point/></object>\
         <object id=\"51\" name=\"coin\" x=\"40\" y=\"30\" width=\"10\" height=\"4\"/></objectgroup></map>",
    );
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("m.tmx"), tmx).unwrap();
    std::fs::write(
        dir.path().join("level.toml"),
        scenario_text(
            "m.tmx",
            "[\"Ground?solid\"]",
            "[tiled.spawn]\nplayer = \"box\"\ncoin = \"box\"\n",
        ),
    )
    .unwrap();
    let (s, summary) = load(dir.path()).unwrap();
    // `Ground?solid`: only gid 2's tiles (5 of them, the tileset marks them solid).
    assert_eq!(summary.tiles, 5);
    assert_eq!(summary.spawns.get("box"), Some(&2));
    // The point at pixel (15, 35) → world (1.5, (80 - 35) / 10); the coin's centre (45, 32).
    let at: Vec<Vec2> = s.bodies.iter().map(|b| b.position).collect();
    assert_eq!(at.len(), 2);
    for (got, want) in at.iter().zip([Vec2::new(1.5, 4.5), Vec2::new(4.5, 4.8)]) {
        assert!((*got - want).length() < 1e-12, "{got} {want}");
    }
    // Without the filter, the 12 floor tiles make one row of one shape.
    std::fs::write(
        dir.path().join("level.toml"),
        scenario_text("m.tmx", "[\"Ground\"]", ""),
    )
    .unwrap();
    let (s, summary) = load(dir.path()).unwrap();
    assert_eq!(summary.tiles, write::tiles().len());
    let floor = s
        .tiles
        .iter()
        .flat_map(|t| &t.rows)
        .find(|&&(_, n)| n == 12)
        .expect("the floor's run");
    // Cell (0, 7)'s centre: pixel (5, 75) → world (0.5, (80 - 75) / 10).
    assert_eq!(floor.0, Vec2::new(0.5, 0.5));
}

/// `one_way` entries: the tiles and objects they take become static bodies of
/// `one_way_layer` (the platform side of a `one_way` pair), counted as one-way pieces; the
/// same layers listed in `solid` instead give as many solids on `layer`.
#[test]
fn one_way_entries_become_one_way_statics_on_their_layer() {
    let embedded = write::tileset_xml(" firstgid=\"1\"");
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("m.tmx"),
        write::tmx(Encoding::Csv, &embedded, None),
    )
    .unwrap();
    let one_way = "one_way_layer = \"box\"\n[[collide]]\na = \"tile\"\nb = \"box\"\n\
                   response = \"one_way\"\n";
    std::fs::write(
        dir.path().join("level.toml"),
        scenario_text("m.tmx", "[\"Shapes\"]", ""),
    )
    .unwrap();
    let (_, as_solid) = load(dir.path()).unwrap();
    assert!(as_solid.solids > 0);
    std::fs::write(
        dir.path().join("level.toml"),
        scenario_text(
            "m.tmx",
            "[]",
            &format!("one_way = [\"Ground\", \"Shapes\"]\n{one_way}"),
        ),
    )
    .unwrap();
    let (s, summary) = load(dir.path()).unwrap();
    assert_eq!(summary.tiles, 0);
    assert_eq!(summary.solids, 0);
    assert_eq!(summary.one_way, write::tiles().len() + as_solid.solids);
    // Layer 1 is "box", the platform layer; nothing went to "tile".
    assert!(s.tiles.iter().all(|t| t.layer == 1));
    assert_eq!(s.bodies.len(), as_solid.solids);
    assert!(s.bodies.iter().all(|b| b.layer == 1));
}

/// The shipped level: `ricochet check` says what its map became, counted from the map file
/// (`scenarios/maps/level1.tmx`): "Ground" holds a 40-tile floor, two 7-tile walls, a 2 x 5
/// raised floor and a tile under its down slope (40 + 14 + 10 + 1 = 65 whole tiles) and 2
/// slope tiles; "Terrain" a ramp polygon and the hills polyline (a chain); "Platforms" 5
/// one-way tiles; "Spawns" the player, an enemy, a boulder and three coins.
#[test]
fn check_summarises_the_shipped_tiled_level() {
    let level = crate::util::root().join("scenarios/tiled_level.toml");
    let o = crate::util::ricochet(&["check", level.to_str().unwrap()], b"");
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        out.contains(
            "tiled map: 67 static tiles, 1 solid bodies, 5 one-way pieces, 1 chains, \
             spawns: 1 boulder, 3 coin, 1 enemy, 1 player"
        ),
        "{out}"
    );
}

/// No false refusal: the shipped Tiled level, its map's bodies added, passes the check a
/// game runs on a scene before it steps (its script names the player the map spawns).
#[test]
fn the_shipped_tiled_level_passes_the_check() {
    let level = crate::util::root().join("scenarios/tiled_level.toml");
    let (scenario, _) = load_file(&level).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scenario.check(), Ok(()));
}

/// Polylines of a `solid` layer become chains covering exactly their points: sampled on
/// every segment (ends, joints and between) and off it (half a pixel to either side, and
/// past the ends), the answers from the map's own numbers (a polyline at object `(x, y)`,
/// turned by `rotation` degrees clockwise on screen, its points relative to the object).
/// A polyline of more points than a chain holds becomes several chains.
#[test]
fn polylines_become_chains_covering_exactly_their_points() {
    let h_px = f64::from(H) * TILE;
    // Object 1: at (5, 35) px, unrotated. Object 2: at (60, 70) px, turned 30°. Object 3: a
    // zigzag of 2,500 points (4 px apart along x, up and down 3 px), at (0, 75) px.
    let zig: Vec<(f64, f64)> = (0..2500)
        .map(|k| (f64::from(k) * 4.0, if k % 2 == 0 { 0.0 } else { -3.0 }))
        .collect();
    // Each: object x, y (px), rotation (degrees), points.
    type Line = (f64, f64, f64, Vec<(f64, f64)>);
    let lines: [Line; 3] = [
        (
            5.0,
            35.0,
            0.0,
            vec![(0.0, 0.0), (30.0, 0.0), (50.0, -20.0), (80.0, -20.0)],
        ),
        (60.0, 70.0, 30.0, vec![(0.0, 0.0), (20.0, 5.0), (40.0, 0.0)]),
        (0.0, 75.0, 0.0, zig),
    ];
    let mut objects = String::new();
    for (i, (x, y, rot, pts)) in lines.iter().enumerate() {
        let points: Vec<String> = pts.iter().map(|(u, v)| format!("{u},{v}")).collect();
        objects += &format!(
            "<object id=\"{}\" x=\"{x}\" y=\"{y}\" rotation=\"{rot}\"><polyline points=\"{}\"/></object>",
            i + 1,
            points.join(" ")
        );
    }
    let map = write::tmx(Encoding::Csv, &write::tileset_xml(" firstgid=\"1\""), None).replace(
        "</map>",
        &format!("<objectgroup id=\"9\" name=\"Lines\">{objects}</objectgroup></map>"),
    );
    let dir = level_with(&[("m.tmx", map)], "m.tmx", "[\"Lines\"]");
    let (scenario, summary) = load(dir.path()).unwrap_or_else(|e| panic!("{e}"));
    // 1 + 1 + ceil(2,499 segments / 1,024 a chain) = 5.
    assert_eq!(summary.chains, 5);
    assert_eq!(summary.solids, 0);
    let sim = Simulation::new(&scenario);
    let filter = QueryFilter::default();
    let probe = ricochet_sim::Shape::circle(1e-4).unwrap();
    let hits = |px: f64, py: f64| {
        let world = Vec2::new(px / TILE, (h_px - py) / TILE);
        !sim.overlap_shape(&probe, ricochet_sim::Pose::new(world, 0.0), &filter)
            .is_empty()
    };
    let mut sampled = 0;
    for (x, y, rot, pts) in &lines {
        let (s, c) = (libm::sin(rot.to_radians()), libm::cos(rot.to_radians()));
        // Tiled turns an object clockwise on screen (y down) about its anchor.
        let at = |u: f64, v: f64| (x + u * c - v * s, y + u * s + v * c);
        for w in pts.windows(2) {
            let (a, b) = (at(w[0].0, w[0].1), at(w[1].0, w[1].1));
            let (dx, dy) = (b.0 - a.0, b.1 - a.1);
            let len = (dx * dx + dy * dy).sqrt();
            // Half a pixel to the side, in pixels.
            let (nx, ny) = (-dy / len * 0.5, dx / len * 0.5);
            for k in 0..=8 {
                let t = f64::from(k) / 8.0;
                let (px, py) = (a.0 + dx * t, a.1 + dy * t);
                assert!(hits(px, py), "on the line: pixel ({px}, {py})");
                if (1..8).contains(&k) {
                    assert!(
                        !hits(px + nx, py + ny),
                        "beside: ({}, {})",
                        px + nx,
                        py + ny
                    );
                    assert!(
                        !hits(px - nx, py - ny),
                        "beside: ({}, {})",
                        px - nx,
                        py - ny
                    );
                }
                sampled += 1;
            }
        }
        // Past the first point, along the first segment backwards.
        let (a, b) = (at(pts[0].0, pts[0].1), at(pts[1].0, pts[1].1));
        let back = (a.0 - (b.0 - a.0) * 0.1, a.1 - (b.1 - a.1) * 0.1);
        assert!(!hits(back.0, back.1), "past the start: {back:?}");
    }
    assert!(sampled > 20_000, "{sampled}");
}

/// A group named in `solid` takes every layer in it, offsets added (the group's and its
/// layers'): here the group moves its layers back by the offset its tile layer adds.
#[test]
fn a_group_named_in_solid_takes_its_layers_with_their_offsets() {
    let embedded = write::tileset_xml(" firstgid=\"1\"");
    let tmx = write::tmx(Encoding::Csv, &embedded, None)
        .replacen("<layer id=\"1\"", "<group name=\"Level\" offsetx=\"-3\" offsety=\"2\"><layer offsetx=\"3\" offsety=\"-2\" id=\"1\"", 1)
        .replacen("<objectgroup id=\"2\" name=\"Shapes\">", "<objectgroup id=\"2\" name=\"Shapes\" offsetx=\"3\" offsety=\"-2\">", 1)
        .replacen("</map>", "</group></map>", 1);
    let dir = level_with(&[("m.tmx", tmx)], "m.tmx", "[\"Level\"]");
    check_cover(dir.path(), 0, 0);
}

/// Object filters: class/type, name, and a property read from the object, then its template,
/// then its tile's tileset entry (gid 2's says `solid = true`).
#[test]
fn object_filters_read_the_object_then_its_template_then_its_tile() {
    let props = |v: &str| {
        format!("<properties><property name=\"solid\" type=\"bool\" value=\"{v}\"/></properties>")
    };
    let objects = format!(
        "<object id=\"1\" type=\"Boundaries\" x=\"0\" y=\"0\" width=\"5\" height=\"5\"/>\
         <object id=\"2\" x=\"10\" y=\"0\" width=\"5\" height=\"5\">{}</object>\
         <object id=\"3\" template=\"w.tx\" x=\"20\" y=\"0\"/>\
         <object id=\"4\" gid=\"2\" x=\"30\" y=\"10\" width=\"10\" height=\"10\"/>\
         <object id=\"5\" x=\"40\" y=\"0\" width=\"5\" height=\"5\">{}</object>\
         <object id=\"6\" name=\"edge\" x=\"50\" y=\"0\" width=\"5\" height=\"5\"/>\
         <object id=\"7\" template=\"w.tx\" x=\"60\" y=\"0\">{}</object>\
         <object id=\"8\" gid=\"1\" x=\"70\" y=\"10\" width=\"10\" height=\"10\"/>",
        props("true"),
        props("false"),
        props("false"),
    );
    let map = format!(
        "<?xml version=\"1.0\"?><map version=\"1.10\" orientation=\"orthogonal\" width=\"10\" height=\"4\" \
         tilewidth=\"10\" tileheight=\"10\">{}<objectgroup name=\"Objs\">{objects}</objectgroup></map>",
        write::tileset_xml(" firstgid=\"1\"")
    );
    let tx = format!(
        "<?xml version=\"1.0\"?><template><object width=\"5\" height=\"5\">{}</object></template>",
        props("true")
    );
    let dir = level_with(
        &[("m.tmx", map), ("w.tx", tx)],
        "m.tmx",
        "[\"Objs?type=Boundaries\", \"Objs?solid\", \"Objs?name=edge\"]",
    );
    let (s, summary) = load(dir.path()).unwrap();
    // 1 (type), 2 (its own property), 3 (its template's), 4 (its tile's), 6 (name); not 5
    // (false), 7 (its own false over its template's true), 8 (gid 1 has no property).
    assert_eq!(summary.solids, 5);
    let xs: Vec<f64> = s.bodies.iter().map(|b| b.position.x).collect();
    assert_eq!(xs, [0.25, 1.25, 2.25, 3.5, 5.25]);
}
