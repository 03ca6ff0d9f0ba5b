//! Reading `[[bodies]]` one table at a time, so that loading a scene of half a million
//! bodies holds the text and the checked bodies, never the parser's tree of every body
//! (which costs several kilobytes a body).
//!
//! The text is cut at its table headers: each `[[bodies]]` table, with the `[bodies.*]`
//! sub-tables that follow it, is a chunk parsed on its own; the rest of the file (the
//! skeleton) is parsed with the chunks blanked out, byte for byte, so every offset and so
//! every error location stays that of the file (lines are counted in the file itself).

use std::ops::Range;

/// Where a header line starts a table: `Some((name, array))` for `[name]` (`array` false) or
/// `[[name]]` (true), `None` for any other line.
fn header(line: &str) -> Option<(&str, bool)> {
    let l = line.trim_start();
    if let Some(rest) = l.strip_prefix("[[") {
        return rest.split("]]").next().map(|n| (n.trim(), true));
    }
    let rest = l.strip_prefix('[')?;
    rest.split(']').next().map(|n| (n.trim(), false))
}

/// Whether a header belongs to the body table above it (`[bodies.shape]`).
fn in_body(name: &str) -> bool {
    name.strip_prefix("bodies")
        .is_some_and(|r| r.trim_start().starts_with('.'))
}

/// The byte ranges of the `[[bodies]]` tables, in file order, and the text with those ranges
/// blanked (every byte but each range's last newline made a space). `None` when the file has no such header
/// outside a multi-line string.
pub(crate) fn split_bodies(text: &str) -> Option<(String, Vec<Range<usize>>)> {
    let mut chunks: Vec<Range<usize>> = Vec::new();
    let mut open: Option<usize> = None;
    // Inside a multi-line string, a line that looks like a header is text.
    let mut in_string: Option<&str> = None;
    let mut at = 0;
    for line in text.split_inclusive('\n') {
        let start = at;
        at += line.len();
        if in_string.is_none()
            && let Some((name, array)) = header(line)
        {
            if array && name == "bodies" {
                if let Some(s) = open.take() {
                    chunks.push(s..start);
                }
                open = Some(start);
            } else if !in_body(name)
                && let Some(s) = open.take()
            {
                chunks.push(s..start);
            }
        }
        for quote in ["\"\"\"", "'''"] {
            let n = line.matches(quote).count();
            if n % 2 == 1 {
                in_string = match in_string {
                    Some(q) if q == quote => None,
                    None => Some(quote),
                    other => other,
                };
            }
        }
    }
    if let Some(s) = open {
        chunks.push(s..text.len());
    }
    if chunks.is_empty() {
        return None;
    }
    // One run of spaces a chunk (its last newline kept), so the skeleton costs the parser
    // one token a body, not one a line.
    let mut skeleton = text.as_bytes().to_vec();
    for c in &chunks {
        let end = if text[..c.end].ends_with('\n') {
            c.end - 1
        } else {
            c.end
        };
        skeleton[c.start..end].fill(b' ');
    }
    // Only whole lines were blanked, and spaces and newlines are ASCII: still UTF-8.
    String::from_utf8(skeleton).ok().map(|s| (s, chunks))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn body_tables_are_cut_out_with_their_sub_tables() {
        let text = "layers = [\"a\"]\n[[bodies]]\nlayer = \"a\"\n[bodies.shape]\nkind = \"circle\"\n\
                    radius = 1\n[[script]]\nframe = 1\n[[bodies]]\nlayer = \"a\"\n";
        let (skeleton, chunks) = split_bodies(text).unwrap();
        assert_eq!(chunks.len(), 2);
        assert_eq!(
            &text[chunks[0].clone()],
            "[[bodies]]\nlayer = \"a\"\n[bodies.shape]\nkind = \"circle\"\nradius = 1\n"
        );
        assert_eq!(&text[chunks[1].clone()], "[[bodies]]\nlayer = \"a\"\n");
        assert_eq!(skeleton.len(), text.len());
        assert!(skeleton.contains("[[script]]\nframe = 1\n"));
        assert!(!skeleton.contains("bodies"));
    }

    #[test]
    fn a_header_inside_a_multi_line_string_is_text() {
        let text = "name = \"\"\"\n[[bodies]]\n\"\"\"\nlayers = [\"a\"]\n";
        assert!(split_bodies(text).is_none());
    }
}
