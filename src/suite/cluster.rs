//! `ricochet test --cluster tcp://HOST:PORT`: the items run on a Dask distributed cluster
//! instead of local processes (`pool.rs`), with the same argv and the same result lines.
//!
//! Ricochet does not schedule anything itself. It starts `python3 -m ricochet_dask` (the
//! package in `python/`, `pip install ./python`), writes one `{"argv": [...]}` line per item
//! on its stdin, and reads one line per item from its stdout as the items finish; the
//! package maps them over the user's scheduler and workers, and Dask retries a crashed item
//! and reruns a killed worker's items elsewhere. The merge stays here and in `mod.rs`: the
//! lines come back in any order and are put in item order, so the output is the same bytes
//! as a local run. `--verify` re-runs a sample of the items on a second worker (chosen by the
//! package), and an item whose two digests differ fails, naming both workers.
//!
//! Every worker runs this same binary at this same absolute path, with the scenarios, the
//! goldens and the logs' folder at the same paths: one machine, or a shared filesystem.

use std::ffi::OsString;
use std::io::{BufRead, BufReader, Write};
use std::net::{TcpStream, ToSocketAddrs};
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::Duration;

use serde::Deserialize;

use super::item::{FORMAT, ItemResult, Verdict, name_of};
use crate::out::escape_controls;

/// The Python that runs the package: `RICOCHET_PYTHON` if set (a venv's
/// `bin/python`), else `python3` on the PATH.
pub const PYTHON_VAR: &str = "RICOCHET_PYTHON";

/// How to install what the cluster run needs, said by every error that lacks it.
const INSTALL: &str = "install it with `pip install ./python` from Ricochet's repository \
     (it pulls in dask[distributed]), or set RICOCHET_PYTHON to a Python that has it";

/// How long the scheduler has to accept a TCP connection before the run gives up.
const CONNECT: Duration = Duration::from_secs(3);

/// How often the run looks at the stop flag while it waits for a line.
const POLL: Duration = Duration::from_millis(50);

/// Where and how to run the items.
#[derive(Debug, Clone)]
pub struct Cluster {
    /// The scheduler's address, `tcp://HOST:PORT`.
    pub scheduler: String,
    /// Re-run a sample of the items on a second worker and require identical digests.
    pub verify: bool,
}

/// Why a cluster run could not start or finish (exit code 2).
#[derive(Debug)]
pub enum ClusterError {
    /// The address is not `tcp://HOST:PORT`.
    BadAddress(String),
    /// Nothing accepts connections at the scheduler's address.
    Unreachable(String, String),
    /// The Python interpreter can't be started.
    NoPython(String, std::io::Error),
    /// The Python has no `ricochet_dask` package.
    NoPackage(String),
    /// The package is there but `distributed` is not.
    NoDistributed(String),
    /// An item's argument is not UTF-8 (the protocol is JSON).
    NotUtf8(OsString),
    /// The package failed; its last message.
    Failed(String),
}

impl std::fmt::Display for ClusterError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::BadAddress(a) => write!(
                f,
                "--cluster {}: expected tcp://HOST:PORT, the address of a Dask scheduler",
                escape_controls(a)
            ),
            Self::Unreachable(a, why) => write!(
                f,
                "--cluster {}: cannot reach the Dask scheduler: {why} (start one with \
                 `dask scheduler`, and workers with `dask worker ADDRESS`)",
                escape_controls(a)
            ),
            Self::NoPython(p, e) => {
                write!(f, "--cluster needs Python 3 with Ricochet's Dask package; ")?;
                write!(
                    f,
                    "{} cannot be started ({e}): {INSTALL}",
                    escape_controls(p)
                )
            }
            Self::NoPackage(p) => write!(
                f,
                "--cluster: {} has no package ricochet_dask: {INSTALL}",
                escape_controls(p)
            ),
            Self::NoDistributed(why) => write!(
                f,
                "--cluster: Dask distributed is missing ({}): {INSTALL}",
                escape_controls(why)
            ),
            Self::NotUtf8(a) => write!(
                f,
                "--cluster: the path {} is not UTF-8, which the cluster's JSON can't carry",
                escape_controls(&a.to_string_lossy())
            ),
            Self::Failed(why) => write!(f, "--cluster: {}", escape_controls(why)),
        }
    }
}

impl std::error::Error for ClusterError {}

/// A second run of an item on another worker (`--verify`).
#[derive(Deserialize)]
struct Verified {
    worker: Option<String>,
    result: Option<ItemResult>,
    error: Option<String>,
}

/// One line of the package's stdout.
#[derive(Deserialize)]
struct Line {
    index: usize,
    worker: Option<String>,
    result: Option<ItemResult>,
    verified: Option<Verified>,
    error: Option<String>,
}

/// Runs `args(i)` (the argv of `ricochet test --item`) for every item `i` in `0..count` on
/// the cluster, calling `done(i, result)` as each finishes (in any order), like
/// `pool::run`. When `stop` is set (Ctrl-C) the package is stopped and the items still out
/// get no result. Returns how many results came back.
pub fn run(
    cluster: &Cluster,
    count: usize,
    stop: &AtomicBool,
    args: impl Fn(usize) -> (PathBuf, Vec<OsString>),
    mut done: impl FnMut(usize, ItemResult),
) -> Result<usize, ClusterError> {
    reach(&cluster.scheduler)?;
    let mut input = String::new();
    for i in 0..count {
        let argv = args(i)
            .1
            .into_iter()
            .map(|a| a.into_string().map_err(ClusterError::NotUtf8))
            .collect::<Result<Vec<String>, _>>()?;
        let line = serde_json::json!({ "argv": argv });
        input.push_str(&format!("{line}\n"));
    }
    let python = std::env::var(PYTHON_VAR).unwrap_or_else(|_| "python3".to_owned());
    let exe = std::env::current_exe().map_err(|e| ClusterError::Failed(e.to_string()))?;
    let cwd = std::env::current_dir().map_err(|e| ClusterError::Failed(e.to_string()))?;
    let mut command = Command::new(&python);
    command
        .args(["-m", "ricochet_dask", "--scheduler", &cluster.scheduler])
        .arg("--exe")
        .arg(&exe)
        .arg("--cwd")
        .arg(&cwd);
    if cluster.verify {
        command.arg("--verify");
    }
    let mut child = command
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| ClusterError::NoPython(python.clone(), e))?;
    // stdin, stdout and stderr each on their own thread: the package may write before it
    // has read everything.
    let mut stdin = child.stdin.take().expect("stdin is piped");
    let writer = std::thread::spawn(move || {
        let _ = stdin.write_all(input.as_bytes());
    });
    let stderr = child.stderr.take().expect("stderr is piped");
    let errors = std::thread::spawn(move || {
        let mut text = String::new();
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            text.push_str(&line);
            text.push('\n');
        }
        text
    });
    let stdout = child.stdout.take().expect("stdout is piped");
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    let mut received = vec![false; count];
    let mut got = 0;
    let mut stopped = false;
    loop {
        if stop.load(Ordering::SeqCst) {
            stopped = true;
            stop_child(&mut child);
            break;
        }
        match rx.recv_timeout(POLL) {
            Ok(text) => {
                let Ok(line) = serde_json::from_str::<Line>(&text) else {
                    continue;
                };
                if line.index >= count || received[line.index] {
                    continue;
                }
                received[line.index] = true;
                got += 1;
                let (scenario, _) = args(line.index);
                done(line.index, merge(&scenario, line));
            }
            Err(mpsc::RecvTimeoutError::Timeout) => {}
            Err(mpsc::RecvTimeoutError::Disconnected) => break,
        }
    }
    let _ = writer.join();
    let status = child
        .wait()
        .map_err(|e| ClusterError::Failed(e.to_string()))?;
    let stderr = errors.join().unwrap_or_default();
    if stopped {
        return Ok(got);
    }
    if !status.success() {
        let last = stderr
            .lines()
            .rev()
            .find(|l| !l.trim().is_empty())
            .unwrap_or("")
            .trim()
            .to_owned();
        return Err(match status.code() {
            _ if stderr.contains("No module named ricochet_dask") => {
                ClusterError::NoPackage(python)
            }
            Some(3) => ClusterError::NoDistributed(last),
            Some(4) => ClusterError::Unreachable(cluster.scheduler.clone(), last),
            _ => ClusterError::Failed(format!("python3 -m ricochet_dask: {status}: {last}")),
        });
    }
    for (i, _) in received.iter().enumerate().filter(|(_, r)| !**r) {
        let (scenario, _) = args(i);
        done(i, error(&scenario, "the cluster returned no result for it"));
        got += 1;
    }
    Ok(got)
}

/// Checks that something accepts TCP connections at `tcp://HOST:PORT`, before Python is
/// started: an unreachable scheduler is named in a second, not after the client's timeout.
fn reach(address: &str) -> Result<(), ClusterError> {
    let bad = || ClusterError::BadAddress(address.to_owned());
    let host_port = address.strip_prefix("tcp://").ok_or_else(bad)?;
    let addrs: Vec<_> = host_port
        .to_socket_addrs()
        .map_err(|e| ClusterError::Unreachable(address.to_owned(), e.to_string()))?
        .collect();
    let mut why = String::from("the name resolves to no address");
    for a in addrs {
        match TcpStream::connect_timeout(&a, CONNECT) {
            Ok(_) => return Ok(()),
            Err(e) => why = format!("{a}: {e}"),
        }
    }
    Err(ClusterError::Unreachable(address.to_owned(), why))
}

/// Ends the package on Ctrl-C: SIGINT first (its client closes and cancels the items),
/// SIGKILL if it is still there a second later.
fn stop_child(child: &mut Child) {
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

/// The item's result from the package's line: its own result line, failed when `--verify`
/// found the second worker's digest different (both workers named) or could not re-run it.
fn merge(scenario: &std::path::Path, line: Line) -> ItemResult {
    let Some(mut result) = line.result else {
        let why = line.error.unwrap_or_else(|| "no result".to_owned());
        return error(scenario, &format!("on the cluster: {why}"));
    };
    let Some(verified) = line.verified else {
        return result;
    };
    let first = line.worker.unwrap_or_else(|| "a worker".to_owned());
    let second = verified
        .worker
        .unwrap_or_else(|| "another worker".to_owned());
    let line = match (&verified.result, &verified.error) {
        (Some(again), _) if again.digest == result.digest => return result,
        (Some(again), _) => {
            let hash = |r: &ItemResult| {
                r.digest.as_ref().map_or_else(
                    || format!("no digest ({})", r.line),
                    |d| format!("frames {} bodies {} hash {}", d.frames, d.bodies, d.hash),
                )
            };
            let golden = if result.verdict == Verdict::Ok {
                format!(" (the golden agrees with {first})")
            } else {
                String::new()
            };
            format!(
                "error: --verify: the workers disagree: {first} computed {}, {second} \
                 computed {}{golden}",
                hash(&result),
                hash(again)
            )
        }
        (None, Some(why)) => format!("error: --verify: the re-run failed: {why}"),
        (None, None) => "error: --verify: the re-run returned nothing".to_owned(),
    };
    result.verdict = Verdict::Error;
    result.line = escape_controls(&line);
    result
}

/// An [`Verdict::Error`] result for an item the cluster returned no result line for.
fn error(scenario: &std::path::Path, why: &str) -> ItemResult {
    ItemResult {
        format: FORMAT,
        scenario: scenario.display().to_string(),
        name: name_of(scenario),
        verdict: Verdict::Error,
        line: format!("error: {}", escape_controls(why.trim())),
        digest: None,
        first: None,
        log: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::suite::item::Digest;

    fn result(hash: &str) -> ItemResult {
        ItemResult {
            format: FORMAT,
            scenario: "s/a.toml".to_owned(),
            name: "a".to_owned(),
            verdict: Verdict::Ok,
            line: "ok".to_owned(),
            digest: Some(Digest {
                frames: 600,
                bodies: 6,
                hash: hash.to_owned(),
            }),
            first: None,
            log: None,
        }
    }

    fn line(first: &str, again: &str) -> Line {
        Line {
            index: 0,
            worker: Some("tcp://127.0.0.1:1".to_owned()),
            result: Some(result(first)),
            verified: Some(Verified {
                worker: Some("tcp://127.0.0.1:2".to_owned()),
                result: Some(result(again)),
                error: None,
            }),
            error: None,
        }
    }

    #[test]
    fn equal_digests_on_two_workers_keep_the_verdict() {
        let r = merge(std::path::Path::new("s/a.toml"), line("00aa", "00aa"));
        assert_eq!((r.verdict, r.line.as_str()), (Verdict::Ok, "ok"));
    }

    #[test]
    fn a_worker_that_computes_differently_fails_the_item_and_is_named() {
        let r = merge(std::path::Path::new("s/a.toml"), line("00aa", "00ab"));
        assert_eq!(r.verdict, Verdict::Error);
        assert_eq!(
            r.line,
            "error: --verify: the workers disagree: tcp://127.0.0.1:1 computed frames 600 \
             bodies 6 hash 00aa, tcp://127.0.0.1:2 computed frames 600 bodies 6 hash 00ab \
             (the golden agrees with tcp://127.0.0.1:1)"
        );
    }

    #[test]
    fn an_item_without_a_result_is_an_error_saying_why() {
        let l = Line {
            index: 0,
            worker: None,
            result: None,
            verified: None,
            error: Some("KilledWorker: 3 workers died".to_owned()),
        };
        let r = merge(std::path::Path::new("s/a.toml"), l);
        assert_eq!(r.verdict, Verdict::Error);
        assert_eq!(
            r.line,
            "error: on the cluster: KilledWorker: 3 workers died"
        );
    }

    #[test]
    fn an_address_without_tcp_is_named() {
        assert!(matches!(
            reach("127.0.0.1:8786"),
            Err(ClusterError::BadAddress(_))
        ));
    }
}
