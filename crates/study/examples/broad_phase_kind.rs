//! One broad phase on one scene, as `ricochet bench --broad-phases` measures it: the harness
//! for counting the study's broad-phase call alone with callgrind (repeatable where the
//! wall clock of a shared machine is not).
//!
//! ```console
//! $ cargo build --release -p ricochet-study --example broad_phase_kind
//! $ valgrind --tool=callgrind --toggle-collect='*broad_phase_call*' \
//!     target/release/examples/broad_phase_kind sparse-1000 strips 60
//! ```
//!
//! Arguments: the scene (any `ricochet bench` scene name), the kind (`auto`,
//! `brute-force`, `sort-and-sweep`, `grid`, `strips`, `quadtree`, `tree`), the frames after
//! frame 0 (default 60). Two runs at different frame counts give the cost of one frame
//! without frame 0's builds. Prints the figures; a figure, never an assertion.

use ricochet_scenes::bench::Scene;
use ricochet_sim::broad_phase::BroadPhaseKind;
use ricochet_study::bench::broad_phases::{KINDS, run_kind};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: broad_phase_kind SCENE KIND [FRAMES]";
    let fail = |why: &str| -> ! {
        eprintln!("{why}\n{usage}");
        std::process::exit(2);
    };
    let (Some(name), Some(kind)) = (args.get(1), args.get(2)) else {
        fail("missing arguments");
    };
    let scene = Scene::parse(name).unwrap_or_else(|e| fail(&e.to_string()));
    let kind = std::iter::once(BroadPhaseKind::Auto)
        .chain(KINDS)
        .find(|k| k.name() == kind)
        .unwrap_or_else(|| fail(&format!("no broad phase {kind:?}")));
    let frames = args
        .get(3)
        .map_or(Ok(60), |s| s.parse::<u64>())
        .unwrap_or_else(|_| fail("FRAMES is a count"));
    let run = run_kind(&scene.build(frames + 1), kind, frames);
    let f = &run.figures;
    println!(
        "{name} {}: {frames} frames, broad phase {:.4} ms a frame, step {:.4} ms, {} pairs, \
         {} movers, {} statics, x-overlaps per body {:.2}, {} bytes",
        kind.name(),
        f.broad_ms,
        f.step_ms,
        f.pairs,
        run.movers,
        run.statics,
        run.overlaps,
        f.bytes.unwrap_or(0),
    );
}
