//! The package's process, as `cluster::run` handles it apart from its protocol: what of its
//! stderr is kept for an error, and how it is stopped.

use std::io::{BufRead, BufReader};
use std::process::Child;

use super::POLL;

/// The package's stderr kept for its error: the last [`TAIL_LINES`] lines, each cut at
/// [`TAIL_LINE_BYTES`], so a chatty package (Dask's warnings over a long run) costs bounded
/// memory. Read to the end, so the package never blocks on a full pipe.
pub(super) fn tail(stream: impl std::io::Read) -> String {
    let mut lines = std::collections::VecDeque::new();
    let mut line = Vec::new();
    let mut reader = BufReader::new(stream);
    loop {
        let chunk = match reader.fill_buf() {
            Ok([]) | Err(_) => break,
            Ok(chunk) => chunk,
        };
        let (part, used, ended) = match chunk.iter().position(|b| *b == b'\n') {
            Some(n) => (&chunk[..n], n + 1, true),
            None => (chunk, chunk.len(), false),
        };
        let room = TAIL_LINE_BYTES.saturating_sub(line.len());
        line.extend_from_slice(&part[..part.len().min(room)]);
        reader.consume(used);
        if ended {
            if lines.len() == TAIL_LINES {
                lines.pop_front();
            }
            lines.push_back(String::from_utf8_lossy(&std::mem::take(&mut line)).into_owned());
        }
    }
    if !line.is_empty() {
        if lines.len() == TAIL_LINES {
            lines.pop_front();
        }
        lines.push_back(String::from_utf8_lossy(&line).into_owned());
    }
    lines.into_iter().map(|l| l + "\n").collect()
}

/// How many of the package's last stderr lines [`tail`] keeps: a Python traceback's.
const TAIL_LINES: usize = 64;

/// The longest stderr line [`tail`] keeps, in bytes; the rest of it is dropped.
const TAIL_LINE_BYTES: usize = 4096;

/// Ends the package on Ctrl-C: SIGINT first (its client closes and cancels the items),
/// SIGKILL if it is still there a second later.
pub(super) fn stop_child(child: &mut Child) {
    if let Ok(pid) = i32::try_from(child.id()) {
        use nix::sys::signal::{Signal, kill};
        let _ = kill(nix::unistd::Pid::from_raw(pid), Signal::SIGINT);
    }
    for _ in 0..20 {
        if let Ok(Some(_)) = child.try_wait() {
            return;
        }
        std::thread::sleep(POLL);
    }
    let _ = child.kill();
}

#[cfg(test)]
mod tests {
    use super::tail;

    #[test]
    fn the_packages_stderr_is_kept_bounded_and_its_last_line_whole() {
        // 1,000 lines of 10 KiB, then the error: 10 MB read, at most 64 lines of 4 KiB kept.
        let mut text = Vec::new();
        for _ in 0..1000 {
            text.extend(std::iter::repeat_n(b'w', 10 * 1024));
            text.push(b'\n');
        }
        text.extend_from_slice(b"MemoryError\n");
        let kept = tail(&text[..]);
        assert!(kept.len() <= 64 * (4096 + 1), "{} bytes kept", kept.len());
        assert_eq!(kept.lines().count(), 64);
        assert_eq!(kept.lines().last(), Some("MemoryError"));
        assert!(kept.lines().next().is_some_and(|l| l.len() == 4096));
        assert_eq!(tail(&b"one\ntwo"[..]), "one\ntwo\n");
    }
}
