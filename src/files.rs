//! Writing the user's files: never half a file. Each is written to a temporary file in the
//! same directory and renamed into place once complete, so a failure (a full disk, a
//! signal) leaves the old file as it was. A path is checked before long work starts, so a
//! missing directory fails at once, not after the work.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::Context;

/// The directory a file at `path` lives in (`.` for a bare file name).
fn directory(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_owned(),
        _ => PathBuf::from("."),
    }
}

fn temp_in(path: &Path) -> anyhow::Result<tempfile::NamedTempFile> {
    let name = path
        .file_name()
        .map_or_else(|| "out".to_owned(), |n| n.to_string_lossy().into_owned());
    tempfile::Builder::new()
        .prefix(&format!(".{name}."))
        .suffix(".tmp")
        .tempfile_in(directory(path))
        .with_context(|| format!("cannot write {}", path.display()))
}

/// Fails now if a file can't be created next to `path` (a missing directory, no
/// permission), before the work whose result goes there.
pub fn check_writable(path: &Path) -> anyhow::Result<()> {
    if path.is_dir() {
        anyhow::bail!("cannot write {}: it is a directory", path.display());
    }
    temp_in(path).map(drop)
}

/// Writes `bytes` to `path`: to a temporary file beside it, synced, then renamed over it.
pub fn write(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    let mut temp = temp_in(path)?;
    temp.write_all(bytes)
        .and_then(|()| temp.as_file().sync_all())
        .with_context(|| format!("writing {}", path.display()))?;
    temp.persist(path)
        .map_err(|e| e.error)
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(())
}
