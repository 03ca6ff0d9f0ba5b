//! Reading the files: each is at most [`MAX_FILE_BYTES`], JSON ones are converted to TMX text
//! ([`crate::json`]), and compressed tile data is measured (decompressed into a counter, never
//! kept) before the `tiled` crate decompresses it, so a small bomb cannot fill memory.

use std::io::{Cursor, Read};
use std::path::Path;

use base64::Engine;

use crate::{MAX_CELLS, MAX_FILE_BYTES, TiledError};

/// What a zstd-compressed layer gets from a build without the `zstd` feature.
#[cfg(not(feature = "zstd"))]
const NO_ZSTD: &str = "tile data compression \"zstd\" needs ricochet-tiled's `zstd` feature, \
     which this build leaves off; save the layer as CSV, or zlib or gzip base64";

/// Reads a map through the `tiled` crate, with the checks above on every file.
pub(crate) fn load_map(path: &Path) -> Result<tiled::Map, TiledError> {
    let file = path.display().to_string();
    // Decompressed tile bytes of every file so far (maps and their templates).
    let budget = std::cell::Cell::new(MAX_CELLS * 4);
    let reader = |p: &Path| -> Result<Cursor<Vec<u8>>, std::io::Error> {
        let text = read_file(p)?;
        let json = matches!(
            p.extension().and_then(|e| e.to_str()),
            Some("json" | "tmj" | "tsj" | "tj")
        );
        let xml = if json {
            crate::json::to_tmx(&text, p).map_err(std::io::Error::other)?
        } else {
            text
        };
        let xml = xml_tiles_to_csv(&xml);
        let used = compressed_sizes(&xml).map_err(std::io::Error::other)?;
        gids_without_tileset(&xml).map_err(std::io::Error::other)?;
        if used > budget.get() {
            return Err(std::io::Error::other(format!(
                "its compressed tile data decompresses past {} bytes, {} cells' worth; \
                 a map may cover at most {MAX_CELLS} cells",
                MAX_CELLS * 4,
                MAX_CELLS
            )));
        }
        budget.set(budget.get() - used);
        Ok(Cursor::new(xml.into_owned().into_bytes()))
    };
    let mut loader = tiled::Loader::with_reader(reader);
    loader.load_tmx_map(path).map_err(|e| TiledError {
        file,
        place: "reading".to_owned(),
        problem: describe(&e),
    })
}

/// The `tiled` crate's error, with its cause chain (the file it could not read and why).
fn describe(e: &tiled::Error) -> String {
    let mut s = e.to_string();
    let mut src = std::error::Error::source(e);
    while let Some(c) = src {
        // The crate's messages often quote their cause already.
        let cause = c.to_string();
        if !s.contains(&cause) {
            s.push_str(": ");
            s.push_str(&cause);
        }
        src = c.source();
    }
    s
}

fn read_file(p: &Path) -> Result<String, std::io::Error> {
    let f = std::fs::File::open(p)?;
    let mut text = String::new();
    // One byte past the cap tells a file at the cap from a longer one.
    f.take(MAX_FILE_BYTES + 1).read_to_string(&mut text)?;
    if text.len() as u64 > MAX_FILE_BYTES {
        return Err(std::io::Error::other(format!(
            "longer than {MAX_FILE_BYTES} bytes, the most a map, tileset or template file may be"
        )));
    }
    Ok(text)
}

/// The old XML tile data (`<data>` holding a `<tile gid="N"/>` per cell, the form Tiled wrote
/// before CSV), which the `tiled` crate does not read, rewritten as the same cells in CSV.
fn xml_tiles_to_csv(xml: &str) -> std::borrow::Cow<'_, str> {
    if !xml.contains("<data") || !xml.contains("<tile") {
        return xml.into();
    }
    let mut out = String::with_capacity(xml.len());
    let mut rest = xml;
    while let Some(start) = rest.find("<data") {
        out.push_str(&rest[..start]);
        rest = &rest[start..];
        let (Some(tag_end), Some(end)) = (rest.find('>'), rest.find("</data>")) else {
            break;
        };
        let tag = &rest[..tag_end];
        if attr(tag, "encoding").is_some() || tag.ends_with('/') {
            out.push_str(&rest[..end]);
            rest = &rest[end..];
            continue;
        }
        out.push_str(tag);
        out.push_str(" encoding=\"csv\">");
        let body = &rest[tag_end + 1..end];
        // Each block of cells: the whole body, or each chunk's (its own tag kept).
        let mut b = body;
        let mut gids: Vec<&str> = Vec::new();
        let flush = |gids: &mut Vec<&str>, out: &mut String| {
            out.push_str(&gids.join(","));
            gids.clear();
        };
        while let Some(t) = b.find('<') {
            let Some(close) = b[t..].find('>') else { break };
            let element = &b[t..t + close + 1];
            if element.starts_with("<tile") {
                gids.push(attr(element, "gid").unwrap_or("0"));
            } else {
                // A `<chunk ...>` or `</chunk>`: the cells so far end before it.
                flush(&mut gids, &mut out);
                out.push_str(element);
            }
            b = &b[t + close + 1..];
        }
        flush(&mut gids, &mut out);
        rest = &rest[end..];
    }
    out.push_str(rest);
    out.into()
}

/// The attribute `name` of the start tag `tag` (its text up to `>`), if written.
fn attr<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let at = tag.find(&format!(" {name}=\""))? + name.len() + 3;
    let rest = &tag[at..];
    Some(&rest[..rest.find('"')?])
}

/// How many bytes every compressed `<data>` block (or each of its chunks) decompresses to,
/// counted up to the budget and no further.
fn compressed_sizes(xml: &str) -> Result<u64, String> {
    let limit = MAX_CELLS * 4;
    let mut total = 0u64;
    let mut rest = xml;
    while let Some(start) = rest.find("<data") {
        rest = &rest[start..];
        let Some(tag_end) = rest.find('>') else { break };
        let tag = &rest[..tag_end];
        let Some(end) = rest.find("</data>") else {
            break;
        };
        let body = &rest[tag_end + 1..end];
        rest = &rest[end..];
        let Some(compression) = attr(tag, "compression") else {
            continue;
        };
        // A finite layer's text, or each chunk's.
        let mut blocks: Vec<&str> = Vec::new();
        if body.contains("<chunk") {
            let mut b = body;
            while let Some(s) = b.find("<chunk") {
                b = &b[s..];
                let (Some(open), Some(close)) = (b.find('>'), b.find("</chunk>")) else {
                    break;
                };
                blocks.push(&b[open + 1..close]);
                b = &b[close..];
            }
        } else {
            blocks.push(body);
        }
        for block in blocks {
            let clean: String = block.chars().filter(|c| !c.is_whitespace()).collect();
            let bytes = base64::engine::general_purpose::STANDARD
                .decode(clean.as_bytes())
                .map_err(|e| format!("tile data is not valid base64: {e}"))?;
            let budget = limit.saturating_sub(total) + 1;
            let n = match compression {
                "zlib" => count(flate2::read::ZlibDecoder::new(&bytes[..]), budget),
                "gzip" => count(flate2::read::GzDecoder::new(&bytes[..]), budget),
                #[cfg(feature = "zstd")]
                "zstd" => count(
                    zstd::stream::read::Decoder::new(&bytes[..]).map_err(|e| e.to_string())?,
                    budget,
                ),
                #[cfg(not(feature = "zstd"))]
                "zstd" => return Err(NO_ZSTD.to_owned()),
                other => {
                    return Err(format!(
                        "tile data compression \"{other}\" is not one of zlib, gzip, zstd"
                    ));
                }
            }
            .map_err(|e| format!("tile data does not decompress ({compression}): {e}"))?;
            total += n;
            if total > limit {
                return Ok(total);
            }
        }
    }
    Ok(total)
}

fn count(r: impl Read, budget: u64) -> std::io::Result<u64> {
    std::io::copy(&mut r.take(budget), &mut std::io::sink())
}

/// A tile whose gid is below every tileset's `firstgid` (or in a map with no tileset) has no
/// tileset: the `tiled` crate drops such a cell silently, so it is refused here, naming its
/// layer and cell. Maps whose first tileset starts at gid 1 (Tiled's own) are not scanned.
fn gids_without_tileset(xml: &str) -> Result<(), String> {
    if !xml.contains("<map") {
        return Ok(());
    }
    let mut first = u32::MAX;
    let mut rest = xml;
    while let Some(at) = rest.find("<tileset") {
        rest = &rest[at + 8..];
        let tag = &rest[..rest.find('>').unwrap_or(rest.len())];
        if let Some(g) = attr(tag, "firstgid").and_then(|g| g.parse::<u32>().ok()) {
            first = first.min(g);
        }
    }
    if first <= 1 {
        return Ok(());
    }
    let mut rest = xml;
    while let Some(at) = rest.find("<layer") {
        rest = &rest[at..];
        let Some(tag_end) = rest.find('>') else { break };
        let name = attr(&rest[..tag_end], "name").unwrap_or("").to_owned();
        let width: i64 = attr(&rest[..tag_end], "width")
            .and_then(|w| w.parse().ok())
            .unwrap_or(1);
        let (Some(d), Some(end)) = (rest.find("<data"), rest.find("</data>")) else {
            break;
        };
        let data = &rest[d..end];
        rest = &rest[end..];
        let Some(dt) = data.find('>') else { continue };
        let (tag, body) = (&data[..dt], &data[dt + 1..]);
        // Each block: its top-left cell, its width, its text.
        let mut blocks: Vec<(i64, i64, i64, &str)> = Vec::new();
        if body.contains("<chunk") {
            let mut b = body;
            while let Some(c) = b.find("<chunk") {
                b = &b[c..];
                let (Some(open), Some(close)) = (b.find('>'), b.find("</chunk>")) else {
                    break;
                };
                let ct = &b[..open];
                let num = |k: &str| attr(ct, k).and_then(|v| v.parse::<i64>().ok()).unwrap_or(0);
                blocks.push((num("x"), num("y"), num("width").max(1), &b[open + 1..close]));
                b = &b[close..];
            }
        } else {
            blocks.push((0, 0, width.max(1), body));
        }
        for (x0, y0, w, text) in blocks {
            let gids = decode_gids(tag, text)?;
            if let Some(k) = gids
                .iter()
                .position(|&g| g & 0x0fff_ffff != 0 && g & 0x0fff_ffff < first)
            {
                let k = k as i64;
                return Err(format!(
                    "layer \"{name}\", tile ({}, {}): gid {} has no tileset (the first starts at gid \
                     {}); add its tileset to the map, or clear the tile",
                    x0 + k % w,
                    y0 + k / w,
                    gids[k as usize] & 0x0fff_ffff,
                    if first == u32::MAX {
                        "none: the map has no tileset".to_owned()
                    } else {
                        first.to_string()
                    }
                ));
            }
        }
    }
    Ok(())
}

/// One block of tile data as gids (CSV, or base64 plain or compressed; sizes already
/// bounded by [`compressed_sizes`]).
fn decode_gids(tag: &str, text: &str) -> Result<Vec<u32>, String> {
    if attr(tag, "encoding") == Some("csv") {
        return Ok(text
            .split(',')
            .filter_map(|v| v.trim().parse::<u32>().ok())
            .collect());
    }
    let clean: String = text.chars().filter(|c| !c.is_whitespace()).collect();
    let bytes = base64::engine::general_purpose::STANDARD
        .decode(clean.as_bytes())
        .map_err(|e| format!("tile data is not valid base64: {e}"))?;
    let mut raw = Vec::new();
    let limit = MAX_CELLS * 4;
    let read = match attr(tag, "compression") {
        None => {
            raw = bytes.clone();
            Ok(0)
        }
        Some("zlib") => flate2::read::ZlibDecoder::new(&bytes[..])
            .take(limit)
            .read_to_end(&mut raw),
        Some("gzip") => flate2::read::GzDecoder::new(&bytes[..])
            .take(limit)
            .read_to_end(&mut raw),
        #[cfg(feature = "zstd")]
        Some("zstd") => zstd::stream::read::Decoder::new(&bytes[..])
            .and_then(|d| d.take(limit).read_to_end(&mut raw)),
        #[cfg(not(feature = "zstd"))]
        Some("zstd") => return Err(NO_ZSTD.to_owned()),
        Some(other) => {
            return Err(format!(
                "tile data compression \"{other}\" is not one of zlib, gzip, zstd"
            ));
        }
    };
    read.map_err(|e| format!("tile data does not decompress: {e}"))?;
    Ok(raw
        .chunks_exact(4)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect())
}
