//! `ricochet test [PATHS…]`: the golden-log runner for a folder of scenarios.
//!
//! Each scenario is one item: recorded as `ricochet run` records it and compared with its
//! golden log and digest (`item.rs`), in its own process (`pool.rs`, `-j N` at a time). The
//! runner gathers the items, sorts them, keeps its `--shard` (`shard.rs`), and prints the
//! verdicts in that sorted order, whatever order the processes finish in, so the output is
//! the same bytes with any `-j` and shards concatenate to the whole suite. Then the summary
//! `N passed, M failed`, and `--junit` (`junit.rs`).

pub mod cluster;
pub mod item;
mod junit;
mod pool;
mod read;
pub mod shard;

use std::collections::{BTreeMap, BTreeSet};
use std::ffi::OsString;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use crate::out;
use item::{ItemOptions, ItemResult, default_golden, name_of};
use shard::Shard;

/// The folder `ricochet test` runs without paths.
pub const DEFAULT_FOLDER: &str = "scenarios";

/// The name of the JUnit testsuite.
const SUITE: &str = "ricochet test";

/// `ricochet test`'s options, as parsed.
pub struct Options {
    /// Scenario files and folders (the `*.toml` at a folder's top level).
    pub paths: Vec<PathBuf>,
    /// The goldens' folder; default: `recordings/` beside each scenario's folder.
    pub golden: Option<PathBuf>,
    /// Item processes at once; default: the number of cores.
    pub jobs: Option<usize>,
    /// Write the goldens instead of comparing.
    pub bless: bool,
    /// Also write a JUnit XML report here.
    pub junit: Option<PathBuf>,
    /// Run only this slice of the sorted items.
    pub shard: Option<Shard>,
    /// Keep the fresh logs in this folder (NAME.mcap); default: a temporary folder.
    pub keep: Option<PathBuf>,
    /// Run the items on this Dask cluster instead of local processes (`cluster.rs`).
    pub cluster: Option<cluster::Cluster>,
}

/// Sets a flag on Ctrl-C, SIGTERM and SIGHUP. If a handler can't be installed, the signal
/// just ends the process; goldens are still only ever renamed into place whole.
fn stop_flag() -> Arc<AtomicBool> {
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    let _ = ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst));
    stop
}

/// `ricochet test --item SCENARIO`: runs one item and prints its result line (JSON). Exit
/// code 0 passed, 1 failed.
pub fn run_item(
    scenario: &Path,
    golden: Option<&Path>,
    out_dir: Option<&Path>,
    bless: bool,
) -> anyhow::Result<ExitCode> {
    let stop = stop_flag();
    let result = item::run(
        &ItemOptions {
            scenario,
            golden,
            out: out_dir,
            bless,
        },
        &stop,
    );
    out::print(&(serde_json::to_string(&result)? + "\n"))?;
    Ok(if result.verdict.passed() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

/// The scenarios the paths name, sorted by name then path, each once; `Err` is a bad-input
/// message (exit code 2).
fn gather(paths: &[PathBuf], golden: Option<&Path>) -> Result<Vec<PathBuf>, String> {
    let default = [PathBuf::from(DEFAULT_FOLDER)];
    let paths = if paths.is_empty() {
        &default[..]
    } else {
        paths
    };
    let mut items = Vec::new();
    for path in paths {
        let shown = out::escape_controls(&path.display().to_string());
        let meta = std::fs::metadata(path).map_err(|e| format!("{shown}: {e}"))?;
        if meta.is_file() {
            items.push(path.clone());
            continue;
        }
        if !meta.is_dir() {
            // Opening a FIFO would wait for a writer; a device may never end.
            return Err(format!(
                "{shown}: not a regular file or a folder (a FIFO, a device or a socket); a \
                 scenario is a TOML file"
            ));
        }
        let mut found: Vec<PathBuf> = std::fs::read_dir(path)
            .map_err(|e| format!("{shown}: {e}"))?
            .filter_map(Result::ok)
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|e| e == "toml") && p.is_file())
            .collect();
        if found.is_empty() {
            return Err(format!(
                "{shown}: no scenario files (*.toml) at the top of this folder"
            ));
        }
        found.sort();
        items.extend(found);
    }
    items.sort_by_key(|p| (name_of(p), p.clone()));
    // One file named twice (`scenarios` and `./scenarios/a.toml`) is one item.
    let mut seen = BTreeSet::new();
    items.retain(|p| seen.insert(crate::files::resolved(p)));
    // Two scenarios with one name would share a golden: each must have its own. Compared
    // by resolved folder, so `s2/sub/../x.toml` and `s1/x.toml` are caught too.
    let mut owners: BTreeMap<(PathBuf, String), &Path> = BTreeMap::new();
    for p in &items {
        let dir = golden.map_or_else(|| default_golden(p), Path::to_owned);
        let name = name_of(p);
        if let Some(other) = owners.insert((crate::files::resolved(&dir), name.clone()), p) {
            return Err(format!(
                "{} and {} would share the golden {}: rename one",
                out::escape_controls(&other.display().to_string()),
                out::escape_controls(&p.display().to_string()),
                out::escape_controls(&dir.join(format!("{name}.mcap")).display().to_string())
            ));
        }
    }
    Ok(items)
}

/// `--keep DIR` checked against the items before any runs: `Err` (exit code 2) when a
/// fresh log would be kept where a golden is (`DIR` is, or resolves to, a golden folder),
/// or two items would be kept at one path (one name in two folders).
fn check_keep(items: &[PathBuf], golden: Option<&Path>, keep: &Path) -> Result<(), String> {
    let shown = |p: &Path| out::escape_controls(&p.display().to_string());
    let keep_dir = crate::files::resolved(keep);
    let mut dirs = BTreeSet::new();
    let mut kept: BTreeMap<String, &Path> = BTreeMap::new();
    for p in items {
        let dir = golden.map_or_else(|| default_golden(p), Path::to_owned);
        let resolved = crate::files::resolved(&dir);
        if !dirs.contains(&resolved)
            && (resolved == keep_dir || crate::files::same_file(&dir, keep))
        {
            return Err(format!(
                "--keep {} is the golden folder {}: the fresh logs would replace the goldens; \
                 keep them in another folder",
                shown(keep),
                shown(&dir)
            ));
        }
        dirs.insert(resolved);
        if let Some(other) = kept.insert(name_of(p), p) {
            return Err(format!(
                "--keep {}: {} and {} would both be kept as {}: run them in two runs, or \
                 rename one",
                shown(keep),
                shown(other),
                shown(p),
                shown(&keep.join(format!("{}.mcap", name_of(p))))
            ));
        }
    }
    Ok(())
}

/// An item's result from the cluster: `--verify`'s failure and a missing result line are
/// `error` verdicts whose line says why. Of two workers that disagree, the one whose digest
/// the golden digest file holds is named as agreeing with it: two runs alone can't say
/// which node computes differently, and a node's own verdict is its own word.
fn from_cluster(
    scenario: &Path,
    golden: Option<&Path>,
    returned: cluster::Returned<ItemResult>,
) -> ItemResult {
    match returned {
        cluster::Returned::Line(r) => r,
        cluster::Returned::Unverified {
            mut result,
            why,
            first,
            again,
        } => {
            let dir = golden.map_or_else(|| default_golden(scenario), Path::to_owned);
            let kept = read::read_golden(&dir.join(format!("{}.digest", name_of(scenario))))
                .ok()
                .flatten()
                .map(|b| String::from_utf8_lossy(&b).replace("\r\n", "\n"))
                .ok_or(());
            let text = |r: &ItemResult| r.digest.as_ref().map(item::Digest::text);
            let golden = match (kept, &again) {
                (Ok(kept), Some((second, again))) => {
                    let agree: Vec<&str> = [(first.as_str(), &result), (second.as_str(), again)]
                        .into_iter()
                        .filter(|(_, r)| text(r).as_deref() == Some(kept.as_str()))
                        .map(|(w, _)| w)
                        .collect();
                    match agree[..] {
                        [w] => format!(" (the golden digest agrees with {w})"),
                        _ => " (the golden digest agrees with neither)".to_owned(),
                    }
                }
                _ => String::new(),
            };
            result.verdict = item::Verdict::Error;
            result.line = out::escape_controls(&format!("error: --verify: {why}{golden}"));
            result
        }
        cluster::Returned::Failed(why) => ItemResult {
            format: item::FORMAT,
            scenario: scenario.display().to_string(),
            name: name_of(scenario),
            verdict: item::Verdict::Error,
            line: format!("error: {why}"),
            digest: None,
            first: None,
            log: None,
        },
    }
}

/// `ricochet test`: exit code 0 all passed, 1 any failed, 2 bad input, 130 interrupted.
pub fn run(opts: &Options) -> anyhow::Result<ExitCode> {
    let items = match gather(&opts.paths, opts.golden.as_deref()) {
        Ok(items) => items,
        Err(e) => {
            out::error(&format!("error: {e}"));
            return Ok(ExitCode::from(2));
        }
    };
    if let Some(g) = &opts.golden
        && !opts.bless
        && !g.is_dir()
    {
        out::error(&format!(
            "error: --golden {}: no such folder (--bless creates it)",
            out::escape_controls(&g.display().to_string())
        ));
        return Ok(ExitCode::from(2));
    }
    if let Some(j) = &opts.junit
        && let Err(e) = junit::check(j, &items, opts.golden.as_deref(), opts.keep.as_deref())
    {
        out::error(&format!("error: {e:#}"));
        return Ok(ExitCode::from(2));
    }
    let items = match opts.shard {
        Some(s) => s.select(items),
        None => items,
    };
    if let Some(dir) = &opts.keep {
        if let Err(e) = check_keep(&items, opts.golden.as_deref(), dir) {
            out::error(&format!("error: {e}"));
            return Ok(ExitCode::from(2));
        }
        if let Err(e) = std::fs::create_dir_all(dir) {
            out::error(&format!("error: --keep {}: {e}", dir.display()));
            return Ok(ExitCode::from(2));
        }
    }
    // The items' temporary files go here (their TMPDIR), removed at the end even when an
    // item's process had to be killed.
    let scratch = tempfile::tempdir()?;
    let jobs = opts
        .jobs
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, usize::from));
    let stop = stop_flag();
    let started = Instant::now();
    let bar = std::io::stderr().is_terminal().then(|| {
        let bar = indicatif::ProgressBar::new(items.len() as u64);
        bar.set_style(
            indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} scenarios {elapsed}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        bar
    });
    let argv = |i: usize| {
        let scenario: &Path = &items[i];
        // `--item=PATH`: a path that starts with `-` is still the value, and the result
        // line names the scenario as given.
        let mut item = OsString::from("--item=");
        item.push(scenario);
        let mut a: Vec<OsString> = vec!["test".into(), item];
        // Each item records in a scratch folder of its own; `--out` is only where to keep.
        if let Some(keep) = &opts.keep {
            a.extend(["--out".into(), not_a_flag(keep)]);
        }
        if let Some(g) = &opts.golden {
            a.extend(["--golden".into(), not_a_flag(g)]);
        }
        if opts.bless {
            a.push("--bless".into());
        }
        (scenario.to_owned(), a)
    };
    // Results by item; printed in item order as soon as every earlier one is in.
    let mut results: Vec<Option<ItemResult>> = vec![None; items.len()];
    let mut printed = 0;
    let mut write_error = None;
    let mut on_done = |i, r| {
        results[i] = Some(r);
        if let Some(b) = &bar {
            b.inc(1);
        }
        while let Some(Some(r)) = results.get(printed) {
            let line = format!("{}: {}\n", out::escape_controls(&r.scenario), r.line);
            let written = match &bar {
                Some(b) => b.suspend(|| out::print(&line)),
                None => out::print(&line),
            };
            if let Err(e) = written {
                write_error.get_or_insert(e);
            }
            printed += 1;
        }
    };
    let started_count = match &opts.cluster {
        None => pool::run(items.len(), jobs, &stop, scratch.path(), argv, on_done)?,
        Some(c) => match cluster::run(
            c,
            items.len(),
            &stop,
            |i| argv(i).1,
            |i, returned| on_done(i, from_cluster(&items[i], opts.golden.as_deref(), returned)),
        ) {
            Ok(n) => n,
            Err(e) => {
                out::error(&format!("error: {e}"));
                return Ok(ExitCode::from(2));
            }
        },
    };
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    if let Some(e) = write_error {
        return Err(e.into());
    }
    let interrupted = stop.load(Ordering::SeqCst);
    // After a stop, the results that came in after a missing one.
    let done: Vec<ItemResult> = results.into_iter().flatten().collect();
    for r in done.iter().skip(printed) {
        out::print(&format!(
            "{}: {}\n",
            out::escape_controls(&r.scenario),
            r.line
        ))?;
    }
    let passed = done.iter().filter(|r| r.verdict.passed()).count();
    let failed = done.len() - passed;
    out::print(&format!("{passed} passed, {failed} failed\n"))?;
    if let Some(path) = &opts.junit {
        junit::write(path, SUITE, &done)?;
    }
    let shard = opts
        .shard
        .map_or_else(String::new, |s| format!(" (shard {s})"));
    out::note(&format!(
        "{} scenario{}{shard} in {:.1} s, {}",
        done.len(),
        if done.len() == 1 { "" } else { "s" },
        started.elapsed().as_secs_f64(),
        opts.cluster.as_ref().map_or_else(
            || format!("{} at a time", pool::slots(jobs).min(items.len()).max(1)),
            |c| format!("on the cluster at {}", c.scheduler)
        )
    ))?;
    if interrupted {
        let stopped = done
            .iter()
            .filter(|r| r.verdict == item::Verdict::Interrupted)
            .count();
        out::note(&format!(
            "interrupted: {} of {} scenarios not started, {stopped} stopped; no golden was \
             left half-written",
            items.len() - started_count,
            items.len()
        ))?;
        return Ok(ExitCode::from(130));
    }
    Ok(if failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

/// `path` as an argument of an item's process that can't be taken for a flag: `./-x` for
/// a relative `-x`, the same file.
fn not_a_flag(path: &Path) -> OsString {
    if path.as_os_str().as_encoded_bytes().starts_with(b"-") {
        Path::new(".").join(path).into_os_string()
    } else {
        path.as_os_str().to_owned()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use item::{Digest, Verdict};

    fn result(hash: &str) -> ItemResult {
        ItemResult {
            format: item::FORMAT,
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

    /// `--verify` on two workers that disagree: the item fails, and the worker whose digest
    /// the golden `.digest` file holds is named, whichever ran first.
    #[test]
    fn a_disagreement_names_the_worker_the_golden_digest_agrees_with() {
        let dir = tempfile::tempdir().unwrap();
        let golden = Digest {
            frames: 600,
            bodies: 6,
            hash: "00aa".to_owned(),
        };
        std::fs::write(dir.path().join("a.digest"), golden.text()).unwrap();
        let line = |first: &str, again: &str| {
            let r = from_cluster(
                Path::new("s/a.toml"),
                Some(dir.path()),
                cluster::Returned::Unverified {
                    result: result(first),
                    why: "the workers disagree".to_owned(),
                    first: "tcp://w:1".to_owned(),
                    again: Some(("tcp://w:2".to_owned(), result(again))),
                },
            );
            assert_eq!(r.verdict, Verdict::Error);
            r.line
        };
        assert_eq!(
            line("00aa", "0000"),
            "error: --verify: the workers disagree (the golden digest agrees with tcp://w:1)"
        );
        assert_eq!(
            line("0000", "00aa"),
            "error: --verify: the workers disagree (the golden digest agrees with tcp://w:2)"
        );
        assert_eq!(
            line("0000", "1111"),
            "error: --verify: the workers disagree (the golden digest agrees with neither)"
        );
    }
}
