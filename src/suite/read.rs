//! Reading what a `ricochet test` item compares, bounded: only regular files (a FIFO would
//! wait for a writer, a device may never end), the scenario up to `serve`'s `/load` limit,
//! a golden digest up to a few KiB, and logs compared a chunk at a time, never read whole.

use std::io::Read;
use std::path::Path;

use ricochet_serve::MAX_SCENARIO_BYTES;

/// Opens `path` for reading if it is a regular file: checked by name first (opening a FIFO
/// would wait for a writer, a device may never end), then on the file opened, so what is
/// read is what was checked. `None` when it does not exist; `what` names it in errors.
pub fn open_regular(path: &Path, what: &str) -> Result<Option<std::fs::File>, String> {
    let not_a_file = || {
        format!(
            "{what} {}: not a regular file (a FIFO, a device, a socket or a folder)",
            path.display()
        )
    };
    let unreadable = |e: std::io::Error| format!("cannot read {what} {}: {e}", path.display());
    match std::fs::metadata(path) {
        Ok(m) if !m.is_file() => return Err(not_a_file()),
        Ok(_) => {}
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(unreadable(e)),
    }
    let file = std::fs::File::open(path).map_err(unreadable)?;
    if !file.metadata().map_err(unreadable)?.is_file() {
        return Err(not_a_file());
    }
    Ok(Some(file))
}

/// The scenario's text: a regular file of at most [`MAX_SCENARIO_BYTES`] (`serve`'s
/// `/load` limit), read through a bounded reader so a file that grows while read can't
/// take more memory.
pub fn read_scenario(path: &Path) -> Result<String, String> {
    let shown = path.display();
    let Some(file) = open_regular(path, "the scenario")? else {
        return Err(format!("{shown}: No such file or directory"));
    };
    let too_large =
        || format!("{shown}: larger than {MAX_SCENARIO_BYTES} bytes, the most a scenario may have");
    let len = file.metadata().map_err(|e| format!("{shown}: {e}"))?.len();
    if len > MAX_SCENARIO_BYTES {
        return Err(too_large());
    }
    let mut bytes = Vec::new();
    file.take(MAX_SCENARIO_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("{shown}: {e}"))?;
    if bytes.len() as u64 > MAX_SCENARIO_BYTES {
        return Err(too_large());
    }
    String::from_utf8(bytes).map_err(|_| format!("{shown}: not UTF-8 text"))
}

/// The most of a golden `.digest` read: its three lines take under 100 bytes, so a larger
/// file differs whatever follows, and is never read whole.
const DIGEST_BYTES: u64 = 4096;

/// Reads a golden digest file (at most [`DIGEST_BYTES`] and one byte of it); `None` when
/// it does not exist.
pub fn read_golden(path: &Path) -> Result<Option<Vec<u8>>, String> {
    let Some(file) = open_regular(path, "the golden")? else {
        return Ok(None);
    };
    let mut bytes = Vec::new();
    file.take(DIGEST_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read the golden {}: {e}", path.display()))?;
    Ok(Some(bytes))
}

/// Whether two files hold the same bytes, read a chunk at a time (never whole): memory
/// stays flat whatever the logs' size.
pub fn same_bytes(a: std::fs::File, b: std::fs::File) -> std::io::Result<bool> {
    const CHUNK: usize = 64 << 10;
    let (len_a, len_b) = (a.metadata()?.len(), b.metadata()?.len());
    if len_a != len_b {
        return Ok(false);
    }
    // Bounded by the length seen, should either file grow while it is read.
    let (mut a, mut b) = (a.take(len_a), b.take(len_b));
    let (mut x, mut y) = (vec![0; CHUNK], vec![0; CHUNK]);
    loop {
        let n = fill(&mut a, &mut x)?;
        let m = fill(&mut b, &mut y)?;
        if n != m || x[..n] != y[..m] {
            return Ok(false);
        }
        if n < CHUNK {
            return Ok(true);
        }
    }
}

/// Reads until `buf` is full or the end; the count read.
fn fill(r: &mut impl Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut n = 0;
    while n < buf.len() {
        match r.read(&mut buf[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(n)
}
