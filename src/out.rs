//! Checked writes to standard output and standard error.
//!
//! `println!` and `eprintln!` panic (exit 101) when the stream can't be written: a full disk,
//! `> /dev/full`, a closed pipe. Every write of the binary goes through here instead and
//! returns the failure, so a command can decide: a closed pipe (`ricochet collide FILE |
//! head -1`) ends the command quietly with the exit code it had reached; any other failure
//! is an error with a message (on stderr, when stderr itself still works).

use std::fmt;
use std::io::{self, Write};

/// Which stream failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stream {
    /// Standard output.
    Stdout,
    /// Standard error.
    Stderr,
}

/// A failed write to standard output or standard error.
#[derive(Debug)]
pub struct WriteError {
    /// The stream.
    pub stream: Stream,
    /// Why.
    pub source: io::Error,
}

impl WriteError {
    /// Whether the reader went away (`EPIPE`): not an error of ours, nothing to report.
    pub fn is_closed(&self) -> bool {
        self.source.kind() == io::ErrorKind::BrokenPipe
    }
}

impl fmt::Display for WriteError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = match self.stream {
            Stream::Stdout => "standard output",
            Stream::Stderr => "standard error",
        };
        write!(f, "cannot write to {name}: {}", self.source)
    }
}

// No `source()`: the message already holds it, and `{:#}` would print it twice.
impl std::error::Error for WriteError {}

fn write(stream: Stream, text: &str) -> Result<(), WriteError> {
    let result = match stream {
        Stream::Stdout => {
            let mut s = io::stdout().lock();
            s.write_all(text.as_bytes()).and_then(|()| s.flush())
        }
        Stream::Stderr => io::stderr().lock().write_all(text.as_bytes()),
    };
    result.map_err(|source| WriteError { stream, source })
}

/// Writes `text` to standard output and flushes it.
pub fn print(text: &str) -> Result<(), WriteError> {
    write(Stream::Stdout, text)
}

/// Writes `text` to standard error.
pub fn eprint(text: &str) -> Result<(), WriteError> {
    write(Stream::Stderr, text)
}

/// Writes `text` and a newline to standard error; a closed pipe is ignored (the reader of
/// our diagnostics went away, the command goes on). For messages such as warnings and the
/// run summary, whose loss must not go unnoticed otherwise.
pub fn note(text: &str) -> Result<(), WriteError> {
    match eprint(&format!("{}\n", escape_controls_in_lines(text))) {
        Err(e) if e.is_closed() => Ok(()),
        other => other,
    }
}

/// Writes an error message and a newline to standard error, as well as it can: the caller
/// is about to exit with a non-zero code, which says what went wrong if the message can't.
pub fn error(text: &str) {
    let _ = eprint(&format!("{}\n", escape_controls_in_lines(text)));
}

/// [`escape_controls`] for a message of several lines: newlines and tabs are kept.
fn escape_controls_in_lines(text: &str) -> String {
    text.split('\n')
        .map(|line| {
            line.split('\t')
                .map(escape_controls)
                .collect::<Vec<_>>()
                .join("\t")
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// A name from a file, for printing, its control characters escaped (the log crate's, shared
/// with the messages it builds).
pub use ricochet_log::escape_controls;
