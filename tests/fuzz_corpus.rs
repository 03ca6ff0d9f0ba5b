//! The fuzz corpus, replayed as an ordinary test. Every input the `cargo fuzz` targets have
//! kept (`fuzz/corpus/<target>/`), every hand-picked seed (`fuzz/seeds/<target>/`) and every
//! crash they found (`fuzz/regressions/<target>/`) is run through the very checks the targets
//! run: `fuzz/src/checks.rs`, included here, so the two can't drift apart. Any input at all
//! must give an error or a result, never a panic. How to fuzz, and what was found:
//! `fuzz/README.md`.

use std::any::Any;
use std::path::PathBuf;
use std::time::Instant;

use crate::util::root;

#[path = "../fuzz/src/checks.rs"]
mod checks;

/// Every file of `fuzz/{corpus,seeds,regressions}/<target>/`, sorted, and how many of them
/// came from the corpus.
fn inputs(target: &str) -> (Vec<PathBuf>, usize) {
    let mut corpus = 0;
    let mut files = Vec::new();
    for kind in ["corpus", "seeds", "regressions"] {
        let dir = root().join("fuzz").join(kind).join(target);
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        let mut found: Vec<PathBuf> = entries
            .map(|e| e.expect("a fuzz input directory can be listed").path())
            .filter(|p| p.is_file())
            .collect();
        found.sort();
        if kind == "corpus" {
            corpus = found.len();
        }
        files.extend(found);
    }
    (files, corpus)
}

fn message(payload: &(dyn Any + Send)) -> &str {
    payload
        .downcast_ref::<String>()
        .map(String::as_str)
        .or_else(|| payload.downcast_ref::<&str>().copied())
        .unwrap_or("(a panic without a message)")
}

/// Runs `check` on every input of `target`, as the fuzz target does (non-UTF-8 inputs are
/// skipped there too), and fails naming each input that panicked.
fn replay(target: &str, check: fn(&str)) {
    let start = Instant::now();
    let (files, corpus) = inputs(target);
    assert!(
        corpus > 0,
        "fuzz/corpus/{target}/ holds the committed corpus: run it from a checkout"
    );
    let mut failures = Vec::new();
    for path in &files {
        let bytes = std::fs::read(path).expect("a corpus file can be read");
        let Ok(text) = std::str::from_utf8(&bytes) else {
            continue;
        };
        if let Err(payload) = std::panic::catch_unwind(|| check(text)) {
            let name = path.strip_prefix(root()).unwrap_or(path);
            failures.push(format!("{}: {}", name.display(), message(&*payload)));
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} fuzz inputs panicked (replay one with `cargo +nightly fuzz run {target} FILE` \
         in fuzz/):\n{}",
        failures.len(),
        files.len(),
        failures.join("\n")
    );
    eprintln!(
        "{target}: {} inputs replayed in {:.2?}",
        files.len(),
        start.elapsed()
    );
}

#[test]
fn scenario_corpus_gives_errors_or_results() {
    replay("scenario", checks::scenario);
}

#[test]
fn collide_corpus_gives_errors_or_results() {
    replay("collide", checks::collide);
}

/// Like [`replay`], for a target that reads bytes (logs); its inputs are hand-made seeds and
/// whatever the fuzzer kept, if it ran.
fn replay_bytes(target: &str, check: fn(&[u8])) {
    let (files, _) = inputs(target);
    assert!(
        !files.is_empty(),
        "fuzz/seeds/{target}/ holds the committed seeds: run it from a checkout"
    );
    let mut failures = Vec::new();
    for path in &files {
        let bytes = std::fs::read(path).expect("a fuzz input can be read");
        if let Err(payload) = std::panic::catch_unwind(|| check(&bytes)) {
            let name = path.strip_prefix(root()).unwrap_or(path);
            failures.push(format!("{}: {}", name.display(), message(&*payload)));
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} fuzz inputs panicked:\n{}",
        failures.len(),
        files.len(),
        failures.join("\n")
    );
}

#[test]
fn log_seeds_give_errors_or_messages() {
    replay_bytes("log", checks::log);
}
