//! `ricochet test --cluster tcp://HOST:PORT` and `ricochet sweep --cluster …`: the items run
//! on a Dask distributed cluster instead of local processes (`pool.rs`), with the same argv
//! and the same result lines (`test --item`'s `ItemResult`, `sweep --item`'s row).
//!
//! Ricochet does not schedule anything itself. It starts `python3 -m ricochet_dask` (the
//! package in `python/`, `pip install ./python`), writes one `{"argv": [...]}` line per item
//! on its stdin, and reads one line per item from its stdout as the items finish; the
//! package maps them over the user's scheduler and workers, and Dask retries a crashed item
//! and reruns a killed worker's items elsewhere. The merge stays here and in `mod.rs`: the
//! lines come back in any order and are put in item order, so the output is the same bytes
//! as a local run. `--verify` re-runs a sample of the items on a second worker (chosen by the
//! package), and an item whose two digests differ fails, naming both workers. A re-run whose
//! worker leaves is moved to another one, and one that does not finish within
//! [`Cluster::verify_timeout`] fails the item, named: `--verify` never waits forever.
//!
//! Every worker runs this same binary at this same absolute path, with the scenarios, the
//! goldens and the logs' folder at the same paths: one machine, or a shared filesystem.

use std::ffi::OsString;
use std::io::{BufRead, BufReader, Write};
use std::net::{TcpStream, ToSocketAddrs};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use serde::Deserialize;
use serde::de::DeserializeOwned;

use crate::out::escape_controls;

mod child;
use child::{stop_child, tail};

/// The Python that runs the package: `RICOCHET_PYTHON` if set (a venv's
/// `bin/python`), else `python3` on the PATH.
pub const PYTHON_VAR: &str = "RICOCHET_PYTHON";

/// How to install what the cluster run needs, said by every error that lacks it.
const INSTALL: &str = "install it with `pip install ./python` from Ricochet's repository \
     (it pulls in dask[distributed]), or set RICOCHET_PYTHON to a Python that has it";

/// How long the scheduler has to accept a TCP connection before the run gives up.
const CONNECT: Duration = Duration::from_secs(3);

/// How long the package may take to connect to the scheduler, the TCP connect and Dask's
/// handshake together (its `--timeout`): a port that accepts but never speaks Dask's
/// protocol is named after this long (`ricochet test --help`).
pub const HANDSHAKE: Duration = Duration::from_secs(10);

/// How long the run waits for the package's first line (`{"connected": …}`, said once it
/// has a client): [`HANDSHAKE`] plus time to start Python and import `distributed` (under
/// a second on an idle machine). A package that is silent longer is killed, so no run
/// waits forever for a Python that hangs.
pub const FIRST_ANSWER: Duration = Duration::from_secs(HANDSHAKE.as_secs() + 20);

/// How often the run looks at the stop flag while it waits for a line.
const POLL: Duration = Duration::from_millis(50);

/// Where and how to run the items.
#[derive(Debug, Clone)]
pub struct Cluster {
    /// The scheduler's address, `tcp://HOST:PORT`.
    pub scheduler: String,
    /// Re-run a sample of the items on a second worker and require identical digests.
    pub verify: bool,
    /// With `verify`: how long a re-run may take, from when it is handed to its worker,
    /// before the item fails with a named error.
    pub verify_timeout: Duration,
    /// Copy each fresh log's bytes back from the worker (`ricochet test --keep DIR
    /// --fetch-logs`); otherwise a result names the log's path on the worker.
    pub fetch_logs: bool,
}

impl Cluster {
    /// A cluster run at `scheduler`, without `--verify` or fetched logs.
    #[must_use]
    pub fn new(scheduler: String) -> Cluster {
        Cluster {
            scheduler,
            verify: false,
            verify_timeout: VERIFY_TIMEOUT,
            fetch_logs: false,
        }
    }
}

/// The default of [`Cluster::verify_timeout`]: far longer than any item of a test suite
/// should take, short enough that a lost re-run ends the run the same hour.
pub const VERIFY_TIMEOUT: Duration = Duration::from_secs(600);

/// A result line the cluster carries back: `--verify` compares the digests of two runs.
pub trait ResultLine: DeserializeOwned {
    /// What `--verify` compares between the two runs of an item, as the error shows it.
    fn digest_text(&self) -> String;
}

/// What became of one item on the cluster.
#[derive(Debug)]
pub enum Returned<R> {
    /// Its result line (and, when it was sampled, the second run's digest was the same).
    Line(R),
    /// Its result line, but `--verify` failed: the second run's digest differs, or it
    /// could not re-run. `why` names both workers; `first` is the first run's.
    Unverified {
        /// The first run's line.
        result: R,
        /// `the workers disagree: A computed X, B computed Y`, or why there is no re-run
        /// (as the package wrote it: escape it before printing).
        why: String,
        /// The worker of the first run.
        first: String,
        /// The second run's worker and line, when it returned one that reads.
        again: Option<(String, R)>,
    },
    /// No result line: why (`on the cluster: …`).
    Failed(String),
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
    /// Something accepts connections at the address but no Dask scheduler answered within
    /// [`HANDSHAKE`].
    NoAnswer(String),
    /// What answered at the address does not speak Dask's protocol; the reader's error.
    NotDask(String, String),
    /// The package said nothing within [`FIRST_ANSWER`] and was stopped.
    Stalled(String),
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
            Self::NoAnswer(a) => write!(
                f,
                "--cluster {}: no Dask scheduler answered within {} s (something accepts \
                 connections there: is it the scheduler's port? `dask scheduler` prints it)",
                escape_controls(a),
                HANDSHAKE.as_secs()
            ),
            Self::NotDask(a, why) => write!(
                f,
                "--cluster {}: is not a Dask scheduler: its answer does not read as Dask's \
                 protocol ({})",
                escape_controls(a),
                escape_controls(why)
            ),
            Self::Stalled(a) => write!(
                f,
                "--cluster {}: python3 -m ricochet_dask did not connect to a Dask scheduler \
                 within {} s; it was stopped",
                escape_controls(a),
                FIRST_ANSWER.as_secs()
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
    result: Option<serde_json::Value>,
    error: Option<String>,
}

/// One line of the package's stdout. The results are read into the item's own line type
/// in [`merge`], so a worker's line that does not read (another `ricochet` on that node) is
/// named rather than dropped.
#[derive(Deserialize)]
struct Line {
    index: usize,
    worker: Option<String>,
    result: Option<serde_json::Value>,
    verified: Option<Verified>,
    error: Option<String>,
}

/// Runs `args(i)` (the argv of one `ricochet … --item` process) for every item `i` in
/// `0..count` on the cluster, calling `done(i, returned)` as each finishes (in any order),
/// like `pool::run`. When `stop` is set (Ctrl-C) the package is stopped and the items still
/// out get no result. Returns how many results came back.
pub fn run<R: ResultLine>(
    cluster: &Cluster,
    count: usize,
    stop: &AtomicBool,
    args: impl Fn(usize) -> Vec<OsString>,
    mut done: impl FnMut(usize, Returned<R>),
) -> Result<usize, ClusterError> {
    reach(&cluster.scheduler)?;
    let mut input = String::new();
    for i in 0..count {
        let argv = args(i)
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
        .arg(&cwd)
        .arg("--timeout")
        .arg(HANDSHAKE.as_secs().to_string());
    if cluster.verify {
        command
            .arg("--verify")
            .arg("--verify-timeout")
            .arg(cluster.verify_timeout.as_secs_f64().to_string());
    }
    if cluster.fetch_logs {
        command.arg("--fetch-logs");
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
    let errors = std::thread::spawn(move || tail(stderr));
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
    let (started, mut answered, mut stalled) = (Instant::now(), false, false);
    loop {
        if stop.load(Ordering::SeqCst) {
            stopped = true;
            stop_child(&mut child);
            break;
        }
        match rx.recv_timeout(POLL) {
            Ok(text) => {
                answered = true;
                let Ok(line) = serde_json::from_str::<Line>(&text) else {
                    continue;
                };
                if line.index >= count || received[line.index] {
                    continue;
                }
                received[line.index] = true;
                got += 1;
                done(line.index, merge(line));
            }
            Err(mpsc::RecvTimeoutError::Timeout) => {
                if !answered && started.elapsed() > FIRST_ANSWER {
                    stalled = true;
                    let _ = child.kill();
                    break;
                }
            }
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
    if stalled {
        return Err(ClusterError::Stalled(cluster.scheduler.clone()));
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
            Some(6) => ClusterError::NoAnswer(cluster.scheduler.clone()),
            Some(7) => ClusterError::NotDask(
                cluster.scheduler.clone(),
                last.split_once("protocol (")
                    .map_or(last.as_str(), |(_, why)| why.trim_end_matches(')'))
                    .to_owned(),
            ),
            _ => ClusterError::Failed(format!("python3 -m ricochet_dask: {status}: {last}")),
        });
    }
    for (i, _) in received.iter().enumerate().filter(|(_, r)| !**r) {
        done(
            i,
            Returned::Failed("the cluster returned no result for it".to_owned()),
        );
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

/// The item's outcome from the package's line: its own result line, unverified when
/// `--verify` found the second worker's digest different (both workers named) or could not
/// re-run it.
fn merge<R: ResultLine>(line: Line) -> Returned<R> {
    let first = line.worker.unwrap_or_else(|| "a worker".to_owned());
    let Some(result) = line.result else {
        let why = line.error.unwrap_or_else(|| "no result".to_owned());
        return Returned::Failed(format!("on the cluster: {}", escape_controls(why.trim())));
    };
    let result = match R::deserialize(result) {
        Ok(r) => r,
        Err(e) => {
            return Returned::Failed(format!(
                "on the cluster: the result line from {} does not read ({}): is its ricochet \
                 this one?",
                escape_controls(&first),
                escape_controls(&e.to_string())
            ));
        }
    };
    let Some(verified) = line.verified else {
        return Returned::Line(result);
    };
    let second = verified
        .worker
        .unwrap_or_else(|| "another worker".to_owned());
    let again = verified.result.map(R::deserialize);
    let why = match (&again, &verified.error) {
        (Some(Err(e)), _) => format!(
            "the re-run's line from {second} does not read ({e}): is its ricochet this one?"
        ),
        (Some(Ok(again)), _) if again.digest_text() == result.digest_text() => {
            return Returned::Line(result);
        }
        (Some(Ok(again)), _) => format!(
            "the workers disagree: {first} computed {}, {second} computed {}",
            result.digest_text(),
            again.digest_text()
        ),
        (None, Some(why)) => format!("the re-run failed: {why}"),
        (None, None) => "the re-run returned nothing".to_owned(),
    };
    Returned::Unverified {
        result,
        why,
        first,
        again: again.and_then(Result::ok).map(|a| (second, a)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A result line with only a digest.
    #[derive(Deserialize, Debug, PartialEq)]
    struct Hashed(String);

    impl ResultLine for Hashed {
        fn digest_text(&self) -> String {
            format!("hash {}", self.0)
        }
    }

    fn line(first: &str, again: &str) -> Line {
        Line {
            index: 0,
            worker: Some("tcp://127.0.0.1:1".to_owned()),
            result: Some(serde_json::json!(first)),
            verified: Some(Verified {
                worker: Some("tcp://127.0.0.1:2".to_owned()),
                result: Some(serde_json::json!(again)),
                error: None,
            }),
            error: None,
        }
    }

    #[test]
    fn equal_digests_on_two_workers_keep_the_line() {
        let r: Returned<Hashed> = merge(line("00aa", "00aa"));
        assert!(matches!(r, Returned::Line(Hashed(h)) if h == "00aa"));
    }

    #[test]
    fn a_worker_that_computes_differently_is_named() {
        let Returned::<Hashed>::Unverified {
            result,
            why,
            first,
            again,
        } = merge(line("00aa", "00ab"))
        else {
            panic!("verified although the digests differ");
        };
        assert_eq!(result, Hashed("00aa".to_owned()));
        assert_eq!(first, "tcp://127.0.0.1:1");
        assert_eq!(
            again,
            Some(("tcp://127.0.0.1:2".to_owned(), Hashed("00ab".to_owned())))
        );
        assert_eq!(
            why,
            "the workers disagree: tcp://127.0.0.1:1 computed hash 00aa, tcp://127.0.0.1:2 \
             computed hash 00ab"
        );
    }

    #[test]
    fn a_re_run_that_timed_out_is_unverified_saying_why() {
        let mut l = line("00aa", "00aa");
        l.verified = Some(Verified {
            worker: Some("tcp://127.0.0.1:2".to_owned()),
            result: None,
            error: Some("no result from tcp://127.0.0.1:2 in 5 s".to_owned()),
        });
        let Returned::<Hashed>::Unverified { why, .. } = merge(l) else {
            panic!("verified without a second run");
        };
        assert_eq!(
            why,
            "the re-run failed: no result from tcp://127.0.0.1:2 in 5 s"
        );
    }

    #[test]
    fn an_item_without_a_result_fails_saying_why() {
        let l = Line {
            index: 0,
            worker: None,
            result: None,
            verified: None,
            error: Some("KilledWorker: 3 workers died".to_owned()),
        };
        assert!(matches!(
            merge::<Hashed>(l),
            Returned::Failed(why) if why == "on the cluster: KilledWorker: 3 workers died"
        ));
    }

    #[test]
    fn a_line_another_ricochet_wrote_is_named_with_its_worker() {
        let mut l = line("00aa", "00aa");
        l.result = Some(serde_json::json!({"format": 99}));
        let Returned::<Hashed>::Failed(why) = merge(l) else {
            panic!("a line that does not read was taken");
        };
        assert!(
            why.starts_with("on the cluster: the result line from tcp://127.0.0.1:1 does not read"),
            "{why}"
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
