//! The item processes: at most `jobs` children of this same binary at a time, each running
//! `ricochet test --item ...` on one scenario and printing its result line. A process per
//! item (not a thread) is the unit a cluster worker runs too, and keeps one scenario's
//! crash or overflow from taking the others with it.

use std::ffi::OsString;
use std::process::{Command, Output, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::Duration;

use nix::sys::signal::{Signal, kill};
use nix::unistd::Pid;

use super::item::{FORMAT, ItemResult, Verdict, name_of};

/// How often the pool looks at the stop flag while it waits for a child.
const POLL: Duration = Duration::from_millis(50);

/// Runs `args(i)` for every item `i` in `0..count`, at most `jobs` at once, calling
/// `done(i, result)` as each finishes (in any order). When `stop` is set (Ctrl-C), no
/// more are started and the running ones get SIGINT: they stop at their next frame, touch
/// no golden, and report `interrupted`. Returns how many were started.
pub fn run(
    count: usize,
    jobs: usize,
    stop: &AtomicBool,
    args: impl Fn(usize) -> (std::path::PathBuf, Vec<OsString>),
    mut done: impl FnMut(usize, ItemResult),
) -> anyhow::Result<usize> {
    let exe = std::env::current_exe()?;
    let (tx, rx) = mpsc::channel::<(usize, std::io::Result<Output>)>();
    // The PIDs of the children still running, by item. A child is reaped by its waiting
    // thread just before its result is sent, so a PID here is never a reused one for
    // longer than that instant.
    let mut running: Vec<(usize, u32)> = Vec::new();
    let mut next = 0;
    let mut signalled = false;
    loop {
        while !stop.load(Ordering::SeqCst) && running.len() < jobs.max(1) && next < count {
            let (scenario, argv) = args(next);
            let child = Command::new(&exe)
                .args(&argv)
                .stdin(Stdio::null())
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn();
            match child {
                Ok(child) => {
                    running.push((next, child.id()));
                    let tx = tx.clone();
                    let i = next;
                    std::thread::spawn(move || {
                        let _ = tx.send((i, child.wait_with_output()));
                    });
                }
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
        if stop.load(Ordering::SeqCst) && !signalled {
            signalled = true;
            for &(_, pid) in &running {
                // A child that already exited (its result on the way) can't be signalled;
                // nothing to do then.
                if let Ok(pid) = i32::try_from(pid) {
                    let _ = kill(Pid::from_raw(pid), Signal::SIGINT);
                }
            }
        }
        match rx.recv_timeout(POLL) {
            Ok((i, output)) => {
                running.retain(|&(j, _)| j != i);
                let (scenario, _) = args(i);
                done(i, parse(&scenario, output));
            }
            Err(mpsc::RecvTimeoutError::Timeout) => {}
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                anyhow::bail!("the item processes' results were lost")
            }
        }
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
