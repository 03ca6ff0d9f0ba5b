//! A case file read as a stream, one case at a time, from any reader the caller opened: a
//! `{"meta": ..., "cases": [...]}` document or JSON lines. Memory is bounded by the largest
//! case ([`MAX_CASE_BYTES`]), whatever the file's length, and the document's own keys are
//! checked as strictly as a case's: `meta` and `cases` only, each at most once.

use std::io::BufRead;

use crate::case::{Case, CaseError, cut, parse_case};

/// The longest case (a line of JSON lines, or an element of `cases`), in bytes: two
/// compounds of [`crate::MAX_COMPOUND_PARTS`] polygons of 8 vertices take about 1 MB.
pub const MAX_CASE_BYTES: usize = 4 << 20;

/// How far ahead the first key of a document is looked for (after the blanks that open the
/// file): a file whose first object has no `cases` or `meta` key that soon is JSON lines.
const LOOK_AHEAD: usize = 4096;

/// The cases of a case file, read one at a time: each is a case or the error that case has.
/// An error in the document's own structure (an unknown or repeated key, a syntax error
/// between cases) ends the reading, since nothing after it can be located.
pub struct CaseReader<R> {
    input: R,
    /// Bytes read ahead to tell a document from JSON lines: read again before `input`.
    ahead: Vec<u8>,
    ahead_at: usize,
    /// 1-based line of the next byte.
    line: usize,
    state: State,
    seen_cases: bool,
    seen_meta: bool,
}

enum State {
    Start,
    Lines,
    /// Before a key of the document (after its `{`, or after a `,`).
    Key {
        after_comma: bool,
    },
    /// Before an element of `cases` (after its `[`, or after a `,`).
    Case {
        after_comma: bool,
    },
    /// After an element of `cases`: a `,` or the `]`.
    AfterCase,
    /// After a key's value: a `,` or the `}`.
    AfterValue,
    Done,
}

/// A value or line taken from the input.
enum Taken {
    Bytes(Vec<u8>),
    /// Longer than the limit: this many bytes, skipped.
    TooLong(usize),
}

impl<R: BufRead> CaseReader<R> {
    /// Reads cases from `input`.
    pub fn new(input: R) -> CaseReader<R> {
        CaseReader {
            input,
            ahead: Vec::new(),
            ahead_at: 0,
            line: 1,
            state: State::Start,
            seen_cases: false,
            seen_meta: false,
        }
    }

    fn buf(&mut self) -> std::io::Result<&[u8]> {
        if self.ahead_at < self.ahead.len() {
            Ok(&self.ahead[self.ahead_at..])
        } else {
            self.input.fill_buf()
        }
    }

    /// Consumes the first `n` bytes of [`buf`](Self::buf), counting lines.
    fn consume(&mut self, n: usize) {
        if self.ahead_at < self.ahead.len() {
            let taken = &self.ahead[self.ahead_at..self.ahead_at + n];
            self.line += taken.iter().filter(|b| **b == b'\n').count();
            self.ahead_at += n;
            if self.ahead_at == self.ahead.len() {
                self.ahead = Vec::new();
                self.ahead_at = 0;
            }
        } else {
            if let Ok(buf) = self.input.fill_buf() {
                self.line += buf[..n].iter().filter(|b| **b == b'\n').count();
            }
            self.input.consume(n);
        }
    }

    fn peek(&mut self) -> std::io::Result<Option<u8>> {
        Ok(self.buf()?.first().copied())
    }

    fn skip_blanks(&mut self) -> std::io::Result<()> {
        loop {
            let buf = self.buf()?;
            let n = buf.iter().take_while(|b| b.is_ascii_whitespace()).count();
            let all = n == buf.len();
            if buf.is_empty() {
                return Ok(());
            }
            self.consume(n);
            if !all {
                return Ok(());
            }
        }
    }

    /// One JSON value's text, from the next byte: an object, array or string by its
    /// brackets and quotes, anything else up to the next delimiter. The grammar inside is
    /// left to the parser; at the end of the input, what there was.
    fn take_value(&mut self, limit: usize) -> std::io::Result<Taken> {
        let mut scan = Scan::default();
        let (mut out, mut len) = (Vec::new(), 0usize);
        loop {
            let buf = self.buf()?;
            if buf.is_empty() {
                break;
            }
            let (n, done) = scan.scan(buf);
            if len + n <= limit {
                out.extend_from_slice(&buf[..n]);
            } else if !out.is_empty() {
                out = Vec::new();
            }
            len += n;
            self.consume(n);
            if done {
                break;
            }
        }
        Ok(if len > limit {
            Taken::TooLong(len)
        } else {
            Taken::Bytes(out)
        })
    }

    /// The next line's text (its newline consumed, not included); `None` at the end.
    fn take_line(&mut self, limit: usize) -> std::io::Result<Option<Taken>> {
        let (mut out, mut len, mut any) = (Vec::new(), 0usize, false);
        loop {
            let buf = self.buf()?;
            if buf.is_empty() {
                break;
            }
            any = true;
            let (n, end) = match buf.iter().position(|b| *b == b'\n') {
                Some(i) => (i, true),
                None => (buf.len(), false),
            };
            if len + n <= limit {
                out.extend_from_slice(&buf[..n]);
            } else if !out.is_empty() {
                out = Vec::new();
            }
            len += n;
            self.consume(n + usize::from(end));
            if end {
                break;
            }
        }
        Ok(any.then_some(if len > limit {
            Taken::TooLong(len)
        } else {
            Taken::Bytes(out)
        }))
    }

    /// Whether the input is a document: its first object's first key is `cases` or `meta`,
    /// within [`LOOK_AHEAD`] bytes. What it reads stays to be read again.
    fn is_document(&mut self) -> std::io::Result<bool> {
        loop {
            match first_key(&self.ahead[self.ahead_at..]) {
                Some(key) => return Ok(key == b"cases" || key == b"meta"),
                None if self.ahead.len() - self.ahead_at >= LOOK_AHEAD => return Ok(false),
                None => {}
            }
            let buf = self.input.fill_buf()?;
            let n = buf.len().min(LOOK_AHEAD);
            if n == 0 {
                return Ok(false);
            }
            self.ahead.extend_from_slice(&buf[..n]);
            self.input.consume(n);
        }
    }

    /// An error in the document's structure, at the current line: the last item.
    fn fatal(&mut self, field: &str, problem: String) -> Option<Result<Case, CaseError>> {
        self.state = State::Done;
        Some(Err(CaseError {
            id: None,
            line: Some(self.line),
            field: cut(field),
            problem,
        }))
    }

    fn step(&mut self) -> std::io::Result<Option<Result<Case, CaseError>>> {
        loop {
            match self.state {
                State::Done => return Ok(None),
                State::Start => {
                    self.skip_blanks()?;
                    if self.is_document()? {
                        self.skip_blanks()?;
                        self.consume(1);
                        self.state = State::Key { after_comma: false };
                    } else {
                        self.state = State::Lines;
                    }
                }
                State::Lines => {
                    let line = self.line;
                    match self.take_line(MAX_CASE_BYTES)? {
                        None => self.state = State::Done,
                        Some(Taken::TooLong(n)) => return Ok(Some(Err(too_long(line, n)))),
                        Some(Taken::Bytes(text)) if text.iter().all(u8::is_ascii_whitespace) => {}
                        Some(Taken::Bytes(text)) => return Ok(Some(parse_case(&text, Some(line)))),
                    }
                }
                State::Key { after_comma } => {
                    self.skip_blanks()?;
                    match self.peek()? {
                        Some(b'}') if !after_comma => {
                            self.consume(1);
                            return Ok(self.end());
                        }
                        Some(b'"') => {}
                        other => {
                            return Ok(self.fatal(
                                "json",
                                format!("expected a key of the document, found {}", found(other)),
                            ));
                        }
                    }
                    let key = match self.take_value(LOOK_AHEAD)? {
                        Taken::TooLong(n) => {
                            return Ok(self.fatal(
                                "json",
                                format!("a key of {n} bytes; the document has `meta` and `cases`"),
                            ));
                        }
                        Taken::Bytes(b) => match serde_json::from_slice::<String>(&b) {
                            Ok(k) => k,
                            Err(e) => return Ok(self.fatal("json", e.to_string())),
                        },
                    };
                    self.skip_blanks()?;
                    if self.peek()? != Some(b':') {
                        let f = found(self.peek()?);
                        return Ok(
                            self.fatal(&key, format!("expected `:` after the key, found {f}"))
                        );
                    }
                    self.consume(1);
                    self.skip_blanks()?;
                    let seen = match key.as_str() {
                        "cases" => &mut self.seen_cases,
                        "meta" => &mut self.seen_meta,
                        _ => {
                            return Ok(self.fatal(
                                &key,
                                "unknown key; a case document has only `meta` and `cases`"
                                    .to_owned(),
                            ));
                        }
                    };
                    if std::mem::replace(seen, true) {
                        return Ok(self.fatal(
                            &key,
                            "given twice; a case document has one (the second would silently \
                             replace the first)"
                                .to_owned(),
                        ));
                    }
                    if key == "cases" {
                        if self.peek()? != Some(b'[') {
                            return Ok(self.fatal("cases", "must be a list of cases".to_owned()));
                        }
                        self.consume(1);
                        self.state = State::Case { after_comma: false };
                    } else {
                        let valid = match self.take_value(MAX_CASE_BYTES)? {
                            Taken::TooLong(n) => Err(format!(
                                "{n} bytes, more than the {MAX_CASE_BYTES} a value may have"
                            )),
                            Taken::Bytes(b) => serde_json::from_slice::<serde::de::IgnoredAny>(&b)
                                .map(|_| ())
                                .map_err(|e| e.to_string()),
                        };
                        if let Err(e) = valid {
                            return Ok(self.fatal("meta", e));
                        }
                        self.state = State::AfterValue;
                    }
                }
                State::Case { after_comma } => {
                    self.skip_blanks()?;
                    match self.peek()? {
                        Some(b']') if !after_comma => {
                            self.consume(1);
                            self.state = State::AfterValue;
                        }
                        None => {
                            return Ok(self.fatal(
                                "cases",
                                "the input ends inside the list of cases".to_owned(),
                            ));
                        }
                        Some(_) => {
                            let line = self.line;
                            let case = match self.take_value(MAX_CASE_BYTES)? {
                                Taken::TooLong(n) => Err(too_long(line, n)),
                                Taken::Bytes(text) => parse_case(&text, Some(line)),
                            };
                            self.state = State::AfterCase;
                            return Ok(Some(case));
                        }
                    }
                }
                State::AfterCase => {
                    self.skip_blanks()?;
                    match self.peek()? {
                        Some(b',') => {
                            self.consume(1);
                            self.state = State::Case { after_comma: true };
                        }
                        Some(b']') => {
                            self.consume(1);
                            self.state = State::AfterValue;
                        }
                        other => {
                            return Ok(self.fatal(
                                "cases",
                                format!("expected `,` or `]` after a case, found {}", found(other)),
                            ));
                        }
                    }
                }
                State::AfterValue => {
                    self.skip_blanks()?;
                    match self.peek()? {
                        Some(b',') => {
                            self.consume(1);
                            self.state = State::Key { after_comma: true };
                        }
                        Some(b'}') => {
                            self.consume(1);
                            return Ok(self.end());
                        }
                        other => {
                            return Ok(self.fatal(
                                "json",
                                format!(
                                    "expected `,` or `}}` in the document, found {}",
                                    found(other)
                                ),
                            ));
                        }
                    }
                }
            }
        }
    }

    /// After the document's `}`: nothing but blanks may follow, and it must have had cases.
    fn end(&mut self) -> Option<Result<Case, CaseError>> {
        if let Err(e) = self.skip_blanks() {
            return self.fatal("input", format!("cannot read: {e}"));
        }
        match self.peek() {
            Err(e) => return self.fatal("input", format!("cannot read: {e}")),
            Ok(Some(b)) => {
                return self.fatal(
                    "json",
                    format!("text after the document's closing `}}`: {}", found(Some(b))),
                );
            }
            Ok(None) => {}
        }
        if !self.seen_cases {
            return self.fatal("cases", "the document has no `cases` list".to_owned());
        }
        self.state = State::Done;
        None
    }
}

impl<R: BufRead> Iterator for CaseReader<R> {
    type Item = Result<Case, CaseError>;

    fn next(&mut self) -> Option<Self::Item> {
        match self.step() {
            Ok(item) => item,
            Err(e) => self.fatal("input", format!("cannot read: {e}")),
        }
    }
}

fn too_long(line: usize, bytes: usize) -> CaseError {
    CaseError {
        id: None,
        line: Some(line),
        field: "case".to_owned(),
        problem: format!(
            "{bytes} bytes, more than the {MAX_CASE_BYTES} a case may have (skipped unread)"
        ),
    }
}

/// A byte found where another was expected, for messages.
fn found(b: Option<u8>) -> String {
    match b {
        None => "the end of the input".to_owned(),
        Some(b) if b.is_ascii_graphic() => format!("`{}`", char::from(b)),
        Some(b) => format!("byte {b:#04x}"),
    }
}

/// The first key of the object `text` opens with, once it is all there: `Some(b"")` when
/// `text` does not open an object with a key.
fn first_key(text: &[u8]) -> Option<&[u8]> {
    let Some((&b'{', rest)) = text.split_first() else {
        return if text.is_empty() { None } else { Some(b"") };
    };
    let rest = &rest[rest.iter().take_while(|b| b.is_ascii_whitespace()).count()..];
    match rest.split_first() {
        None => None,
        Some((&b'"', key)) => {
            // The shared keys have no escapes: a key with one is not theirs.
            let end = key.iter().position(|b| *b == b'"' || *b == b'\\')?;
            Some(if key[end] == b'"' { &key[..end] } else { b"" })
        }
        Some(_) => Some(b""),
    }
}

/// Where a JSON value ends, fed its text a piece at a time.
#[derive(Default)]
struct Scan {
    started: bool,
    /// A number, `true`, `false` or `null`: ends at a delimiter.
    scalar: bool,
    depth: usize,
    in_string: bool,
    escape: bool,
}

impl Scan {
    /// How many bytes of `buf` belong to the value, and whether it ends there.
    fn scan(&mut self, buf: &[u8]) -> (usize, bool) {
        for (i, &b) in buf.iter().enumerate() {
            if !self.started {
                self.started = true;
                match b {
                    b'{' | b'[' => {
                        self.depth = 1;
                        continue;
                    }
                    b'"' => {
                        self.in_string = true;
                        continue;
                    }
                    _ => self.scalar = true,
                }
            }
            if self.scalar {
                if matches!(b, b',' | b']' | b'}') || b.is_ascii_whitespace() {
                    return (i, true);
                }
            } else if self.in_string {
                if self.escape {
                    self.escape = false;
                } else if b == b'\\' {
                    self.escape = true;
                } else if b == b'"' {
                    self.in_string = false;
                    if self.depth == 0 {
                        return (i + 1, true);
                    }
                }
            } else {
                match b {
                    b'"' => self.in_string = true,
                    b'{' | b'[' => self.depth += 1,
                    b'}' | b']' => {
                        self.depth -= 1;
                        if self.depth == 0 {
                            return (i + 1, true);
                        }
                    }
                    _ => {}
                }
            }
        }
        (buf.len(), false)
    }
}
