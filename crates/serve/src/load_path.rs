//! Where `/load` may read a scenario from: a regular file whose resolved path (every symlink
//! followed) is below the server's directory (resolved likewise), of at most
//! [`MAX_SCENARIO_BYTES`], read through a bounded reader so a file that grows while being
//! read (or a device that passes for a file) cannot take more.

use std::fmt;
use std::io::Read;
use std::path::{Path, PathBuf};

/// The largest scenario `/load` reads: 16 MiB, some 150,000 bodies in TOML (a 100,000-body
/// file is about 8 MB), far past what steps in real time.
pub const MAX_SCENARIO_BYTES: u64 = 16 << 20;

/// Why `/load` refused a path; its text is the service call's failure message.
#[derive(Debug)]
pub enum LoadPathError {
    /// The path or the server's directory does not resolve, or the file can't be read.
    Unreadable {
        /// The path asked for.
        path: String,
        /// Why.
        source: std::io::Error,
    },
    /// It resolves outside the server's directory (through `..` or a symlink).
    Outside {
        /// The path asked for.
        path: String,
        /// Where it resolves.
        resolved: PathBuf,
        /// The server's directory, resolved.
        root: PathBuf,
    },
    /// It is a directory, a device, a FIFO or a socket.
    NotAFile {
        /// The path asked for.
        path: String,
    },
    /// It is larger than [`MAX_SCENARIO_BYTES`].
    TooLarge {
        /// The path asked for.
        path: String,
    },
    /// It is not UTF-8 text.
    NotText {
        /// The path asked for.
        path: String,
    },
}

impl fmt::Display for LoadPathError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LoadPathError::Unreadable { path, source } => write!(f, "{path}: {source}"),
            LoadPathError::Outside {
                path,
                resolved,
                root,
            } => write!(
                f,
                "{path}: resolves to {}, outside the server's directory {}",
                resolved.display(),
                root.display()
            ),
            LoadPathError::NotAFile { path } => {
                write!(f, "{path}: not a regular file (a scenario is a TOML file)")
            }
            LoadPathError::TooLarge { path } => write!(
                f,
                "{path}: larger than {MAX_SCENARIO_BYTES} bytes, the most a scenario may have"
            ),
            LoadPathError::NotText { path } => write!(f, "{path}: not UTF-8 text"),
        }
    }
}

impl std::error::Error for LoadPathError {}

/// The text of the scenario file `path` (relative to `root`, the server's directory), if
/// it resolves below `root` to a regular file of at most [`MAX_SCENARIO_BYTES`].
pub fn read_below(root: &Path, path: &str) -> Result<String, LoadPathError> {
    let unreadable = |source| LoadPathError::Unreadable {
        path: path.to_owned(),
        source,
    };
    let root = root.canonicalize().map_err(unreadable)?;
    let resolved = root.join(path).canonicalize().map_err(unreadable)?;
    if !resolved.starts_with(&root) {
        return Err(LoadPathError::Outside {
            path: path.to_owned(),
            resolved,
            root,
        });
    }
    // Checked by name first (opening a FIFO would wait for a writer), then on the file
    // opened: what is read is what was checked.
    let not_a_file = || LoadPathError::NotAFile {
        path: path.to_owned(),
    };
    if !std::fs::metadata(&resolved).map_err(unreadable)?.is_file() {
        return Err(not_a_file());
    }
    let file = std::fs::File::open(&resolved).map_err(unreadable)?;
    let meta = file.metadata().map_err(unreadable)?;
    if !meta.is_file() {
        return Err(not_a_file());
    }
    if meta.len() > MAX_SCENARIO_BYTES {
        return Err(LoadPathError::TooLarge {
            path: path.to_owned(),
        });
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(MAX_SCENARIO_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(unreadable)?;
    if bytes.len() as u64 > MAX_SCENARIO_BYTES {
        return Err(LoadPathError::TooLarge {
            path: path.to_owned(),
        });
    }
    String::from_utf8(bytes).map_err(|_| LoadPathError::NotText {
        path: path.to_owned(),
    })
}

/// The scenario `/load` asks for (below the server's working directory), checked; the
/// located error as the call's failure message.
pub fn load(path: &str) -> Result<(ricochet_sim::Scenario, String), String> {
    let root = std::env::current_dir().map_err(|e| format!("{path}: {e}"))?;
    let text = read_below(&root, path).map_err(|e| e.to_string())?;
    let scenario = ricochet_sim::load_scenario(&text, path).map_err(|e| e.to_string())?;
    Ok((scenario, text))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_symlink_out_of_the_directory_a_device_and_a_large_file_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path().join("srv");
        std::fs::create_dir_all(root.join("d")).unwrap();
        std::fs::write(dir.path().join("elsewhere.toml"), "layers = []\n").unwrap();
        std::fs::write(root.join("d/in.toml"), "layers = []\n").unwrap();
        std::os::unix::fs::symlink("../../elsewhere.toml", root.join("d/out.toml")).unwrap();
        std::os::unix::fs::symlink("in.toml", root.join("d/alias.toml")).unwrap();
        std::os::unix::fs::symlink("/dev/zero", root.join("zero.toml")).unwrap();
        let fifo = std::process::Command::new("mkfifo")
            .arg(root.join("fifo.toml"))
            .status()
            .unwrap();
        assert!(fifo.success());
        let big = std::fs::File::create(root.join("big.toml")).unwrap();
        big.set_len(MAX_SCENARIO_BYTES + 1).unwrap();
        assert_eq!(read_below(&root, "d/in.toml").unwrap(), "layers = []\n");
        assert_eq!(read_below(&root, "d/alias.toml").unwrap(), "layers = []\n");
        assert!(matches!(
            read_below(&root, "d/out.toml"),
            Err(LoadPathError::Outside { .. })
        ));
        assert!(matches!(
            read_below(&root, "zero.toml"),
            Err(LoadPathError::Outside { .. })
        ));
        assert!(matches!(
            read_below(&root, "fifo.toml"),
            Err(LoadPathError::NotAFile { .. })
        ));
        // A device below the directory is no file either (and is never read).
        assert!(matches!(
            read_below(Path::new("/dev"), "zero"),
            Err(LoadPathError::NotAFile { .. })
        ));
        assert!(matches!(
            read_below(&root, "d"),
            Err(LoadPathError::NotAFile { .. })
        ));
        assert!(matches!(
            read_below(&root, "big.toml"),
            Err(LoadPathError::TooLarge { .. })
        ));
        assert!(matches!(
            read_below(&root, "missing.toml"),
            Err(LoadPathError::Unreadable { .. })
        ));
    }
}
