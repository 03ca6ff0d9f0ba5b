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

/// Where the TOML scanner is at the end of a line: inside a multi-line string, or how deep
/// inside arrays and inline tables (a value may span lines; a header line never does).
#[derive(Default)]
struct Scanner {
    /// The closing quotes of the multi-line string we are in.
    string: Option<&'static str>,
    /// `[` and `{` opened by values and not yet closed.
    depth: usize,
}

impl Scanner {
    fn at_top(&self) -> bool {
        self.string.is_none() && self.depth == 0
    }

    /// Follows one line. A line that is a header (at the top) opens no value: it is skipped.
    fn line(&mut self, line: &str) {
        let b = line.as_bytes();
        let mut k = 0;
        if self.at_top() && header(line).is_some() {
            return;
        }
        while k < b.len() {
            if let Some(close) = self.string {
                match line[k..].find(close) {
                    Some(at) => {
                        self.string = None;
                        k += at + close.len();
                        continue;
                    }
                    None => return,
                }
            }
            match b[k] {
                b'#' => return,
                q @ (b'"' | b'\'') => {
                    let triple = if q == b'"' { "\"\"\"" } else { "\'\'\'" };
                    if line[k..].starts_with(triple) {
                        self.string = Some(triple);
                        k += 3;
                        continue;
                    }
                    // A one-line string: to its closing quote (basic strings escape with \).
                    k += 1;
                    while k < b.len() && b[k] != q {
                        k += if q == b'"' && b[k] == b'\\' { 2 } else { 1 };
                    }
                }
                b'[' | b'{' => self.depth += 1,
                b']' | b'}' => self.depth = self.depth.saturating_sub(1),
                _ => {}
            }
            k += 1;
        }
    }
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
    let mut scan = Scanner::default();
    let mut at = 0;
    for line in text.split_inclusive('\n') {
        let start = at;
        at += line.len();
        // A header starts a line outside any string, array or inline table.
        if scan.at_top()
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
        scan.line(line);
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
    fn a_line_of_a_multi_line_array_is_no_header() {
        let text = "layers = [\"a\"]\n[[bodies]]\nlayer = \"a\"\nshape = { kind = \"polygon\", vertices = [\n  [1, 0], [0, 1], [-1, 0],\n] }\n[[bodies]]\nlayer = \"a\"\n";
        let (_, chunks) = split_bodies(text).unwrap();
        assert_eq!(chunks.len(), 2);
        assert!(text[chunks[0].clone()].ends_with("] }\n"));
    }

    #[test]
    fn a_header_inside_a_multi_line_string_is_text() {
        let text = "name = \"\"\"\n[[bodies]]\n\"\"\"\nlayers = [\"a\"]\n";
        assert!(split_bodies(text).is_none());
    }
}
