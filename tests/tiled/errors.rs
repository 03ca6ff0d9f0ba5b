//! Bad maps: a located, named error (exit 2 from the CLI) naming the map file, the layer,
//! the object or tile, and what to do.

use super::write::{Encoding, tileset_xml, tmx};

/// `ricochet check` on a level of `files`, solid `solid`; its exit code and stderr.
fn check(files: &[(&str, String)], solid: &str, extra: &str) -> (Option<i32>, String) {
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in files {
        std::fs::write(dir.path().join(name), text).unwrap();
    }
    let level = dir.path().join("level.toml");
    std::fs::write(&level, super::scenario_text("m.tmx", solid, extra)).unwrap();
    let o = crate::util::ricochet(&["check", level.to_str().unwrap()], b"");
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

fn map_with(objects: &str) -> String {
    tmx(Encoding::Csv, &tileset_xml(" firstgid=\"1\""), None).replace(
        "</map>",
        &format!("<objectgroup name=\"Bad\">{objects}</objectgroup></map>"),
    )
}

fn assert_error(got: (Option<i32>, String), wants: &[&str]) {
    assert_eq!(got.0, Some(2), "{}", got.1);
    for w in wants {
        assert!(got.1.contains(w), "{w:?} not in {}", got.1);
    }
}

#[test]
fn a_solid_layer_the_map_lacks_is_named() {
    let got = check(&[("m.tmx", map_with(""))], "[\"Ground\", \"Walls\"]", "");
    assert_error(
        got,
        &[
            "m.tmx",
            "\"Walls\"",
            "no layer named",
            "\"Ground\", \"Shapes\", \"Bad\"",
        ],
    );
}

#[test]
fn a_too_eccentric_ellipse_is_located() {
    let o = "<object id=\"77\" name=\"needle\" x=\"0\" y=\"0\" width=\"110\" height=\"10\"><ellipse/></object>";
    let got = check(&[("m.tmx", map_with(o))], "[\"Bad\"]", "");
    assert_error(
        got,
        &[
            "m.tmx",
            "layer \"Bad\", object 77 \"needle\"",
            "10 times longer",
            "rectangle or polygon",
        ],
    );
}

/// A polyline is a chain of `solid` entries; in a `one_way` entry (a ledge by its top) or
/// with a repeated point (a segment of no length) it is a located error.
#[test]
fn polylines_that_cannot_be_chains_are_located() {
    let o = "<object id=\"5\" x=\"0\" y=\"0\"><polyline points=\"0,0 10,0 20,5\"/></object>";
    let one_way = "one_way = [\"Bad\"]\none_way_layer = \"box\"\n[[collide]]\na = \"tile\"\n\
                   b = \"box\"\nresponse = \"one_way\"";
    let got = check(&[("m.tmx", map_with(o))], "[]", one_way);
    assert_error(
        got,
        &[
            "layer \"Bad\", object 5",
            "a polyline in a `one_way` entry",
            "`solid`",
        ],
    );
    let o = "<object id=\"6\" x=\"0\" y=\"0\"><polyline points=\"0,0 10,0 10,0 20,5\"/></object>";
    let got = check(&[("m.tmx", map_with(o))], "[\"Bad\"]", "");
    assert_error(
        got,
        &["layer \"Bad\", object 6", "polyline point 2 is on point 1"],
    );
}

/// One-way platforms exist now: a `one_way` entry needs the scenario layer its platforms go
/// to, and that layer must be the platform side of a `one_way` pair (else the pieces would
/// silently be whatever that layer's pairs say).
#[test]
fn one_way_entries_need_a_one_way_platform_layer() {
    let got = check(
        &[("m.tmx", map_with(""))],
        "[\"Ground\"]",
        "one_way = [\"Shapes\"]",
    );
    assert_error(
        got,
        &["level.toml", "tiled.one_way_layer", "one_way_layer = "],
    );
    let got = check(
        &[("m.tmx", map_with(""))],
        "[\"Ground\"]",
        "one_way = [\"Shapes\"]\none_way_layer = \"box\"",
    );
    assert_error(
        got,
        &[
            "tiled.one_way_layer",
            "no [[collide]] pair makes layer \"box\" one-way",
        ],
    );
    let got = check(
        &[("m.tmx", map_with(""))],
        "[\"Ground\"]",
        "one_way = [\"Nowhere\"]\none_way_layer = \"box\"\n\
         [[collide]]\na = \"tile\"\nb = \"box\"\nresponse = \"one_way\"",
    );
    assert_error(
        got,
        &[
            "m.tmx",
            "one_way entry for layer \"Nowhere\"",
            "no layer named",
        ],
    );
}

#[test]
fn a_missing_tileset_file_is_named() {
    let map = tmx(
        Encoding::Csv,
        "<tileset firstgid=\"1\" source=\"gone.tsx\"/>",
        None,
    );
    let got = check(&[("m.tmx", map)], "[\"Ground\"]", "");
    assert_error(got, &["m.tmx", "gone.tsx"]);
}

#[test]
fn a_tile_past_its_tileset_and_a_self_crossing_polygon_are_located() {
    let map = tmx(Encoding::Csv, &tileset_xml(" firstgid=\"1\""), None).replacen(
        "encoding=\"csv\">0,",
        "encoding=\"csv\">9,",
        1,
    );
    let got = check(&[("m.tmx", map)], "[\"Ground\"]", "");
    assert_error(
        got,
        &[
            "layer \"Ground\", tile (0, 0)",
            "tile 8 of tileset \"t\", which has 3 tiles",
        ],
    );
    let bow =
        "<object id=\"9\" x=\"0\" y=\"0\"><polygon points=\"0,0 10,10 10,0 0,10 -5,5\"/></object>";
    let got = check(&[("m.tmx", map_with(bow))], "[\"Bad\"]", "");
    assert_error(got, &["layer \"Bad\", object 9", "crosses itself"]);
}

#[test]
fn a_compressed_layer_past_the_cell_cap_is_refused_before_it_is_decoded() {
    // 80 MiB of zeros, zlib'd to about 80 KiB: more than 2^24 cells' worth.
    use std::io::Write;
    let mut e = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::best());
    e.write_all(&vec![0u8; 80 << 20]).unwrap();
    let data = base64::Engine::encode(
        &base64::engine::general_purpose::STANDARD,
        e.finish().unwrap(),
    );
    let map = format!(
        "<?xml version=\"1.0\"?><map orientation=\"orthogonal\" width=\"5000\" height=\"4200\" tilewidth=\"10\" \
         tileheight=\"10\">{}<layer name=\"Ground\" width=\"5000\" height=\"4200\"><data encoding=\"base64\" \
         compression=\"zlib\">{data}</data></layer></map>",
        tileset_xml(" firstgid=\"1\"")
    );
    let got = check(&[("m.tmx", map)], "[\"Ground\"]", "");
    assert_error(got, &["m.tmx", "decompresses past", "16777216 cells"]);
}

#[test]
fn the_plain_loader_refuses_a_tiled_scenario_rather_than_drop_its_level() {
    let text = super::scenario_text("m.tmx", "[\"Ground\"]", "");
    let e = ricochet_sim::load_scenario(&text, "level.toml").unwrap_err();
    assert_eq!((e.line, e.field.as_str()), (2, "tiled"));
    assert!(e.problem.contains("ricochet_tiled::add_map"), "{e}");
}

#[test]
fn a_tile_of_no_tileset_is_named_not_dropped() {
    // The tileset starts at gid 5: the map's gids 1 to 4 have none, in every encoding.
    for enc in [Encoding::Csv, Encoding::Zlib, Encoding::Xml] {
        let map = tmx(enc, &tileset_xml(" firstgid=\"5\""), None);
        let got = check(&[("m.tmx", map)], "[\"Ground\"]", "");
        // Row 4 (y = 4) holds the first tile in reading order: cell (3, 4), gid 1.
        assert_error(
            got,
            &[
                "m.tmx",
                "layer \"Ground\", tile (3, 4): gid 1 has no tileset",
                "starts at gid 5",
            ],
        );
    }
}

/// The scenario's `[tiled]` table is checked with the scenario, located in its file.
#[test]
fn a_bad_tiled_table_is_located_in_the_scenario() {
    let dir = tempfile::tempdir().unwrap();
    let level = dir.path().join("level.toml");
    for (solid, extra, wants) in [
        (
            "[\"Ground?\"]",
            "",
            &["level.toml:4:10:", "tiled.solid[0]", "LAYER?PROP=VALUE"][..],
        ),
        (
            "[\"Ground\"]",
            "units_per_tile = -1\n",
            &["level.toml:6:", "tiled.units_per_tile", "above 0"][..],
        ),
        (
            "[\"Ground\"]",
            "[tiled.spawn]\nhero = \"nobody\"\n",
            &["tiled.spawn.hero", "unknown template \"nobody\""][..],
        ),
        (
            "[\"Ground\"]",
            "colour = 1\n",
            &["level.toml:6:", "unknown field `colour`"][..],
        ),
    ] {
        std::fs::write(&level, super::scenario_text("m.tmx", solid, extra)).unwrap();
        let o = crate::util::ricochet(&["check", level.to_str().unwrap()], b"");
        assert_error(
            (
                o.status.code(),
                String::from_utf8_lossy(&o.stderr).into_owned(),
            ),
            wants,
        );
    }
    // The scenario layer the map's bodies go to must exist.
    let text = super::scenario_text("m.tmx", "[\"Ground\"]", "")
        .replace("layer = \"tile\"", "layer = \"floor\"");
    std::fs::write(&level, text).unwrap();
    let o = crate::util::ricochet(&["check", level.to_str().unwrap()], b"");
    assert_error(
        (
            o.status.code(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        ),
        &["tiled.layer", "unknown layer \"floor\""],
    );
}
