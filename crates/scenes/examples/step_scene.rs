//! Steps one built-in bench scene alone (no other engine in the process) and prints the
//! median time per frame and the process's memory: the harness behind the profiles in
//! BENCHMARKS.md. Run it under `perf record -e cpu-clock` to see where the time goes.
//!
//! ```console
//! $ cargo run --release -p ricochet-scenes --example step_scene -- rain-10000 300 2
//! rain-10000: 300 frames, 2 threads: median 1.012 ms a frame; VmRSS 13 MB, VmHWM 13 MB
//! ```
//!
//! Arguments: the scene (`asteroids-N`, `platformer-T-A`, `rain-N`), the frames to time
//! after frame 0 (default 300), the threads (default 1). A figure, never an assertion.

use std::time::Instant;

use ricochet_scenes::bench::Scene;
use ricochet_sim::Simulation;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: step_scene SCENE [FRAMES] [THREADS]";
    let Some(name) = args.get(1) else {
        eprintln!("{usage}");
        std::process::exit(2);
    };
    let number = |k: usize, default: u64| {
        args.get(k)
            .map_or(Ok(default), |s| s.parse::<u64>())
            .unwrap_or_else(|_| {
                eprintln!("{usage}");
                std::process::exit(2);
            })
    };
    let (frames, threads) = (number(2, 300).max(1), number(3, 1));
    let scene = Scene::parse(name).unwrap_or_else(|e| {
        eprintln!("error: {e}");
        std::process::exit(2);
    });
    let mut sim = Simulation::from_scenario(scene.build(frames + 1));
    sim.set_threads(usize::try_from(threads).unwrap_or(1));
    drop(sim.step());
    let mut ms: Vec<f64> = (0..frames)
        .map(|_| {
            let t = Instant::now();
            drop(sim.step());
            t.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    ms.sort_by(f64::total_cmp);
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let mb = |field: &str| {
        status
            .lines()
            .find_map(|l| l.strip_prefix(field))
            .and_then(|v| {
                v.trim_start_matches(':')
                    .trim()
                    .trim_end_matches("kB")
                    .trim()
                    .parse::<f64>()
                    .ok()
            })
            .map_or_else(|| "n/a".to_owned(), |kb| format!("{:.0} MB", kb / 1024.0))
    };
    println!(
        "{name}: {frames} frames, {} threads: median {:.3} ms a frame; VmRSS {}, VmHWM {}",
        sim.threads(),
        ms[ms.len() / 2],
        mb("VmRSS"),
        mb("VmHWM")
    );
}
