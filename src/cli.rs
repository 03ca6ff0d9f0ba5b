//! The command line: every command, its arguments and the `--help` that teaches them (clap
//! derive). `main.rs` hands each command to its module.

use std::path::PathBuf;

use clap::{Parser, Subcommand};

use crate::{serve, suite, sweep};

/// Ricochet: a headless, deterministic 2D game-physics simulation server.
///
/// Write a scenario (a scene plus a script of inputs), run it, replay every frame in Foxglove,
/// and keep golden logs so any change in your game's physics fails a test.
///
/// Start here: `ricochet` (no arguments) runs the built-in Asteroids demo into asteroids.mcap;
/// open it in Foxglove (File > Open local file) with the layout in foxglove/ricochet-layout.json.
/// Then try `ricochet run scenarios/platformer.toml` and `ricochet check your-game.toml`.
#[derive(Parser, Debug)]
#[command(name = "ricochet", version, about)]
pub struct Cli {
    /// What to do. Without one, `ricochet` runs the built-in Asteroids demo (`ricochet run`).
    #[command(subcommand)]
    pub command: Option<Command>,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Run a scenario and write every frame to an MCAP log that Foxglove opens.
    ///
    /// With no scenario, runs the built-in Asteroids demo (scenarios/asteroids.toml, embedded)
    /// into asteroids.mcap. The log is protobuf (official Foxglove schemas for what Foxglove
    /// draws): /scene and /scene/static (foxglove.SceneUpdate: moving and static bodies, in
    /// the world frame, each message whole), /tf (foxglove.FrameTransforms: the `view` frame
    /// the layout's camera follows), /scene/contacts
    /// (contact normals), /bodies (exact states: keyframes, then what the integrator does not
    /// predict), /contacts, /stats (for the Plot panel) and /events (foxglove.Log).
    /// Ctrl-C (SIGINT), SIGTERM and SIGHUP stop the run and still leave a complete, indexed
    /// log. The log is written to a hidden temporary file next to OUT.mcap and renamed onto
    /// it when complete, so an existing OUT.mcap is replaced whole or not at all.
    ///
    /// Exit code: 0 success, 1 the run failed, 2 bad input (scenario or output path; the
    /// output can't be the scenario itself, `-`, or a device such as /dev/null).
    ///
    /// Example: ricochet run scenarios/platformer.toml -o platformer.mcap --frames 1200
    Run {
        /// The scenario file (TOML). Default: the built-in Asteroids demo.
        scenario: Option<PathBuf>,
        /// Where to write the log. Default: the scenario's file name with .mcap (asteroids.mcap).
        #[arg(short, long, value_name = "OUT.mcap")]
        output: Option<PathBuf>,
        /// Steps to run after frame 0 (the initial state). Default: the scenario's `frames`.
        #[arg(long, value_name = "N")]
        frames: Option<u64>,
        /// Also referee every frame with rapier2d, into a /validation channel, and print the
        /// summary table; exit code 1 on any unexplained difference.
        #[arg(long)]
        validate: bool,
        /// Record only these channels (comma-separated: scene, bodies, contacts, stats,
        /// events; scene is /scene, /scene/static, /tf and /scene/contacts). Default: all
        /// five. Without scene, Foxglove's 3D panel is empty but plots and the log panel
        /// work; `ricochet diff` needs /bodies to name a divergent body.
        #[arg(long, value_name = "LIST")]
        channels: Option<String>,
        /// Threads for the parallel stages (detect's narrow phase). Default: every core. The
        /// log is the same bytes with any count: only the time changes.
        #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..=256))]
        threads: Option<u16>,
        /// Draw the scene (/scene, /scene/static, /tf, /scene/contacts) in every frame. By
        /// default a drawing of N encoded bytes waits N / 12 KiB frames before the next:
        /// scenes of at most 256 bodies are drawn every frame anyway, 10,000
        /// asteroids about every 124th frame, so that recording keeps up with the simulation
        /// (drawing them every frame records at about 300 frames/s on 2 cores). /bodies,
        /// /contacts, /stats and /events are exact in every frame either way; in the viewer
        /// a time between two drawings shows the earlier one.
        #[arg(long)]
        draw_every_frame: bool,
    },
    /// Step a scenario in real time and stream it live to Foxglove over WebSocket.
    ///
    /// With no scenario, serves the built-in Asteroids demo. In Foxglove (or Lichtblick):
    /// Open connection, Foxglove WebSocket, ws://localhost:8765, then import the layout
    /// foxglove/ricochet-layout.json. The channels are the log's (see `run`), the same
    /// messages and schemas; a viewer that subscribes gets the last scene at once. Both
    /// subprotocols are accepted: foxglove.websocket.v1 (Lichtblick, @foxglove/ws-protocol)
    /// and foxglove.sdk.v1 (current Foxglove). A slow client loses messages (and is told),
    /// never the simulation or the recording; of /scene, /scene/static, /tf and
    /// /scene/contacts it gets the latest, not a backlog, and at most 2 MB/s of each (a
    /// 10,000-body /scene about once a second: a browser viewer draws every scene it is
    /// sent). Ctrl-C or SIGTERM stops, finishing --record.
    ///
    /// Bounds, whatever clients do: at most 64 clients, each with an 8 MiB queue (+1 MiB for
    /// answers), 256 advertised channels and 2,000 inputs a second of at most 4 KB; inputs
    /// within ±1e15 (one that would overflow the state is refused); 32 handshakes under way,
    /// 5 s each; 64 MiB of inputs kept for seeks back; /load reads a regular file below the
    /// server's directory of at most 16 MiB. A frame that still overflows pauses the session
    /// at its last good frame, the recording complete up to there.
    ///
    /// Rooms: ws://IP:PORT/rooms/NAME (NAME: 1 to 64 of A-Z a-z 0-9 _ -) is a room of its
    /// own, a fresh session of the scenario made on first connection, stepped in real time,
    /// closed 10 s after its last client left (see docs/protocol.md). At most 1,000 rooms,
    /// 64 clients a room and 1,000 in all; rooms step on a thread per core.
    ///
    /// Example: ricochet serve scenarios/platformer.toml --record session.mcap
    Serve {
        /// The scenario file (TOML). Default: the built-in Asteroids demo.
        scenario: Option<PathBuf>,
        /// Address to listen on. A non-loopback address prints a warning: the protocol has
        /// no authentication.
        #[arg(long, default_value = serve::DEFAULT_BIND, value_name = "IP:PORT")]
        bind: String,
        /// Simulation seconds per wall-clock second, 0.01 to 100 (as /speed).
        #[arg(long, default_value_t = 1.0, value_name = "X")]
        speed: f64,
        /// Stop after this many frames after frame 0 (default: run until stopped). No /step
        /// or seek goes past frame N either (without it: 100,000,000, the most a log holds).
        #[arg(long, value_name = "N")]
        frames: Option<u64>,
        /// Also record the session to this MCAP file, as `run` writes one. Disk: each file
        /// holds one session, at most frames 0 to --frames; a seek back writes it again (it
        /// adds no file); /reset and /load start a new one, OUT-1.mcap, ... (at most 1,000).
        #[arg(long, value_name = "OUT.mcap")]
        record: Option<PathBuf>,
        /// Record each room (ws://IP:PORT/rooms/NAME) to DIR/NAME.mcap (NAME-1.mcap, ... for
        /// a name recorded before: no file is replaced), finished when the room closes.
        #[arg(long, value_name = "DIR")]
        record_rooms: Option<PathBuf>,
        /// Start paused: frame 0 is shown; the /play or /step service goes on (the plain URL;
        /// rooms always run).
        #[arg(long)]
        paused: bool,
    },
    /// Step a session recorded by `serve --record` again, from the scenario and the inputs
    /// it carries, into a new log; exit code 0 if it is byte-identical to the recording.
    ///
    /// Example: ricochet replay session.mcap -o replayed.mcap
    Replay {
        /// The recorded session.
        session: PathBuf,
        /// Where to write the replay. Default: SESSION.replay.mcap.
        #[arg(short, long, value_name = "OUT.mcap")]
        output: Option<PathBuf>,
    },
    /// Print a log as JSON lines, one message a line, for scripts and grep.
    ///
    /// Each line is {"topic", "sequence", "log_time", "publish_time", "data"}, like
    /// `mcap cat --json`; `data` is the message as recorded. Memory does not grow with the
    /// log. Exit code 2 when the log is unreadable, damaged, or has no such topic.
    ///
    /// Example: ricochet dump recordings/asteroids.mcap --topic /contacts --frames 40..60
    Dump {
        /// The log (MCAP written by `ricochet run`).
        log: PathBuf,
        /// Only this topic (/bodies, /contacts, /stats, /events, /scene).
        #[arg(long, value_name = "T")]
        topic: Option<String>,
        /// Only these frames: `A..B` (inclusive), `A..`, `..B` or `N`.
        #[arg(long, value_name = "A..B")]
        frames: Option<String>,
    },
    /// Referee a scenario with rapier2d: same shapes, same poses, same motion.
    ///
    /// Every logged contact is recomputed by rapier's geometry (parry) at the poses Ricochet
    /// detected it with; the set of pairs in the full pass is compared with rapier's broad
    /// and narrow phase; swept hits are cast along the frame's motion; free flight is
    /// compared with rapier's integrator. Differences that are legitimate (static pairs
    /// Ricochet never tests, boxes owned by the per-axis passes, bodies pushed earlier in a
    /// pass, touching within tolerance, ...) are counted per named rule, see
    /// docs/validation.md. Exit code 1 on any difference no rule explains.
    ///
    /// Example: ricochet validate scenarios/validation.toml
    Validate {
        /// The scenario file (TOML).
        scenario: PathBuf,
        /// Steps after frame 0. Default: the scenario's `frames`.
        #[arg(long, value_name = "N")]
        frames: Option<u64>,
    },
    /// Compare two logs frame by frame and name the first difference.
    ///
    /// Messages are compared one by one, so compression and chunking don't matter: equal
    /// bytes under the same schema are equal (schemas are compared and checked once per
    /// channel, each message's top level is checked), messages that differ are decoded and
    /// compared field by field. Prints the first divergent frame, topic, body and field with
    /// both values as soon as it is found, then, when both logs have been read, how many
    /// messages differ per topic (a log found damaged after the first difference is still an
    /// error, exit code 2). Both logs are streamed, each read on a thread of its own, so
    /// memory does not grow with their length. Exit code: 0 equal (within --tolerance), 1 they differ, 2 they
    /// can't be compared: a file is unreadable, truncated or damaged (chunk, data or summary
    /// CRC), not a Ricochet log, or --topic names a topic neither log has.
    ///
    /// Example: ricochet diff recordings/asteroids.mcap asteroids.mcap --topic /bodies
    Diff {
        /// The reference log (for example the golden recording).
        a: PathBuf,
        /// The log to compare with it.
        b: PathBuf,
        /// Numbers within this absolute difference count as equal (default: exact).
        #[arg(long, default_value_t = 0.0, value_name = "X")]
        tolerance: f64,
        /// Compare only this topic (/bodies, /contacts, /stats, /events, /scene); one that
        /// neither log has is an error (exit code 2) listing those they have.
        #[arg(long, value_name = "T")]
        topic: Option<String>,
        /// Print the report as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Measure run time against error on scenes with exact answers, and draw the chart.
    ///
    /// Sweeps the timestep (1/30 s to 1/960 s) and substeps over: a projectile under gravity,
    /// a body on a spring, a circular orbit (energy drift over 10,000 frames), a ball dropping
    /// onto a floor (landing frame and rest height) and a bullet crossing a field of asteroids
    /// (the exact set of first hits, swept or not). Prints a table; writes a CSV and an SVG
    /// chart of error against wall time per simulated second, log scales.
    ///
    /// Example: ricochet accuracy --csv docs/accuracy.csv --svg docs/accuracy.svg
    Accuracy {
        /// Write the table as CSV here.
        #[arg(long, value_name = "FILE")]
        csv: Option<PathBuf>,
        /// Write the chart as SVG here.
        #[arg(long, value_name = "FILE")]
        svg: Option<PathBuf>,
    },
    /// Run time against error for your own scenario: run it with other values of its
    /// fields (the timestep, gravity, a speed, a collider's shape) and measure each run
    /// against a reference run.
    ///
    /// Every combination of the --set values runs. The reference is the file as written
    /// at the smallest dt swept (or what --reference says). For each run: the median step
    /// time, the final digest, each named moving body's position error at the times both
    /// runs reach (max and RMS; a run at dt = 1/30 is compared at every frame with a
    /// reference at 1/240, on every 8th of the reference's), the energy error and drift,
    /// the touch events that appear, vanish or move frames, and the pair-frames in contact
    /// in one run and not the other (false positive and false negative contacts: what a
    /// simpler collider costs). Prints a table and a one-line summary; writes a CSV and an
    /// SVG chart of error against wall time per simulated second, log scales.
    ///
    /// Each run is measured as it steps beside the reference (the reference runs again
    /// beside each combination), so memory does not grow with the frame count. At most
    /// 100,000 combinations (the product of the --set value counts): each is a run and
    /// a row kept for the table, CSV and chart; more is refused (exit code 2). A run that
    /// overflows (a non-finite state, as `run` stops at it, or a non-finite energy) is
    /// stopped and not measured: its row and the summary say at which frame.
    ///
    /// --csv and --svg must be two different regular files (not a device, not the
    /// scenario); both are written, or neither.
    ///
    /// Exit code: 0 done, 1 a run or the reference overflowed (the measured rows are still
    /// written, unless the reference overflowed) or a file could not be written, 2 bad
    /// input (a key or value the scenario file refuses is reported by the loader,
    /// FILE:LINE:COLUMN; too many combinations; an output that is a device, named twice or
    /// the scenario).
    ///
    /// Examples:
    ///   ricochet sweep scenarios/platformer.toml --set world.dt=1/30,1/60,1/120,1/240
    ///   ricochet sweep scenarios/asteroids.toml --set 'bodies.ship.shape=file,circle:1.2,polygon:1 0;-1 1;-1 -1'
    #[command(verbatim_doc_comment)]
    Sweep(sweep::Args),
    /// Time Ricochet's full step against rapier2d's collision-only pipeline and Box2D v3 on
    /// built-in scenes.
    ///
    /// Scenes: asteroids-N (N asteroids, 100 swept bullets, a ship), platformer-T-A (T static
    /// tiles, A actors), rain-N (N mixed shapes falling through static geometry); each count
    /// from 1 to 1000000 (a million bodies take about 1.6 GB in the three engines). All three
    /// engines run in one process on the same frames and poses. Columns: Ricochet's and
    /// rapier's median and p95 time per frame and their ratio (rapier / ricochet), whether
    /// rapier's contact set agrees, memory (ricochet after its setup, peak at the end), Ricochet
    /// alone with 1 thread and with 2 ("alone 2t": the parallel stages; every ratio is 1 thread
    /// against 1); then Box2D: "box2d collide" (broad + narrow phase, pairs + collide from its own
    /// profile), "box2d step" (its whole b2World_Step, solver included), "box2d sync" (copying
    /// the changed poses in with b2Body_SetTransform, which moves broad-phase proxies), "b2
    /// ratio" (box2d collide / ricochet) and "box2d agree" (end-of-frame contact pairs
    /// agreed/compared).
    /// Box2D's bodies are dynamic with every motion locked, teleported to Ricochet's poses
    /// (ricochet-box2d's docs say why). Exit code 1 if any contact set disagrees with either
    /// engine. Timings are figures, never assertions.
    ///
    /// Example: ricochet bench asteroids-10000 platformer-10000-1000 --frames 50 --csv bench.csv
    Bench {
        /// Scenes to run (default: a small set).
        scenes: Vec<String>,
        /// Frames per scene after frame 0 (at most 1000000: every frame's timings, or with --record its log, are kept).
        #[arg(long, default_value_t = 100, value_name = "N")]
        frames: u64,
        /// Write the results as CSV here.
        #[arg(long, value_name = "FILE")]
        csv: Option<PathBuf>,
        /// Measure the log instead: run each scene alone, then recorded with every channel
        /// as `ricochet run` records it; print frames/s both ways and the log's bytes per
        /// moving body per frame. Default scene: asteroids-10000.
        #[arg(long)]
        record: bool,
        /// With --record: keep the logs in this directory (NAME.mcap; created if missing).
        #[arg(long, value_name = "DIR", requires = "record")]
        keep: Option<PathBuf>,
        /// With --record: draw the scene in every frame (`ricochet run --draw-every-frame`)
        /// instead of at the drawing's pace, to measure what the pace saves.
        #[arg(long, requires = "record")]
        draw_every_frame: bool,
        /// Measure the scene queries instead: after --frames frames, the same 2000 seeded rays
        /// (20 units, from outside every body) and 2000 boxes (about a body's size) asked of
        /// Ricochet (cast_ray, overlap_aabb), rapier's QueryPipeline and Box2D
        /// (b2World_CastRayClosest, b2World_OverlapShape, b2World_OverlapAABB), in one
        /// process; prints rays/s and overlaps/s, the hits, and how many answers differ from
        /// Ricochet's. Exit code 1 if any does.
        #[arg(long, conflicts_with_all = ["record", "csv"])]
        queries: bool,
        /// Measure snapshots instead (issue #22): each scene (default asteroids-75 and
        /// asteroids-10000) stepped --frames frames, snapshotted, stepped 8 more; then the
        /// bytes per moving body, and the median of 21 passes of snapshot, to_bytes,
        /// from_bytes, restore (the 8 frames back, onto the same bodies), their sum,
        /// checksum and a Simulation clone, in microseconds. Build with --release.
        ///
        /// Example: ricochet bench --snapshots asteroids-75 asteroids-10000 --frames 300
        #[arg(long, conflicts_with_all = ["record", "csv", "queries"])]
        snapshots: bool,
        /// Measure every broad phase instead, to choose `[world] broad_phase` for a scene:
        /// each scene (default: every bench scene and crowded-10000, sparse-10000,
        /// mixed-10000: one layer packed, spread out, or of mixed sizes) stepped --frames
        /// frames with each broad phase forced; prints the broad phase alone and the whole
        /// step in ms per frame, the structures' memory, the pairs per frame, what `auto`
        /// picks and how far it is from the fastest. Brute force is skipped above 4000
        /// bodies. Build with --release.
        ///
        /// Example: ricochet bench --broad-phases mixed-10000 --frames 60
        #[arg(long, conflicts_with_all = ["record", "csv", "queries", "snapshots"])]
        broad_phases: bool,
    },
    /// Run a folder of scenarios against their golden logs: any change in your game's
    /// physics fails, with its first divergence named.
    ///
    /// Each scenario (a file, or every *.toml at the top of a folder; default: scenarios/)
    /// is recorded as `ricochet run` records it and compared with its golden log
    /// GOLDEN/NAME.mcap and digest GOLDEN/NAME.digest (frames, bodies, and a hash of the
    /// final state). One line per scenario, sorted by name: `ok`, `differs: frame 185,
    /// /contacts, pair 6:0/9:0, depth 0.031 → 0.029` (the first divergence, as `ricochet
    /// diff` finds it), or `no golden (run with --bless)`; then `N passed, M failed`. The
    /// output is the same bytes whatever -j or --shard. Each scenario runs in its own
    /// process, -j at a time. Ctrl-C (or SIGTERM) stops: no more are started, the running
    /// ones stop at their next frame (one still running 5 s later, blocked or stopped, is
    /// killed), and no golden is left half-written. A scenario file is a regular file of at
    /// most 16 MiB (16777216 bytes, as serve's /load); a larger one is a failed line.
    ///
    /// Exit code: 0 all passed, 1 any failed (a scenario that does not load is a failed
    /// line), 2 bad input (no such path, a named path that is a FIFO or a device, a folder
    /// without scenarios, two scenarios sharing a golden, a bad --shard, a --keep folder
    /// that is a golden folder), 130 interrupted.
    #[command(after_help = "\
Examples:
  ricochet test                           every scenarios/*.toml against recordings/
  ricochet test levels --golden goldens   your folders
  ricochet test scenarios/platformer.toml one scenario
  ricochet test --bless                   write the goldens, saying which changed
  ricochet test --junit report.xml        also a JUnit report for CI
  ricochet test --shard 0/4               the first of 4 slices (a job array's task)
  ricochet test --keep fresh              keep the fresh logs, then:
  ricochet diff recordings/level.mcap fresh/level.mcap
  ricochet test --cluster tcp://127.0.0.1:8786 --verify   on a Dask cluster

See docs/suites.md: the result line of one item, Slurm and Kubernetes examples.")]
    Test {
        /// Scenario files or folders (the *.toml at a folder's top level). Default:
        /// scenarios/.
        #[arg(conflicts_with = "item")]
        paths: Vec<PathBuf>,
        /// The folder of golden logs and digests. Default: recordings/ beside each
        /// scenario's folder (game/scenarios/a.toml: game/recordings/a.mcap).
        #[arg(long, value_name = "DIR")]
        golden: Option<PathBuf>,
        /// Scenarios run at once, each in its own process. Default: the number of cores.
        /// At most as many as the open-file limit (ulimit -n) has room for, 2 descriptors
        /// each with 16 kept free (a limit of 64 allows about 20); the others wait for a slot.
        #[arg(short, long, value_name = "N", conflicts_with = "item",
              value_parser = clap::value_parser!(u16).range(1..=256))]
        jobs: Option<u16>,
        /// Write the goldens (log and digest, each through a temporary file renamed into
        /// place) instead of comparing; each line says `blessed (new)`, `blessed
        /// (changed)` or `unchanged`.
        #[arg(long)]
        bless: bool,
        /// Also write the results as JUnit XML here (one testcase per scenario). Refused
        /// before any scenario runs (exit code 2) if it is a directory, a device, or one of
        /// the run's scenarios, golden logs or digests.
        #[arg(long, value_name = "FILE", conflicts_with = "item")]
        junit: Option<PathBuf>,
        /// Run only the K-th (from 0) of N slices of the sorted scenarios: items K, K+N,
        /// K+2N, ... The N shards together are the whole suite, each scenario once.
        #[arg(long, value_name = "K/N", conflicts_with = "item")]
        shard: Option<suite::shard::Shard>,
        /// Keep the fresh logs in this folder, as NAME.mcap (created if missing), once
        /// compared. Refused (exit code 2) when it is, or resolves to, a golden folder, or
        /// when two scenarios have one name.
        #[arg(long, value_name = "DIR", conflicts_with = "item")]
        keep: Option<PathBuf>,
        /// Run the scenarios on this Dask distributed cluster's workers (tcp://HOST:PORT
        /// of its scheduler) instead of local processes; needs `pip install ./python`
        /// (docs/suites.md). Nothing there, or no Dask scheduler answering within 10 s (a
        /// port that accepts and stays silent, or speaks another protocol), is an error
        /// before any item, exit code 2.
        #[arg(long, value_name = "tcp://HOST:PORT", conflicts_with = "item")]
        cluster: Option<String>,
        /// With --cluster: re-run one item in ten on a second worker and fail any whose
        /// digests differ, naming both workers.
        #[arg(long, requires = "cluster")]
        verify: bool,
        /// With --cluster and --keep: copy each fresh log's bytes back from its worker into
        /// the --keep folder, for workers that don't share a filesystem with this machine.
        /// Without it, a worker keeps the log at the --keep path on its own filesystem.
        #[arg(long, requires_all = ["cluster", "keep"])]
        fetch_logs: bool,
        /// Run one scenario and print its result as one JSON line (docs/suites.md): what
        /// each of the runner's processes, or a cluster worker, runs.
        #[arg(long, value_name = "SCENARIO", hide = true)]
        item: Option<PathBuf>,
        /// With --item: keep the fresh log in this folder, as NAME.mcap.
        #[arg(long, value_name = "DIR", hide = true, requires = "item")]
        out: Option<PathBuf>,
    },
    /// Check a scenario file without running it: syntax, units, layers, templates, script.
    ///
    /// Errors are printed as FILE:LINE:COLUMN: FIELD: PROBLEM, with exit code 2.
    Check {
        /// The scenario file (TOML).
        scenario: PathBuf,
    },
    /// Collide shape pairs and print one JSON line per pair: "why did these two collide?"
    ///
    /// Reads the shared collision-case format: a {"cases": [...]} document, or JSON lines of
    /// {"id": .., "a": BODY, "b": BODY}, where BODY is
    /// {"shape": SHAPE, "position": [x, y], "angle": radians} and SHAPE is one of
    /// circle {radius}, aabb {half_extents}, obb {half_extents}, capsule {a, b, radius},
    /// polygon {vertices} (convex, counter-clockwise) or compound {parts}.
    ///
    /// Prints {"id", "overlap", "depth", "normal", "point"} per pair. depth > 0 is the
    /// penetration; depth <= 0 is minus the distance. The normal points from a to b: moving
    /// b by depth * normal separates the pair. Bad input (an unknown key, a key given twice,
    /// a wrong type) is reported by case id, line and field, with exit code 2, and nothing
    /// is printed to stdout. The input is streamed: at most 4 MiB a case, ids of at most 256
    /// bytes, compounds of at most 1024 parts; the first 20 errors are printed, then a count.
    ///
    /// Example: ricochet collide tests/data/collision-cases.json | head -3
    Collide {
        /// The case file, or `-` for standard input.
        file: PathBuf,
    },
}
