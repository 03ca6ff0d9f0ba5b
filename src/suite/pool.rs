//! The item processes: at most `jobs` children of this same binary at a time, each running
//! `ricochet test --item ...` on one scenario and printing its result line. A process per
//! item (not a thread) is the unit a cluster worker runs too, and keeps one scenario's
//! crash or overflow from taking the others with it.

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use nix::sys::resource::{Resource, getrlimit};
use nix::sys::signal::{Signal, kill};
use nix::unistd::Pid;

use super::item::{FORMAT, ItemResult, Verdict, name_of};

/// How often the pool looks at the stop flag while it waits for a child.
const POLL: Duration = Duration::from_millis(50);

/// How long the running items have to stop after the stop's SIGINT before they are killed
/// (SIGKILL): a frame takes milliseconds, so only a process that can't see the signal (one
/// blocked in a system call, or stopped) is still running then. Goldens are still only
/// ever renamed into place whole.
pub const GRACE: Duration = Duration::from_secs(5);

/// Descriptors this process holds for each running item: its standard output and error.
const FDS_PER_ITEM: u64 = 2;

/// Descriptors kept free for the rest: starting a process takes 5 for an instant (its three
/// standard streams and the pipe of a failed `exec`), and the runner writes `--junit`.
const FDS_RESERVED: u64 = 16;

/// How many items can run at once, at most `jobs`: as many as the open-file limit
/// (`ulimit -n`) leaves room for, after the descriptors open now, at [`FDS_PER_ITEM`]
/// each and [`FDS_RESERVED`] kept free. At least 1.
pub fn slots(jobs: usize) -> usize {
    let Ok((soft, _)) = getrlimit(Resource::RLIMIT_NOFILE) else {
        return jobs.max(1);
    };
    let open = std::fs::read_dir("/proc/self/fd").map_or(FDS_RESERVED, |d| d.count() as u64);
    let room = soft.saturating_sub(open + FDS_RESERVED) / FDS_PER_ITEM;
    jobs.min(usize::try_from(room).unwrap_or(usize::MAX)).max(1)
}

/// Whether starting a process failed for want of descriptors, which a finished item frees.
fn out_of_descriptors(e: &std::io::Error) -> bool {
    matches!(
        e.raw_os_error(),
        Some(code) if code == nix::errno::Errno::EMFILE as i32
            || code == nix::errno::Errno::ENFILE as i32
    )
}

/// Runs `args(i)` for every item `i` in `0..count`, at most `jobs` at once (fewer if the
/// open-file limit says so, [`slots`]; an item whose process can't start for want of
/// descriptors waits for a running one to end), calling `done(i, result)` as each
/// finishes (in any order). The items' temporary files go in `scratch` (their `TMPDIR`).
/// When `stop` is set (Ctrl-C), no more are started and the running ones get SIGINT: they
/// stop at their next frame, touch no golden, and report `interrupted`; any still running
/// [`GRACE`] later is killed, and reported `interrupted` too. Returns how many were started.
pub fn run(
    count: usize,
    jobs: usize,
    stop: &AtomicBool,
    scratch: &Path,
    args: impl Fn(usize) -> (PathBuf, Vec<OsString>),
    mut done: impl FnMut(usize, ItemResult),
) -> anyhow::Result<usize> {
    let exe = std::env::current_exe()?;
    let jobs = slots(jobs);
    let (tx, rx) = mpsc::channel::<(usize, std::io::Result<Output>)>();
    // The PIDs of the children still running, by item. A child is reaped by its waiting
    // thread just before its result is sent, so a PID here is never a reused one for
    // longer than that instant.
    let mut running: Vec<(usize, u32)> = Vec::new();
    let mut next = 0;
    let mut signalled: Option<Instant> = None;
    let mut killed = false;
    loop {
        while !stop.load(Ordering::SeqCst) && running.len() < jobs && next < count {
            let (scenario, argv) = args(next);
            let child = Command::new(&exe)
                .args(&argv)
                .env("TMPDIR", scratch)
                .stdin(Stdio::null())
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn();
            match child {
                Ok(child) => {
                    let pid = child.id();
                    let tx = tx.clone();
                    let i = next;
                    let waiting = std::thread::Builder::new()
                        .spawn(move || {
                            let _ = tx.send((i, child.wait_with_output()));
                        })
                        .map(drop);
                    match waiting {
                        Ok(()) => running.push((next, pid)),
                        Err(e) => {
                            // The child (moved into the thread that did not start) is
                            // dropped unwaited; end it rather than leave it running.
                            signal(pid, Signal::SIGKILL);
                            done(next, failed(&scenario, &format!("cannot wait for it: {e}")));
                        }
                    }
                }
                // Waits for a running item to end and free its descriptors.
                Err(e) if out_of_descriptors(&e) && !running.is_empty() => break,
                Err(e) => done(
                    next,
                    failed(&scenario, &format!("cannot start {}: {e}", exe.display())),
                ),
            }
            next += 1;
        }
        if running.is_empty() {
            return Ok(next);
        }
        if stop.load(Ordering::SeqCst) {
            match signalled {
                None => {
                    signalled = Some(Instant::now());
                    for &(_, pid) in &running {
                        signal(pid, Signal::SIGINT);
                    }
                }
                Some(at) if !killed && at.elapsed() >= GRACE => {
                    killed = true;
                    for &(_, pid) in &running {
                        signal(pid, Signal::SIGKILL);
                    }
                }
                Some(_) => {}
            }
        }
        match rx.recv_timeout(POLL) {
            Ok((i, output)) => {
                running.retain(|&(j, _)| j != i);
                let (scenario, _) = args(i);
                let mut result = parse(&scenario, output);
                if killed && result.verdict == Verdict::Error {
                    result.verdict = Verdict::Interrupted;
                    result.line = format!(
                        "interrupted (killed: still running {} s after the stop)",
                        GRACE.as_secs()
                    );
                }
                done(i, result);
            }
            Err(mpsc::RecvTimeoutError::Timeout) => {}
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                anyhow::bail!("the item processes' results were lost")
            }
        }
    }
}

/// Sends `sig` to the child `pid`. A child that already exited (its result on the way)
/// can't be signalled; nothing to do then.
fn signal(pid: u32, sig: Signal) {
    if let Ok(pid) = i32::try_from(pid) {
        let _ = kill(Pid::from_raw(pid), sig);
    }
}

/// The result line of a child, or an error verdict saying why there is none.
fn parse(scenario: &std::path::Path, output: std::io::Result<Output>) -> ItemResult {
    let output = match output {
        Ok(o) => o,
        Err(e) => return failed(scenario, &format!("waiting for its process: {e}")),
    };
    let stdout = String::from_utf8_lossy(&output.stdout);
    let line = stdout.lines().rev().find(|l| !l.trim().is_empty());
    match line.map(serde_json::from_str::<ItemResult>) {
        Some(Ok(r)) => r,
        _ => {
            let stderr = String::from_utf8_lossy(&output.stderr);
            let why = stderr
                .lines()
                .rev()
                .find(|l| !l.trim().is_empty())
                .unwrap_or("");
            failed(
                scenario,
                &format!(
                    "its process ended without a result ({}) {why}",
                    output.status
                ),
            )
        }
    }
}

/// An [`Verdict::Error`] result made by the runner, for an item whose process failed.
fn failed(scenario: &std::path::Path, why: &str) -> ItemResult {
    ItemResult {
        format: FORMAT,
        scenario: scenario.display().to_string(),
        name: name_of(scenario),
        verdict: Verdict::Error,
        line: format!("error: {}", crate::out::escape_controls(why.trim())),
        digest: None,
        first: None,
        log: None,
    }
}
