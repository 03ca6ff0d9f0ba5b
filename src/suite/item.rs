//! One scenario's run and verdict: what `ricochet test --item SCENARIO` does in its own
//! process, and prints as one JSON line (the [`ItemResult`]).
//!
//! The scenario is recorded exactly as `ricochet run` records it (every channel, the same
//! [`Recorder`]), then compared with its golden log `GOLDEN/NAME.mcap` byte for byte (the
//! first divergence found by `ricochet diff`'s comparison) and with its golden digest
//! `GOLDEN/NAME.digest` (`frames N`, `bodies N`, `hash X` of the final state, Box2D's
//! determinism gate). With `--bless` the goldens are written instead, each through a
//! temporary file renamed into place.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use ricochet_log::LogFile;
use ricochet_sim::Simulation;
use serde::{Deserialize, Serialize};

use super::read::{open_regular, read_golden, read_scenario, same_bytes};
use crate::channels::Channels;
use crate::diff::{Divergence, diff_files};
use crate::out::escape_controls;
use crate::record::Recorder;

/// The version of the result line's format. A field is only ever added; a change to an
/// existing one bumps this.
pub const FORMAT: u32 = 1;

/// The longest file name, in bytes, on Linux's file systems.
const NAME_MAX: usize = 255;

/// What became of one scenario.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// Its log and digest equal the goldens.
    Ok,
    /// Its log or digest differs from the golden.
    Differs,
    /// There is no golden log or digest to compare with.
    NoGolden,
    /// It could not be run: the scenario does not load, the simulation overflowed, a file
    /// could not be read or written.
    Error,
    /// `--bless`: the goldens did not exist and were written.
    BlessedNew,
    /// `--bless`: the goldens differed and were replaced.
    BlessedChanged,
    /// `--bless`: the goldens were already right and were left alone.
    Unchanged,
    /// Stopped by Ctrl-C (or SIGTERM) before it finished; no golden was touched.
    Interrupted,
}

impl Verdict {
    /// Whether the scenario counts as passed in the summary.
    pub fn passed(self) -> bool {
        matches!(
            self,
            Verdict::Ok | Verdict::BlessedNew | Verdict::BlessedChanged | Verdict::Unchanged
        )
    }
}

/// The final state's digest, as `GOLDEN/NAME.digest` holds it.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Eq)]
pub struct Digest {
    /// Steps after frame 0 (the scenario's `frames`).
    pub frames: u64,
    /// Bodies alive at the end.
    pub bodies: u64,
    /// `World::digest` of the final state, 16 hex digits.
    pub hash: String,
}

impl Digest {
    /// The `.digest` file's text: `frames N`, `bodies N`, `hash X`, one a line.
    pub fn text(&self) -> String {
        format!(
            "frames {}\nbodies {}\nhash {}\n",
            self.frames, self.bodies, self.hash
        )
    }
}

/// The first difference between the golden log and the fresh one, as `ricochet diff`
/// names it.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Eq)]
pub struct First {
    /// The frame, when the message has one.
    pub frame: Option<u64>,
    /// The topic (`/bodies`, `/contacts`, ...).
    pub topic: String,
    /// The body (`4:0 (ship)`) or contact pair (`pair 6:0/9:0`), when there is one.
    pub body: Option<String>,
    /// The field's path in the message (`bodies[id=4:0].velocity[0]`).
    pub field: String,
    /// Its value in the golden log (JSON), or a note such as `missing`.
    pub golden: String,
    /// Its value in the fresh log.
    pub now: String,
}

impl super::cluster::ResultLine for ItemResult {
    /// `frames N bodies N hash X`, or `no digest (LINE)` for a run that did not end.
    fn digest_text(&self) -> String {
        self.digest.as_ref().map_or_else(
            || format!("no digest ({})", self.line),
            |d| format!("frames {} bodies {} hash {}", d.frames, d.bodies, d.hash),
        )
    }
}

impl From<Divergence> for First {
    fn from(d: Divergence) -> Self {
        First {
            frame: d.frame,
            topic: d.topic,
            body: d.body.filter(|b| !b.is_empty()),
            field: d.field,
            golden: d.a,
            now: d.b,
        }
    }
}

/// The result line of `ricochet test --item`: one JSON object on one line. The runner
/// merges these lines; a cluster worker returns exactly this line.
#[derive(Serialize, Deserialize, Debug, Clone)]
pub struct ItemResult {
    /// [`FORMAT`].
    pub format: u32,
    /// The scenario file, as given.
    pub scenario: String,
    /// Its name: the file name without `.toml`, which names its goldens.
    pub name: String,
    /// The verdict.
    pub verdict: Verdict,
    /// The verdict as the runner prints it after `SCENARIO: ` (`ok`, `differs: frame 185,
    /// /contacts, pair 6:0/9:0, depth 0.031 → 0.029`, ...).
    pub line: String,
    /// The fresh run's final digest, when it ran to the end.
    pub digest: Option<Digest>,
    /// The first divergence of the log, when it differs.
    pub first: Option<First>,
    /// Where the fresh log was kept (`--out`), else null.
    pub log: Option<String>,
}

/// What to run, from `ricochet test --item`.
pub struct ItemOptions<'a> {
    /// The scenario file.
    pub scenario: &'a Path,
    /// The goldens' directory; default: [`default_golden`].
    pub golden: Option<&'a Path>,
    /// Keep the fresh log here as NAME.mcap; default: a temporary file, removed.
    pub out: Option<&'a Path>,
    /// Write the goldens instead of comparing.
    pub bless: bool,
}

/// A scenario's name: its file name without the extension.
pub fn name_of(scenario: &Path) -> String {
    scenario.file_stem().map_or_else(
        || "scenario".to_owned(),
        |s| s.to_string_lossy().into_owned(),
    )
}

/// `recordings/` beside the scenario's folder: `game/scenarios/a.toml` has its goldens in
/// `game/recordings/`.
pub fn default_golden(scenario: &Path) -> PathBuf {
    let folder = match scenario.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    match (folder.file_name(), folder.parent()) {
        (Some(_), Some(up)) if up.as_os_str().is_empty() => PathBuf::from("recordings"),
        (Some(_), Some(up)) => up.join("recordings"),
        // `.`, `..` or `/`: the folder has no name to step out of.
        _ => folder.join("..").join("recordings"),
    }
}

/// How a golden file compares with what the run made.
enum Golden {
    Missing,
    Same,
    Differs(Option<First>, String),
}

/// Runs one scenario to its verdict. `stop` (Ctrl-C) ends the run at the next frame.
pub fn run(opts: &ItemOptions, stop: &AtomicBool) -> ItemResult {
    let name = name_of(opts.scenario);
    let mut result = ItemResult {
        format: FORMAT,
        scenario: opts.scenario.display().to_string(),
        name: name.clone(),
        verdict: Verdict::Error,
        line: String::new(),
        digest: None,
        first: None,
        log: None,
    };
    match judge(opts, &name, stop, &mut result) {
        Ok((verdict, line)) => {
            result.verdict = verdict;
            result.line = line;
        }
        Err(e) => {
            result.verdict = Verdict::Error;
            result.line = format!("error: {}", escape_controls(&e));
        }
    }
    result
}

/// The verdict and its line; `Err` is the message of an [`Verdict::Error`].
fn judge(
    opts: &ItemOptions,
    name: &str,
    stop: &AtomicBool,
    result: &mut ItemResult,
) -> Result<(Verdict, String), String> {
    let path = opts.scenario;
    // The longest golden name, `NAME.digest`, must be a legal file name (255 bytes on
    // Linux's file systems): the one limit on a name that temporary names can't lift.
    if name.len() + ".digest".len() > NAME_MAX {
        return Err(format!(
            "{}: a name of {} bytes makes its golden {name}.digest longer than the {NAME_MAX} \
             bytes a file name may have; shorten it to {} bytes at most (before .toml)",
            path.display(),
            name.len(),
            NAME_MAX - ".digest".len()
        ));
    }
    let text = read_scenario(path)?;
    let scenario = crate::load::scenario_with_map(&text, path)?;
    drop(text);
    scenario
        .world
        .last_time_ns(scenario.frames)
        .map_err(|e| format!("{}: frames {}: {e}", path.display(), scenario.frames))?;
    let golden = opts
        .golden
        .map_or_else(|| default_golden(path), Path::to_owned);
    let golden_log = golden.join(format!("{name}.mcap"));
    let golden_digest = golden.join(format!("{name}.digest"));
    let kept = opts.out.map(|dir| dir.join(format!("{name}.mcap")));
    if let Some(kept) = &kept
        && crate::files::same_file(kept, &golden_log)
    {
        return Err(format!(
            "--out {}: the fresh log would replace the golden {}; keep the fresh logs in \
             another folder",
            kept.display(),
            golden_log.display()
        ));
    }
    let (_scratch, log) = fresh_log(opts.out)?;
    let mut recorder = Recorder::create(&log, scenario.world.dt, Channels::default())
        .map_err(|e| format!("cannot write the log: {e}"))?;
    let mut sim = Simulation::new(&scenario);
    // The runner's parallelism is one process per item; the log is the same bytes with any
    // thread count.
    sim.set_threads(1);
    for _ in 0..=scenario.frames {
        if stop.load(Ordering::SeqCst) {
            let _ = recorder.finish();
            return Ok((Verdict::Interrupted, "interrupted".to_owned()));
        }
        let out = sim.step();
        if let Some(bad) = sim.first_non_finite_after(&out) {
            let _ = recorder.finish();
            return Err(format!(
                "frame {}: {}; the simulation overflowed",
                out.frame,
                crate::validate::describe(&sim, &bad)
            ));
        }
        recorder
            .record(&sim, &out)
            .map_err(|e| format!("writing frame {} of the log: {e}", out.frame))?;
    }
    recorder
        .finish()
        .map_err(|e| format!("finishing the log: {e}"))?;
    let digest = Digest {
        frames: scenario.frames,
        bodies: sim.world().len() as u64,
        hash: format!("{:016x}", sim.world().digest()),
    };
    result.digest = Some(digest.clone());

    // Blessing needs only to know whether the golden is the same; not where it differs.
    let log_state = compare_log(&golden_log, &log, !opts.bless)?;
    let digest_state = compare_digest(&golden_digest, &digest.text())?;
    // Kept only once both comparisons have read the goldens, and never onto one (above).
    let log = match kept {
        Some(kept) => {
            std::fs::rename(&log, &kept)
                .map_err(|e| format!("cannot keep the fresh log as {}: {e}", kept.display()))?;
            result.log = Some(kept.display().to_string());
            kept
        }
        None => log,
    };
    if opts.bless {
        return bless(
            stop,
            &golden,
            (&golden_log, &log),
            (&golden_digest, &digest),
            (&log_state, &digest_state),
        );
    }
    Ok(match (log_state, digest_state) {
        (Golden::Missing, _) => (Verdict::NoGolden, "no golden (run with --bless)".to_owned()),
        (Golden::Differs(first, line), _) => {
            result.first = first;
            (Verdict::Differs, line)
        }
        (Golden::Same, Golden::Missing) => (
            Verdict::NoGolden,
            "no golden digest (run with --bless)".to_owned(),
        ),
        (Golden::Same, Golden::Differs(_, line)) => (Verdict::Differs, line),
        (Golden::Same, Golden::Same) => (Verdict::Ok, "ok".to_owned()),
    })
}

/// Where this item records its fresh log: a file in a scratch folder of its own (removed
/// with the returned guard), so no two items share one, whatever their names, and the
/// name is short whatever the scenario's. With `--out DIR` the folder is inside `DIR`, so
/// keeping the log is a rename on one filesystem.
fn fresh_log(out: Option<&Path>) -> Result<(tempfile::TempDir, PathBuf), String> {
    let scratch = match out {
        Some(dir) => {
            std::fs::create_dir_all(dir).map_err(|e| format!("--out {}: {e}", dir.display()))?;
            tempfile::Builder::new()
                .prefix(".ricochet-item-")
                .tempdir_in(dir)
                .map_err(|e| format!("--out {}: {e}", dir.display()))?
        }
        None => tempfile::tempdir().map_err(|e| format!("a temporary directory: {e}"))?,
    };
    let log = scratch.path().join("fresh.mcap");
    Ok((scratch, log))
}

/// The golden log against the fresh one: equal bytes, or (with `locate`) the first
/// divergence.
fn compare_log(golden: &Path, log: &Path, locate: bool) -> Result<Golden, String> {
    let Some(kept) = open_regular(golden, "the golden")? else {
        return Ok(Golden::Missing);
    };
    let fresh = std::fs::File::open(log).map_err(|e| format!("{}: {e}", log.display()))?;
    let same = same_bytes(kept, fresh)
        .map_err(|e| format!("comparing with the golden {}: {e}", golden.display()))?;
    if same {
        return Ok(Golden::Same);
    }
    if !locate {
        return Ok(Golden::Differs(None, "differs".to_owned()));
    }
    let report = LogFile::open(golden)
        .and_then(|g| LogFile::open(log).map(|f| (g, f)))
        .map_err(crate::diff::DiffError::from)
        .and_then(|(g, f)| diff_files(&g, &f, 0.0, None));
    Ok(match report {
        Ok(r) => match r.first {
            Some(d) => {
                let first = First::from(d);
                let line = format!("differs: {}", compact(&first));
                Golden::Differs(Some(first), line)
            }
            None => Golden::Differs(
                None,
                "differs: the same messages, but not the same bytes (chunking or \
                 compression)"
                    .to_owned(),
            ),
        },
        Err(e) => Golden::Differs(
            None,
            format!(
                "differs: the golden log can't be compared: {}",
                escape_controls(&e.to_string())
            ),
        ),
    })
}

/// The golden digest against the fresh one: the first line that differs.
fn compare_digest(golden: &Path, fresh: &str) -> Result<Golden, String> {
    let Some(kept) = read_golden(golden)? else {
        return Ok(Golden::Missing);
    };
    // A digest saved with CRLF line ends (a Windows checkout) holds the same three lines.
    let kept = String::from_utf8_lossy(&kept).replace("\r\n", "\n");
    if kept == fresh {
        return Ok(Golden::Same);
    }
    let mut old = kept.lines();
    let line = fresh
        .lines()
        .find_map(|now| {
            let was = old.next().unwrap_or("");
            (was != now).then(|| {
                let field = now.split(' ').next().unwrap_or("");
                let value = |l: &str| l.strip_prefix(field).unwrap_or(l).trim().to_owned();
                format!(
                    "differs: digest {field} {} → {}",
                    escape_controls(&value(was)),
                    value(now)
                )
            })
        })
        .unwrap_or_else(|| "differs: digest has extra lines".to_owned());
    Ok(Golden::Differs(None, line))
}

/// Writes the goldens that differ or are missing.
fn bless(
    stop: &AtomicBool,
    dir: &Path,
    (golden_log, fresh): (&Path, &Path),
    (golden_digest, digest): (&Path, &Digest),
    (log_state, digest_state): (&Golden, &Golden),
) -> Result<(Verdict, String), String> {
    if matches!((log_state, digest_state), (Golden::Same, Golden::Same)) {
        return Ok((Verdict::Unchanged, "unchanged".to_owned()));
    }
    if stop.load(Ordering::SeqCst) {
        return Ok((Verdict::Interrupted, "interrupted".to_owned()));
    }
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    // Each file goes through a temporary file renamed into place, so a golden is always
    // whole, the old one or the new. The digest last: a stop between the two leaves a log
    // whose digest then differs, which the next run reports.
    crate::files::copy(golden_log, fresh).map_err(|e| format!("{e:#}"))?;
    crate::files::write(golden_digest, digest.text().as_bytes()).map_err(|e| format!("{e:#}"))?;
    Ok(
        if matches!(
            (log_state, digest_state),
            (Golden::Missing, Golden::Missing)
        ) {
            (Verdict::BlessedNew, "blessed (new)".to_owned())
        } else {
            (Verdict::BlessedChanged, "blessed (changed)".to_owned())
        },
    )
}

/// Longest value shown in a one-line divergence; a longer one (a whole shape) is cut.
const VALUE_CHARS: usize = 40;

/// `frame 185, /contacts, pair 6:0/9:0, depth 0.031 → 0.029`: the first divergence on one
/// line. The field is its last part (`depth`, `velocity[0]`); `--keep` and `ricochet diff`
/// give the whole path.
pub fn compact(first: &First) -> String {
    if first.field == "schema" {
        return format!("the schema of {}", first.topic);
    }
    let mut s = String::new();
    if let Some(f) = first.frame {
        s += &format!("frame {f}, ");
    }
    s += &first.topic;
    match &first.body {
        Some(pair) if pair.starts_with("pair ") => s += &format!(", {pair}"),
        Some(body) => s += &format!(", body {body}"),
        None => {}
    }
    s += &format!(
        ", {} {} → {}",
        leaf(&first.field),
        cut(&first.golden),
        cut(&first.now)
    );
    escape_controls(&s)
}

/// The last part of a field path, outside brackets: `bodies[id=4:0].velocity[0]` gives
/// `velocity[0]`.
fn leaf(field: &str) -> &str {
    let mut depth = 0usize;
    let mut start = 0;
    for (i, c) in field.char_indices() {
        match c {
            '[' => depth += 1,
            ']' => depth = depth.saturating_sub(1),
            '.' if depth == 0 => start = i + 1,
            _ => {}
        }
    }
    &field[start..]
}

fn cut(value: &str) -> String {
    if value.chars().count() <= VALUE_CHARS {
        value.to_owned()
    } else {
        let head: String = value.chars().take(VALUE_CHARS - 1).collect();
        format!("{head}…")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_leaf_of_a_field_path_ignores_dots_inside_brackets() {
        assert_eq!(leaf("bodies[id=4:0].velocity[0]"), "velocity[0]");
        assert_eq!(leaf("contacts[id=a.b].depth"), "depth");
        assert_eq!(leaf("frame"), "frame");
    }

    #[test]
    fn goldens_live_in_recordings_beside_the_scenario_folder() {
        let g = |s: &str| default_golden(Path::new(s));
        assert_eq!(g("scenarios/a.toml"), Path::new("recordings"));
        assert_eq!(g("game/scenarios/a.toml"), Path::new("game/recordings"));
        assert_eq!(g("/x/scenarios/a.toml"), Path::new("/x/recordings"));
        assert_eq!(g("a.toml"), Path::new("./../recordings"));
    }

    /// Two items with one name (`g1/scenarios/level.toml`, `g2/scenarios/level.toml`),
    /// both recording at once into one `--out` folder or both into the temporary folder:
    /// each has a path of its own.
    #[test]
    fn two_items_with_one_name_record_to_paths_of_their_own() {
        let dir = tempfile::tempdir().unwrap();
        for out in [Some(dir.path()), None] {
            let (_a_scratch, a) = fresh_log(out).unwrap();
            let (_b_scratch, b) = fresh_log(out).unwrap();
            assert_ne!(a, b, "{out:?}");
            std::fs::write(&a, "a").unwrap();
            std::fs::write(&b, "b").unwrap();
            assert_eq!(std::fs::read(&a).unwrap(), b"a");
        }
    }

    #[test]
    fn a_divergence_fits_one_line() {
        let first = First {
            frame: Some(185),
            topic: "/contacts".into(),
            body: Some("pair 6:0/9:0".into()),
            field: "contacts[3].depth".into(),
            golden: "0.031".into(),
            now: "0.029".into(),
        };
        assert_eq!(
            compact(&first),
            "frame 185, /contacts, pair 6:0/9:0, depth 0.031 → 0.029"
        );
    }
}
