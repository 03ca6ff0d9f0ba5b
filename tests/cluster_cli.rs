//! `ricochet test --cluster`: the named errors when the cluster run can't start (exit code
//! 2, and how to fix it). No cluster is needed; scripts/cluster-ci.sh runs a real one. The
//! ports that are not a scheduler need a Python with `distributed` (skipped without one;
//! scripts/cluster-ci.sh runs them with its venv).

use std::net::TcpListener;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use crate::util::root;

/// `ricochet test scenarios --cluster ADDRESS ARGS` with extra environment variables.
fn test_on(address: &str, args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_ricochet"));
    c.args(["test", "scenarios", "--cluster", address])
        .args(args)
        .current_dir(root());
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("ricochet runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A port on loopback that accepts connections for as long as the listener lives (the
/// kernel completes the handshake without `accept`): a scheduler as far as reaching it goes.
fn listening() -> (TcpListener, String) {
    let l = TcpListener::bind("127.0.0.1:0").expect("a loopback port");
    let address = format!("tcp://{}", l.local_addr().unwrap());
    (l, address)
}

/// A venv without pip or packages: a Python that certainly lacks ricochet_dask and
/// distributed, whatever the machine's own Python has.
fn bare_python(dir: &std::path::Path) -> String {
    let made = Command::new("python3")
        .args(["-m", "venv", "--without-pip"])
        .arg(dir)
        .status()
        .expect("python3 runs (CI installs it; the cluster run needs it)");
    assert!(made.success(), "python3 -m venv failed");
    dir.join("bin/python").display().to_string()
}

#[test]
fn an_unreachable_scheduler_is_named_with_how_to_start_one() {
    let (listener, address) = listening();
    drop(listener);
    let o = test_on(&address, &[], &[]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains(&format!(
            "--cluster {address}: cannot reach the Dask scheduler"
        )),
        "{e}"
    );
    assert!(e.contains("dask scheduler"), "{e}");
    assert!(o.stdout.is_empty(), "no item ran");
}

#[test]
fn an_address_that_is_not_tcp_is_bad_input() {
    let o = test_on("127.0.0.1:8786", &[], &[]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("expected tcp://HOST:PORT"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn a_missing_python_says_how_to_install() {
    let (_listener, address) = listening();
    let o = test_on(
        &address,
        &[],
        &[("RICOCHET_PYTHON", "/nonexistent/python3")],
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("/nonexistent/python3 cannot be started"), "{e}");
    assert!(e.contains("pip install ./python"), "{e}");
}

#[test]
fn a_python_without_the_package_says_how_to_install() {
    let (_listener, address) = listening();
    let venv = tempfile::tempdir().unwrap();
    let python = bare_python(venv.path());
    let o = test_on(&address, &[], &[("RICOCHET_PYTHON", &python)]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("has no package ricochet_dask"), "{e}");
    assert!(e.contains("pip install ./python"), "{e}");
}

#[test]
fn the_package_without_distributed_says_how_to_install() {
    let (_listener, address) = listening();
    let venv = tempfile::tempdir().unwrap();
    let python = bare_python(venv.path());
    let src = root().join("python/src").display().to_string();
    let o = test_on(
        &address,
        &["--verify"],
        &[("RICOCHET_PYTHON", &python), ("PYTHONPATH", &src)],
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("Dask distributed is missing"), "{e}");
    assert!(e.contains("pip install ./python"), "{e}");
}

#[test]
fn verify_needs_a_cluster() {
    let o = crate::util::ricochet(&["test", "scenarios", "--verify"], b"");
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--cluster"), "{}", stderr(&o));
}

/// Set by scripts/cluster-ci.sh, which has a venv with `distributed`: the tests that need it
/// fail rather than skip when it is missing.
const REQUIRE_DASK: &str = "RICOCHET_REQUIRE_DASK";

/// A Python with `distributed`: `RICOCHET_PYTHON`, else the venv scripts/cluster-ci.sh makes
/// (target/cluster-venv). `None`, and the test is skipped saying so, if neither has it.
fn dask_python() -> Option<String> {
    let candidates = std::env::var("RICOCHET_PYTHON")
        .ok()
        .into_iter()
        .chain([root()
            .join("target/cluster-venv/bin/python")
            .display()
            .to_string()]);
    for python in candidates {
        let has = Command::new(&python)
            .args(["-c", "import distributed"])
            .output()
            .is_ok_and(|o| o.status.success());
        if has {
            return Some(python);
        }
    }
    assert!(
        std::env::var_os(REQUIRE_DASK).is_none(),
        "{REQUIRE_DASK} is set but no Python with distributed was found"
    );
    eprintln!("skipped: no Python with distributed (scripts/cluster-ci.sh runs this test)");
    None
}

/// A loopback port that accepts connections and, to each, writes `greeting` (nothing, for
/// a port that stays silent) and holds it open: not a Dask scheduler. Stops when dropped,
/// and after 3 minutes whatever happens.
struct NotDask {
    address: String,
    stop: std::sync::Arc<std::sync::atomic::AtomicBool>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl NotDask {
    fn start(greeting: &'static [u8]) -> NotDask {
        use std::io::Write;
        use std::sync::atomic::Ordering;
        let (listener, address) = listening();
        listener.set_nonblocking(true).unwrap();
        let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        let flag = stop.clone();
        let thread = std::thread::spawn(move || {
            let end = Instant::now() + Duration::from_secs(180);
            let mut held = Vec::new();
            while !flag.load(Ordering::SeqCst) && Instant::now() < end {
                match listener.accept() {
                    Ok((mut stream, _)) if held.len() < 16 => {
                        let _ = stream.write_all(greeting);
                        held.push(stream);
                    }
                    Ok(_) => {}
                    Err(_) => std::thread::sleep(Duration::from_millis(20)),
                }
            }
        });
        NotDask {
            address,
            stop,
            thread: Some(thread),
        }
    }
}

impl Drop for NotDask {
    fn drop(&mut self) {
        self.stop.store(true, std::sync::atomic::Ordering::SeqCst);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// `ricochet test scenarios/level.toml --cluster ADDRESS` with `env`, killed if it runs 90
/// s (a hang, which is the failure): its output.
fn bounded_test_on(address: &str, env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_ricochet"));
    c.args(["test", "scenarios/level.toml", "--cluster", address])
        .current_dir(root())
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    for (k, v) in env {
        c.env(k, v);
    }
    let mut child = c.spawn().expect("ricochet runs");
    let end = Instant::now() + Duration::from_secs(90);
    while child.try_wait().unwrap().is_none() {
        if Instant::now() > end {
            let _ = child.kill();
            let o = child.wait_with_output().unwrap();
            panic!(
                "ricochet test --cluster {address} still ran after 90 s: {}",
                stderr(&o)
            );
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    child.wait_with_output().unwrap()
}

/// Runs `test --cluster` against a loopback port that answers `reply` (nothing: silent) and
/// checks the run is refused, exit 2, with `--cluster ADDRESS: {says}` and no item run.
fn refused_by_a_port_that_answers(reply: &'static [u8], says: &str) {
    let Some(python) = dask_python() else { return };
    let port = NotDask::start(reply);
    let src = root().join("python/src").display().to_string();
    let o = bounded_test_on(
        &port.address,
        &[("RICOCHET_PYTHON", &python), ("PYTHONPATH", &src)],
    );
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains(&format!("--cluster {}: {says}", port.address)),
        "{e}"
    );
    assert!(o.stdout.is_empty(), "no item ran");
}

#[test]
fn a_port_that_accepts_and_stays_silent_is_named_not_waited_on() {
    refused_by_a_port_that_answers(b"", "no Dask scheduler answered within 10 s");
}

#[test]
fn a_port_that_answers_in_another_protocol_is_not_a_dask_scheduler() {
    refused_by_a_port_that_answers(
        b"HTTP/1.1 400 Bad Request\r\nContent-Length: 0\r\n\r\n",
        "is not a Dask scheduler",
    );
}

#[test]
fn a_package_that_never_answers_is_stopped_and_named() {
    // A "Python" that says nothing for longer than the run waits: the run's own bound, for
    // a package that hangs where its timer can't help.
    let dir = tempfile::tempdir().unwrap();
    let python = dir.path().join("python");
    std::fs::write(&python, "#!/bin/sh\nexec sleep 120\n").unwrap();
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&python, std::fs::Permissions::from_mode(0o755)).unwrap();
    }
    let port = NotDask::start(b"");
    let o = bounded_test_on(
        &port.address,
        &[("RICOCHET_PYTHON", &python.display().to_string())],
    );
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains(&format!(
            "--cluster {}: python3 -m ricochet_dask did not connect to a Dask scheduler \
             within 30 s",
            port.address
        )),
        "{e}"
    );
    assert!(o.stdout.is_empty(), "no item ran");
}
