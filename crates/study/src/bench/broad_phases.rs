//! `ricochet bench --broad-phases`: every broad phase on every scene (issue #24's study).
//!
//! For each scene and each [`BroadPhaseKind`] but `Auto`, a fresh [`Simulation`] with that
//! kind forced is stepped `frames + 1` times (every kind gives the same simulation, so the
//! same frames). Two figures come from it:
//! - **whole step**: the time of `Simulation::step`;
//! - **broad phase alone**: after each step, the bodies' exact bounds at their poses are
//!   handed to a [`BroadPhase`] of that kind of the study's own (`pairs_split`: the static
//!   bodies once, the moving ones every frame), as `detect` hands them over, and only that
//!   call is timed. Like `detect`, it leaves out the static bodies of a layer that pairs with
//!   no layer through the broad phase (a tile map the per-axis stages meet), and takes the
//!   layer table `detect` takes (`ignore`, and `separate` between two layers of boxes, do
//!   not interact). It does not add a wrapping world's seam images.
//!
//! The first frame (the structures built) is not in the means. Memory is
//! [`BroadPhase::heap_bytes`] of the study's broad phase after the last frame. The pairs per
//! frame are the study's broad phase's: every kind must find the same number on every
//! frame, or the run fails. `Auto`'s pick is what a simulation left on `auto` reports in
//! its last frame. Brute force is skipped above [`BRUTE_FORCE_MAX`] bodies given to the
//! broad phase. Figures, never assertions.
//!
//! The last table says, per scene, `Auto`'s estimate of sort and sweep's x-overlaps per body
//! ([`BroadPhase::sweep_overlaps`], the figure its rule compares), its pick, the pick's
//! broad-phase time over the fastest kind's, and whether that is within [`AUTO_WITHIN`]
//! (issue #24's 10%); a line counts the scenes within. A report: a miss is printed, never
//! an exit code. One kind's run is [`run_kind`]; its timed call, [`broad_phase_call`], is
//! out of line so that callgrind can count it alone (`examples/broad_phase_kind.rs`).

use std::fmt::Write as _;
use std::time::Instant;

use anyhow::bail;
use ricochet_scenes::bench::Scene;
use ricochet_sim::broad_phase::{BodyEntry, BroadPhase, BroadPhaseKind, Interactions};
use ricochet_sim::{BodyKind, Response, Scenario, Simulation};

/// The kinds measured, in table order.
pub const KINDS: [BroadPhaseKind; 6] = [
    BroadPhaseKind::BruteForce,
    BroadPhaseKind::SortAndSweep,
    BroadPhaseKind::Grid,
    BroadPhaseKind::Strips,
    BroadPhaseKind::Quadtree,
    BroadPhaseKind::Tree,
];

/// Brute force runs only up to this many bodies given to the broad phase (at 4,000, about
/// 8 million tests a frame).
pub const BRUTE_FORCE_MAX: usize = 4_000;

/// The scenes `--broad-phases` runs when none is named: every bench scene of BENCHMARKS.md
/// and the study's three.
pub const DEFAULT_SCENES: [&str; 8] = [
    "asteroids-10000",
    "asteroids-100000",
    "platformer-10000-1000",
    "platformer-1000000-1000",
    "rain-10000",
    "crowded-10000",
    "sparse-10000",
    "mixed-10000",
];

/// One kind's figures on one scene.
#[derive(Clone, Copy, Debug)]
pub struct KindFigures {
    /// The broad phase.
    pub kind: BroadPhaseKind,
    /// Mean ms of the study's broad-phase call per frame.
    pub broad_ms: f64,
    /// Mean ms of `Simulation::step` per frame.
    pub step_ms: f64,
    /// Pairs found over the timed frames.
    pub pairs: u64,
    /// The structures' heap bytes, when the kind reports them.
    pub bytes: Option<usize>,
}

/// One scene's figures.
#[derive(Clone, Debug)]
pub struct BroadPhaseRow {
    /// The scene's name.
    pub scene: String,
    /// Timed frames.
    pub frames: u64,
    /// Moving bodies given to the broad phase.
    pub movers: usize,
    /// Static bodies given to the broad phase (a tile map it never meets is not).
    pub statics: usize,
    /// What `Auto` picked (in the last frame).
    pub auto: Option<BroadPhaseKind>,
    /// `Auto`'s estimate of sort and sweep's x-overlaps per body
    /// ([`BroadPhase::sweep_overlaps`]) after the first frame; 0 when no crowd layer.
    pub overlaps: f64,
    /// Per kind of [`KINDS`], or `None` where skipped.
    pub kinds: Vec<Option<KindFigures>>,
}

impl BroadPhaseRow {
    /// The fastest kind's broad-phase ms.
    #[must_use]
    pub fn best_broad_ms(&self) -> f64 {
        self.kinds
            .iter()
            .flatten()
            .map(|k| k.broad_ms)
            .fold(f64::INFINITY, f64::min)
    }

    /// `Auto`'s pick's figures.
    #[must_use]
    pub fn auto_figures(&self) -> Option<&KindFigures> {
        self.kinds
            .iter()
            .flatten()
            .find(|k| Some(k.kind) == self.auto)
    }

    /// Pairs per timed frame.
    #[must_use]
    pub fn pairs_per_frame(&self) -> f64 {
        let pairs = self.kinds.iter().flatten().map(|k| k.pairs).next();
        pairs.unwrap_or(0) as f64 / self.frames.max(1) as f64
    }
}

/// The layer table `detect` gives the broad phase.
fn interactions(sim: &Simulation) -> Interactions {
    let layers = &sim.scenario().world.layers;
    let n = layers.names().len();
    let w = sim.world();
    Interactions::from_fn(n, |a, b| match layers.response(a, b) {
        Response::Ignore => false,
        Response::Separate => !(w.only_boxes(a) && w.only_boxes(b)),
        _ => true,
    })
}

/// The bodies as the broad phase sees them: `(statics, movers)`, keys their indices.
fn entries(
    sim: &Simulation,
    interactions: &Interactions,
    statics: &mut Vec<BodyEntry>,
    movers: &mut Vec<BodyEntry>,
    with_statics: bool,
) {
    let w = sim.world();
    let n_layers = sim.scenario().world.layers.names().len();
    let paired = |l: u8| (0..n_layers).any(|m| interactions.interacts(l, m as u8));
    movers.clear();
    for i in 0..w.len() {
        let kind = w.kind[i];
        if kind == BodyKind::Static && !(with_statics && paired(w.layer[i])) {
            continue;
        }
        let entry = BodyEntry {
            key: i as u64,
            bounds: w.shape(i).bounds(&w.pose(i)),
            layer: w.layer[i],
            kind,
        };
        if kind == BodyKind::Static {
            statics.push(entry);
        } else {
            movers.push(entry);
        }
    }
}

/// The one broad-phase call the study times, kept out of line so that callgrind can count
/// it alone (`--toggle-collect='*broad_phase_call*'`, see `examples/broad_phase_kind.rs`).
#[inline(never)]
pub fn broad_phase_call(
    bp: &mut BroadPhase,
    statics: &[BodyEntry],
    movers: &[BodyEntry],
    table: &Interactions,
    out: &mut Vec<(u32, u32)>,
) {
    bp.pairs_split(statics, 0, movers, table, out);
}

/// One kind stepped through a scene.
#[derive(Clone, Debug)]
pub struct KindRun {
    /// Its figures (frame 0 left out).
    pub figures: KindFigures,
    /// Pairs found on each frame, frame 0 included.
    pub counts: Vec<u64>,
    /// Moving and static bodies given to the broad phase.
    pub movers: usize,
    /// Static bodies given to the broad phase.
    pub statics: usize,
    /// The broad phase's [`BroadPhase::sweep_overlaps`] after the last frame (0 unless
    /// `kind` is `Auto`).
    pub overlaps: f64,
}

/// Steps `scenario` `frames + 1` times with `kind` forced, handing the bodies to a broad
/// phase of `kind` of the study's own after each step (see the module docs).
#[must_use]
pub fn run_kind(scenario: &Scenario, kind: BroadPhaseKind, frames: u64) -> KindRun {
    let mut s = scenario.clone();
    s.world.broad_phase = kind;
    let mut sim = Simulation::from_scenario(s);
    let table = interactions(&sim);
    let (mut statics, mut movers) = (Vec::new(), Vec::new());
    entries(&sim, &table, &mut statics, &mut movers, true);
    let mut bp = BroadPhase::new(kind);
    let mut out = Vec::new();
    let (mut broad, mut step, mut pairs) = (0.0, 0.0, 0);
    let mut counts = Vec::new();
    for frame in 0..=frames {
        let t = Instant::now();
        drop(std::hint::black_box(sim.step()));
        let step_s = t.elapsed().as_secs_f64();
        entries(&sim, &table, &mut Vec::new(), &mut movers, false);
        let t = Instant::now();
        broad_phase_call(&mut bp, &statics, &movers, &table, &mut out);
        let broad_s = t.elapsed().as_secs_f64();
        counts.push(out.len() as u64);
        if frame > 0 {
            broad += broad_s;
            step += step_s;
            pairs += out.len() as u64;
        }
    }
    let per_frame = 1e3 / frames.max(1) as f64;
    KindRun {
        figures: KindFigures {
            kind,
            broad_ms: broad * per_frame,
            step_ms: step * per_frame,
            pairs,
            bytes: bp.heap_bytes(kind),
        },
        counts,
        movers: movers.len(),
        statics: statics.len(),
        overlaps: bp.sweep_overlaps(),
    }
}

/// Measures every kind on `scene` (see the module docs); `progress` hears of each kind.
///
/// # Errors
/// Two kinds that find different numbers of pairs on a frame (a bug: the figures would
/// compare different work).
pub fn run_broad_phases(
    name: &str,
    scene: Scene,
    frames: u64,
    mut progress: impl FnMut(&str),
) -> anyhow::Result<BroadPhaseRow> {
    let scenario = scene.build(frames + 1);
    let mut auto_sim = Simulation::from_scenario(scenario.clone());
    let mut auto = None;
    for _ in 0..=frames {
        auto = auto_sim.step().stats.broad_phase.or(auto);
    }
    drop(auto_sim);
    // Auto's estimate, and the bodies given, as the study's own broad phase sees the scene.
    let probe = run_kind(&scenario, BroadPhaseKind::Auto, 0);
    let overlaps = probe.overlaps;
    let mut row = BroadPhaseRow {
        scene: name.to_owned(),
        frames,
        movers: 0,
        statics: 0,
        auto,
        overlaps,
        kinds: Vec::new(),
    };
    // Pairs per frame of the first kind run, which every other must match.
    let mut expected: Vec<u64> = Vec::new();
    for kind in KINDS {
        if kind == BroadPhaseKind::BruteForce && probe.movers + probe.statics > BRUTE_FORCE_MAX {
            row.kinds.push(None);
            continue;
        }
        progress(&format!("{name}: {}", kind.name()));
        let run = run_kind(&scenario, kind, frames);
        if expected.is_empty() {
            expected = run.counts;
        } else if run.counts != expected {
            bail!(
                "{name}: {} found other pair counts than {}",
                kind.name(),
                KINDS[0].name()
            );
        }
        (row.movers, row.statics) = (run.movers, run.statics);
        row.kinds.push(Some(run.figures));
    }
    Ok(row)
}

/// How far `Auto`'s pick may be from the fastest kind (issue #24): 10%.
pub const AUTO_WITHIN: f64 = 1.10;

/// The three tables (broad phase alone, whole step, memory), Markdown, `Auto`'s pick
/// marked `†`, the best broad phase in bold; then, per scene, `Auto`'s pick and how far it
/// is from the fastest (a report: a miss is printed, never an error).
#[must_use]
pub fn table(rows: &[BroadPhaseRow]) -> String {
    let mut t = String::new();
    // One table: its title, its header, and a row per scene of one cell per kind.
    let mut section = |what: &str, cell: &dyn Fn(&BroadPhaseRow, &KindFigures) -> String| {
        let _ = write!(t, "\n{what}\n\n| scene | movers | statics |");
        for k in KINDS {
            let _ = write!(t, " {} |", k.name());
        }
        let _ = write!(t, "\n|---|---:|---:|{}\n", "---:|".repeat(KINDS.len()));
        for r in rows {
            let _ = write!(t, "| {} | {} | {} |", r.scene, r.movers, r.statics);
            for k in &r.kinds {
                let v = k.as_ref().map_or_else(|| "–".to_owned(), |k| cell(r, k));
                let _ = write!(t, " {v} |");
            }
            t.push('\n');
        }
    };
    let dagger =
        |r: &BroadPhaseRow, k: &KindFigures| if Some(k.kind) == r.auto { "†" } else { "" };
    section(
        "Broad phase alone, ms per frame († = Auto's pick, bold = fastest)",
        &|r, k| {
            let v = format!("{:.3}{}", k.broad_ms, dagger(r, k));
            if k.broad_ms <= r.best_broad_ms() {
                format!("**{v}**")
            } else {
                v
            }
        },
    );
    section("Whole step, ms per frame († = Auto's pick)", &|r, k| {
        format!("{:.3}{}", k.step_ms, dagger(r, k))
    });
    section("Memory of the structures, KB (– = skipped)", &|_, k| {
        k.bytes
            .map_or("–".to_owned(), |b| format!("{:.0}", b as f64 / 1024.0))
    });
    let _ = write!(
        t,
        "\n| scene | pairs per frame | x-overlaps per body | Auto | Auto ÷ fastest | within 10% |\n\
         |---|---:|---:|---|---:|---|\n"
    );
    let (mut within, mut judged) = (0, 0);
    for r in rows {
        let ratio = r.auto_figures().map(|a| a.broad_ms / r.best_broad_ms());
        let verdict = match ratio {
            Some(x) if x <= AUTO_WITHIN => "yes",
            Some(_) => "**no**",
            None => "–",
        };
        judged += usize::from(ratio.is_some());
        within += usize::from(ratio.is_some_and(|x| x <= AUTO_WITHIN));
        let ratio = ratio.map_or("–".to_owned(), |x| format!("{x:.2}"));
        let auto = r.auto.map_or("–", BroadPhaseKind::name);
        let _ = writeln!(
            t,
            "| {} | {:.1} | {:.2} | {auto} | {ratio} | {verdict} |",
            r.scene,
            r.pairs_per_frame(),
            r.overlaps,
        );
    }
    let _ = writeln!(
        t,
        "\nAuto is within 10% of the fastest broad phase on {within} of {judged} scenes."
    );
    t
}

/// What the tables mean, printed under them.
pub const NOTES: &str = "\nBroad phase alone: the kind's BroadPhase::pairs_split on the \
bodies' exact bounds after each step (static bodies handed over once, the moving ones every \
frame), the first frame left out. Whole step: Simulation::step with the kind forced. Memory: \
BroadPhase::heap_bytes (capacities, the stored static bodies included). x-overlaps per body: \
Auto's estimate of the bodies sort and sweep tests each body against in the most crowded \
self-interacting layer (BroadPhase::sweep_overlaps; 0 when no layer of 256 or more). Brute \
force is skipped above 4000 bodies. Every kind found the same pairs on every frame. Timings \
vary by about 30% between runs on a shared machine; a ratio is a figure, never a test.\n";
