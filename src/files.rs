//! Writing the user's files: never half a file. Each is written to a temporary file in the
//! same directory and renamed into place once complete, so a failure (a full disk, a
//! signal) leaves the old file as it was. A path is checked before long work starts, so a
//! missing directory fails at once, not after the work.
//!
//! An output is refused when it is not a place for a file: a directory, or anything already
//! there that is not a regular file (`/dev/null` and other devices, a FIFO, a socket: a
//! rename would replace the device node). A command with several outputs checks them as a
//! set ([`check_outputs`]: no two the same file, none one of the command's inputs) and
//! writes them all or none ([`write_all`]). Files are created as `File::create` creates
//! them: read and write for all, less the umask.

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

/// Where a write to `path` lands: an existing symbolic link is followed, so the file it
/// points to is replaced, not the link (as `run -o` does).
fn target(path: &Path) -> PathBuf {
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.file_type().is_symlink() => {
            path.canonicalize().unwrap_or_else(|_| path.to_owned())
        }
        _ => path.to_owned(),
    }
}

fn temp_in(path: &Path) -> anyhow::Result<tempfile::NamedTempFile> {
    let name = path
        .file_name()
        .map_or_else(|| "out".to_owned(), |n| n.to_string_lossy().into_owned());
    // A long name stays a legal one: the temporary name keeps at most 100 bytes of it.
    let mut short = String::new();
    for c in name.chars() {
        if short.len() + c.len_utf8() > 100 {
            break;
        }
        short.push(c);
    }
    let prefix = format!(".{short}.");
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp");
    #[cfg(unix)]
    {
        // Read and write for all, less the umask: what `File::create` gives.
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    builder
        .tempfile_in(directory(path))
        .with_context(|| format!("cannot write {}", path.display()))
}

/// Fails now if `path` can't take an output: it is a directory, or something that is not a
/// regular file (a device, a FIFO, a socket), or no file can be created beside it (a
/// missing directory, no permission). Before the work whose result goes there.
pub fn check_writable(path: &Path) -> anyhow::Result<()> {
    if path.is_dir() {
        anyhow::bail!("cannot write {}: it is a directory", path.display());
    }
    if std::fs::metadata(path).is_ok_and(|m| !m.is_file()) {
        anyhow::bail!(
            "cannot write {}: it is not a regular file (a device, a FIFO or a socket); \
             name a file",
            path.display()
        );
    }
    temp_in(&target(path)).map(drop)
}

/// One file's identity, to tell whether two paths name the same file: the [`resolved`] path
/// (symbolic links and `..` followed, existing yet or not), and for an existing file its
/// device and inode (hard links).
#[derive(Debug)]
struct Identity {
    resolved: PathBuf,
    #[cfg(unix)]
    inode: Option<(u64, u64)>,
}

impl Identity {
    fn of(path: &Path) -> Self {
        let resolved = resolved(path);
        Self {
            #[cfg(unix)]
            inode: {
                use std::os::unix::fs::MetadataExt;
                std::fs::metadata(path).ok().map(|m| (m.dev(), m.ino()))
            },
            resolved,
        }
    }

    fn same(&self, other: &Self) -> bool {
        #[cfg(unix)]
        if let (Some(a), Some(b)) = (self.inode, other.inode) {
            return a == b;
        }
        self.resolved == other.resolved
    }
}

/// Whether `a` and `b` name the same file, by resolved path or (both existing) by inode.
pub fn same_file(a: &Path, b: &Path) -> bool {
    Identity::of(a).same(&Identity::of(b))
}

/// Checks a command's outputs as a set before its work: each one [`check_writable`], no two
/// of them the same file, and none of them one of the command's `inputs` (which the output
/// would overwrite). `outputs` pairs each path with the flag that named it, for the message.
pub fn check_outputs(outputs: &[(&str, &Path)], inputs: &[&Path]) -> anyhow::Result<()> {
    for (i, (flag, path)) in outputs.iter().enumerate() {
        check_writable(path).with_context(|| format!("{flag} {}", path.display()))?;
        let me = Identity::of(path);
        for (other_flag, other) in &outputs[..i] {
            if me.same(&Identity::of(other)) {
                anyhow::bail!(
                    "{flag} {} is the same file as {other_flag} {}: give each output a path \
                     of its own",
                    path.display(),
                    other.display()
                );
            }
        }
        for input in inputs {
            if me.same(&Identity::of(input)) {
                anyhow::bail!(
                    "{flag} {} is {}, an input of this run: writing it would overwrite the \
                     input; name another file",
                    path.display(),
                    input.display()
                );
            }
        }
    }
    Ok(())
}

/// Writes `bytes` to `path`: to a temporary file beside it, synced, then renamed over it.
pub fn write(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    write_all(&[(path, bytes)])
}

/// [`write()`], the bytes streamed from the file `from` rather than held in memory.
pub fn copy(path: &Path, from: &Path) -> anyhow::Result<()> {
    check_writable(path)?;
    let target = target(path);
    let mut temp = temp_in(&target)?;
    let mut source =
        std::fs::File::open(from).with_context(|| format!("reading {}", from.display()))?;
    std::io::copy(&mut source, &mut temp)
        .and_then(|_| temp.as_file().sync_all())
        .with_context(|| format!("writing {}", path.display()))?;
    temp.persist(&target)
        .map_err(|e| e.error)
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(())
}

/// The path `path` resolves to: its longest existing ancestor with every symbolic link
/// followed, then the rest with `.` and `..` taken lexically (a part that does not exist
/// can't be a link). Two paths to one place, existing yet or not, resolve alike.
pub fn resolved(path: &Path) -> PathBuf {
    let absolute = if path.is_absolute() {
        path.to_owned()
    } else {
        std::env::current_dir().map_or_else(|_| path.to_owned(), |d| d.join(path))
    };
    let mut base = absolute.as_path();
    let mut rest = Vec::new();
    loop {
        if let Ok(found) = base.canonicalize() {
            let mut out = found;
            for part in rest.iter().rev() {
                match part {
                    std::path::Component::ParentDir => {
                        out.pop();
                    }
                    std::path::Component::CurDir => {}
                    other => out.push(other.as_os_str()),
                }
            }
            return out;
        }
        match (base.parent(), base.components().next_back()) {
            (Some(up), Some(last)) => {
                rest.push(last);
                base = up;
            }
            _ => return absolute,
        }
    }
}

/// Writes every `(path, bytes)` all or nothing: each to a temporary file beside it, synced;
/// only when all are complete are they renamed into place. A failure before the renames
/// (a full disk, no permission) leaves every old file as it was.
pub fn write_all(outputs: &[(&Path, &[u8])]) -> anyhow::Result<()> {
    let mut ready = Vec::with_capacity(outputs.len());
    for (path, bytes) in outputs {
        check_writable(path)?;
        let target = target(path);
        let mut temp = temp_in(&target)?;
        temp.write_all(bytes)
            .and_then(|()| temp.as_file().sync_all())
            .with_context(|| format!("writing {}", path.display()))?;
        ready.push((path, target, temp));
    }
    for (path, target, temp) in ready {
        temp.persist(&target)
            .map_err(|e| e.error)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_device_is_refused_and_left_a_device() {
        let e = check_writable(Path::new("/dev/null")).unwrap_err();
        assert!(format!("{e:#}").contains("not a regular file"), "{e:#}");
        assert!(write(Path::new("/dev/null"), b"x").is_err());
        let m = std::fs::metadata("/dev/null").unwrap();
        assert!(!m.is_file(), "/dev/null was replaced by a regular file");
    }

    #[test]
    fn two_outputs_naming_one_file_or_an_input_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.csv");
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        let via_dots = dir.path().join("sub/../a.csv");
        let e = check_outputs(&[("--csv", &a), ("--svg", &via_dots)], &[]).unwrap_err();
        assert!(format!("{e:#}").contains("same file"), "{e:#}");
        let input = dir.path().join("game.toml");
        std::fs::write(&input, "x").unwrap();
        let e = check_outputs(&[("--csv", &input)], &[&input]).unwrap_err();
        assert!(format!("{e:#}").contains("an input"), "{e:#}");
        assert_eq!(std::fs::read(&input).unwrap(), b"x");
        check_outputs(
            &[("--csv", &a), ("--svg", &dir.path().join("a.svg"))],
            &[&input],
        )
        .unwrap();
    }

    #[test]
    fn a_set_fails_whole_when_one_output_cannot_be_written() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.csv");
        std::fs::write(&a, "old").unwrap();
        let missing = dir.path().join("no-such-dir/b.svg");
        assert!(write_all(&[(&a, b"new"), (&missing, b"x")]).is_err());
        assert_eq!(std::fs::read(&a).unwrap(), b"old");
        let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(left.len(), 1, "a temporary file was left: {left:?}");
    }

    #[cfg(unix)]
    #[test]
    fn files_are_created_with_the_umasks_permissions() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.csv");
        write(&a, b"x").unwrap();
        let mode = std::fs::metadata(&a).unwrap().permissions().mode() & 0o777;
        // The umask can be read only by setting it: compare with a file made the usual way.
        let b = dir.path().join("b");
        std::fs::File::create(&b).unwrap();
        let expected = std::fs::metadata(&b).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, expected);
    }

    #[test]
    fn paths_to_one_place_resolve_alike_whether_it_exists_or_not() {
        let dir = tempfile::tempdir().unwrap();
        let base = dir.path().canonicalize().unwrap();
        std::fs::create_dir_all(base.join("s2/sub")).unwrap();
        assert_eq!(
            resolved(&base.join("s2/sub/../../recordings")),
            base.join("recordings")
        );
        assert_eq!(resolved(&base.join("new/./a/../b")), base.join("new/b"));
        assert_eq!(resolved(&base.join("s2/sub/..")), base.join("s2"));
    }

    #[test]
    fn a_long_legal_name_is_written() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join(format!("{}.csv", "n".repeat(246)));
        write(&a, b"x").unwrap();
        assert_eq!(std::fs::read(&a).unwrap(), b"x");
    }
}
