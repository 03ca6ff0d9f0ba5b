//! `ricochet test --cluster`: the named errors when the cluster run can't start (exit code
//! 2, and how to fix it). No cluster is needed; scripts/cluster-ci.sh runs a real one.

use std::net::TcpListener;
use std::process::{Command, Output};

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
