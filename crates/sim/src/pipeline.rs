//! The simulation: a world, its scenario, and the fixed stage order.
//!
//! Frame 0 is the initial state: its script events run, contacts are detected and the
//! touching pairs begin, but nothing moves. Every later frame runs every stage in this
//! order, skipping a stage the scene has nothing for (and counting the skip in
//! [`crate::Stats`]):
//!
//! | stage | does |
//! |---|---|
//! | `script` | this frame's script events: inputs, spawns, destroys, velocity/force edits; then the inputs sent with `apply`, and the kinematic bodies' target poses |
//! | `cull` | freeze the moving bodies outside the active region, thaw those inside it |
//! | `unground` | clear `grounded`: it is set again below by whatever holds a body up |
//! | `controls` | controllers turn inputs into angular velocity (ship) or x velocity (runner, walker) |
//! | `forces` | semi-implicit Euler, velocity half: `a = sum(f) / m`, `v += a * dt` |
//! | `move_x` | a rider first moves by its carrier's `vx * dt`; then `x += vx * dt` for every moving body |
//! | `resolve_x` | per-axis separation along x (boxes in `separate` layer pairs); `crushed` when a kinematic body left a box no room |
//! | `move_y` | a rider first moves by its carrier's `vy * dt`; then `y += vy * dt` |
//! | `resolve_y` | per-axis separation along y; a push upwards sets `grounded` and the carrier a box rides next frame; `crushed` as along x |
//! | `turn` | `angle += angular_velocity * dt` |
//! | (`one_way`) | only with a `one_way` layer pair, and not a counted stage (the stats' stage list is in every log): lands the bodies that came down onto a one-way platform (`stages/one_way.rs`) |
//! | `detect` | broad phase, exact narrow phase, `report`/`destroy`/`separate` responses (a runner or walker on a slope: `stages/slope.rs`) |
//! | (`snap`) | only in a scene with a static body that is not an axis-aligned box, and not a counted stage: a runner or walker grounded at the end of the last frame (noted before `unground`) and in the air now is snapped down onto a slope (`stages/slope.rs`) |
//! | `lifetimes` | count down lifetimes; remove expired bodies |
//! | `bounds` | wrap around (Asteroids) or remove bodies that left the world |
//! | `sleep` | count the frames each dynamic body rested; put to sleep those that rested long enough |
//! | `touch` | the pairs touching at the end of the frame; `touch_begin` / `touch_end` events for the pairs that started or stopped (`docs/touches.md`) |
//!
//! The motion stages visit only the *active* bodies ([`World::active`]): moving, not frozen,
//! not asleep. Static bodies are never visited after they are indexed. In a scene without
//! per-axis layer pairs (`resolve_x` and `resolve_y` never have work), `move_x`, `move_y`
//! and `turn` are one pass over the active bodies (`Simulation::run_motion`): each body's
//! arithmetic is the same, so the result is the same bits, and each stage is still counted
//! as run or skipped on its own.
//!
//! Riders (`stages/carry.rs`): a dynamic box that a kinematic box (or a box riding one)
//! held up in the last `resolve_y` is carried by that kinematic body's `v * dt` in `move_x`
//! and `move_y`, before its own motion, so it keeps its place on a moving platform; a
//! kinematic box moving into a dynamic one pushes it in the per-axis passes.

use ricochet_geom::{Pose, Vec2};

use crate::action::{Action, Event};
use crate::entity::Entity;
use crate::output::FrameOutput;
use crate::parallel::Workers;
use crate::scenario::Scenario;
use crate::stage_set::Stage;
use crate::stages::detect::DetectState;
use crate::stages::one_way::{self, OneWayState};
use crate::stages::separate::SeparateState;
use crate::stages::slope::SlopeState;
use crate::stages::touch::TouchState;
use crate::stages::{
    StageCtx, bounds, cull, detect, lifetimes, motion, script, separate, sleep, touch,
};
use crate::world::World;

/// The stages frame 0 runs: the initial state is scripted and checked, never moved. Lifetimes
/// count frame 0, so a body lives `lifetime` frames whether it starts there or is spawned
/// later; bodies overlapping at the start begin touching at frame 0.
const FRAME_ZERO: [Stage; 5] = [
    Stage::Script,
    Stage::Cull,
    Stage::Detect,
    Stage::Lifetimes,
    Stage::Touch,
];

/// The stages [`Simulation::run_motion`] runs in one pass, in their order.
const MOTION: [Stage; 5] = [
    Stage::MoveX,
    Stage::ResolveX,
    Stage::MoveY,
    Stage::ResolveY,
    Stage::Turn,
];

/// A running simulation.
#[derive(Clone)]
pub struct Simulation {
    /// The scenario it runs (its bodies moved into the world).
    pub(crate) scenario: Scenario,
    /// The bodies.
    pub(crate) world: World,
    /// The next frame to run.
    pub(crate) frame: u64,
    /// Index of the next script event.
    pub(crate) cursor: usize,
    /// Whether each frame reports every body's pose at the start of `detect`
    /// ([`FrameOutput::detect_poses`]). Off by default: it costs a copy per frame.
    pub capture_detect_poses: bool,
    /// Actions sent with [`Simulation::apply`], applied at the start of the next step.
    pub(crate) pending: Vec<(Entity, Action)>,
    /// Target poses of kinematic bodies ([`Simulation::set_target_pose`]), by entity, for
    /// the next moving step.
    pub(crate) targets: Vec<(Entity, Pose)>,
    /// The bodies the last moving step moved to a target, by entity: stopped at the next
    /// one unless given a new target.
    pub(crate) targeted: Vec<Entity>,
    /// The body the active region follows, once found.
    pub(crate) focus: Option<crate::Entity>,
    /// The broad phase and buffers of `detect` (given to it each frame).
    pub(crate) detect: DetectState,
    /// The obstacle grids of `resolve_x` and `resolve_y`.
    pub(crate) separate: SeparateState,
    /// The one-way platforms' pass (`stages/one_way.rs`).
    pub(crate) one_way: OneWayState,
    /// The pairs touching at the end of the last frame (`touch`).
    pub(crate) touch: TouchState,
    /// The snap of controlled bodies to sloped ground (`stages/slope.rs`).
    pub(crate) slopes: SlopeState,
    /// The threads of the parallel stages (`parallel.rs`); one by default.
    pub(crate) workers: Workers,
    /// The scene queries' trees (`query/index.rs`): built by the first query after a
    /// change, dropped by every method that moves, adds, removes or reshapes a body.
    pub(crate) queries: crate::query::cache::QueryCache,
    /// The world before the first step, that snapshots are written against (`snapshot/`).
    pub(crate) baseline: std::sync::Arc<crate::snapshot::Baseline>,
    /// The last frames kept for [`Simulation::past`] (`history.rs`); off by default.
    pub(crate) history: crate::history::History,
}

/// A summary, not every body (`{:?}` of a 10,000-body world would be megabytes): the
/// scenario's name, the next frame, the body counts, what waits for the next step.
impl std::fmt::Debug for Simulation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let w = &self.world;
        f.debug_struct("Simulation")
            .field("scenario", &self.scenario.name)
            .field("frame", &self.frame)
            .field("dt", &self.scenario.world.dt)
            .field("bodies", &w.len())
            .field("moving", &w.movers().len())
            .field("active", &w.active().len())
            .field("sleeping", &w.sleeping())
            .field("templates", &self.scenario.templates.len())
            .field(
                "script_events_left",
                &(self.scenario.script.len() - self.cursor),
            )
            .field("pending", &self.pending)
            .field("targets", &self.targets)
            .field("touching", &self.touch.touching().len())
            .field("focus", &self.focus)
            .field("threads", &self.threads())
            .field("kept_frames", &self.kept_frames())
            .finish_non_exhaustive()
    }
}

impl Simulation {
    /// A simulation at the start of frame 0, with the scenario's bodies spawned in file order
    /// and its script sorted by frame (stably). The scenario is trusted as given: a scene
    /// built in code is checked as a file is by [`Simulation::try_new`] (or
    /// [`Scenario::check`]); unchecked, a script naming no body is only a `missed` event at
    /// its frame.
    #[must_use]
    pub fn new(scenario: &Scenario) -> Simulation {
        let mut world = World::new();
        world.reserve(scenario.body_count());
        for t in &scenario.tiles {
            world.spawn_tiles(t, |_| {});
        }
        for b in &scenario.bodies {
            world.spawn(b);
        }
        // The bodies live in the world; the simulation's copy of the scenario keeps the rest.
        let rest = Scenario {
            name: scenario.name.clone(),
            world: scenario.world.clone(),
            frames: scenario.frames,
            templates: scenario.templates.clone(),
            tiles: Vec::new(),
            bodies: Vec::new(),
            script: scenario.script.clone(),
        };
        Simulation::with_world(rest, world)
    }

    /// A simulation of `scenario` that takes its bodies instead of copying them: for large
    /// scenes, where a second copy of every body would double the memory. Like
    /// [`Simulation::new`], it sorts the script and checks nothing ([`Scenario::check`]
    /// does).
    #[must_use]
    pub fn from_scenario(mut scenario: Scenario) -> Simulation {
        let mut world = World::new();
        world.reserve(scenario.body_count());
        for t in std::mem::take(&mut scenario.tiles) {
            world.spawn_tiles(&t, |_| {});
        }
        let mut bodies = std::mem::take(&mut scenario.bodies);
        // Spawned in file order from the back of the reversed list, whose memory is given
        // back every few thousand bodies: the peak is the world plus a little, not the
        // world plus every definition.
        bodies.reverse();
        while let Some(b) = bodies.pop() {
            world.spawn(&b);
            if bodies.len().is_multiple_of(4096) {
                bodies.shrink_to_fit();
            }
        }
        Simulation::with_world(scenario, world)
    }

    /// A simulation of `scenario` with its bodies already in `world`. The script is sorted
    /// by frame, stably (events of one frame keep their order): the `script` stage reads it
    /// in order, so an event listed after a later frame's would otherwise never run
    /// (issue #35). A loaded scenario's script is sorted the same way already.
    fn with_world(mut scenario: Scenario, world: World) -> Simulation {
        scenario.script.sort_by_key(|e| e.frame);
        let baseline = crate::snapshot::Baseline::new(&world);
        let layers = &scenario.world.layers;
        Simulation {
            detect: DetectState::new(layers, scenario.world.broad_phase),
            separate: SeparateState::new(layers),
            one_way: OneWayState::new(layers),
            touch: TouchState::new(layers),
            slopes: SlopeState::default(),
            scenario,
            world,
            frame: 0,
            cursor: 0,
            capture_detect_poses: false,
            pending: Vec::new(),
            targets: Vec::new(),
            targeted: Vec::new(),
            focus: None,
            workers: Workers::default(),
            queries: crate::query::cache::QueryCache::default(),
            baseline,
            history: crate::history::History::default(),
        }
    }

    /// Runs the parallel stages on `threads` threads in all (0 or 1: the calling thread
    /// only, the default). The thread count changes the time a step takes, never its
    /// result: every log is the same bytes with any count. Without the crate's `parallel`
    /// feature (on by default) there is only the calling thread, whatever `threads` says.
    pub fn set_threads(&mut self, threads: usize) {
        if threads != self.threads() {
            self.workers = Workers::new(threads);
        }
    }

    /// The threads the parallel stages use (1: the calling thread only).
    #[must_use]
    pub fn threads(&self) -> usize {
        self.workers.threads()
    }

    /// The bodies, to read: a write goes through the simulation's methods
    /// ([`Simulation::set_position`], [`Simulation::apply`], ...), which keep the broad
    /// phase's and the sleep stage's caches right.
    #[must_use]
    pub fn world(&self) -> &World {
        &self.world
    }

    /// The scenario it runs: world settings, templates and script (its bodies are in the
    /// world). Read-only: the stages' state is built from it once.
    #[must_use]
    pub fn scenario(&self) -> &Scenario {
        &self.scenario
    }

    /// The body the active region follows (its focus), once a step has found it alive.
    #[must_use]
    pub fn focus(&self) -> Option<Entity> {
        self.focus
    }

    /// The frame the next [`step`](Self::step) will run.
    #[must_use]
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// The pairs of bodies touching at the end of the last frame, sorted by `(a, b)` with
    /// `a < b` (`docs/touches.md`): what every [`crate::GameEvent::TouchBegin`] so far
    /// without its [`crate::GameEvent::TouchEnd`] names. Empty before frame 0 has run.
    #[must_use]
    pub fn touching(&self) -> &[(Entity, Entity)] {
        self.touch.touching()
    }

    /// Seconds per step.
    #[must_use]
    pub fn dt(&self) -> f64 {
        self.scenario.world.dt
    }

    /// The script events due at the current frame.
    fn due_events(&self) -> &[Event] {
        let rest = &self.scenario.script[self.cursor..];
        let n = rest.iter().take_while(|e| e.frame == self.frame).count();
        &rest[..n]
    }

    /// Whether the scene has anything for `stage` to do this frame, given what the frame
    /// produced so far.
    fn has_work(&self, stage: Stage, out: &FrameOutput) -> bool {
        let (w, def) = (&self.world, &self.scenario.world);
        match stage {
            Stage::Script => {
                !self.due_events().is_empty()
                    || !self.pending.is_empty()
                    || (self.frame > 0 && !(self.targets.is_empty() && self.targeted.is_empty()))
            }
            Stage::Cull => cull::has_work(def),
            Stage::Unground => motion::has_grounded(w),
            Stage::Controls => motion::has_controls(w),
            Stage::Forces => motion::has_forces(w, def),
            Stage::MoveX | Stage::MoveY => motion::has_motion(w),
            Stage::ResolveX | Stage::ResolveY => separate::has_work(w, &self.separate),
            Stage::Turn => motion::has_turning(w),
            Stage::Detect => detect::has_work(w, def),
            Stage::Lifetimes => lifetimes::has_work(w),
            Stage::Bounds => bounds::has_work(def),
            Stage::Sleep => sleep::has_work(def),
            Stage::Touch => touch::has_work(&self.touch, out),
        }
    }

    /// Runs `stage`, handing it what it works on and the state it keeps.
    fn run(&mut self, stage: Stage, out: &mut FrameOutput) {
        let dt = self.scenario.world.dt;
        let due = self.due_events().len();
        let carries = self.carries();
        let mut ctx = StageCtx {
            world: &mut self.world,
            def: &self.scenario.world,
            templates: &self.scenario.templates,
            out,
        };
        match stage {
            Stage::Script => {
                let events = &self.scenario.script[self.cursor..self.cursor + due];
                self.cursor += due;
                script::run(&mut ctx, events, &self.pending);
                self.pending.clear();
                if self.frame > 0 {
                    script::move_to_targets(ctx.world, dt, &mut self.targets, &mut self.targeted);
                }
            }
            Stage::Cull => cull::run(&mut ctx, &mut self.focus),
            Stage::Unground => motion::unground(ctx.world),
            Stage::Controls => motion::controls(ctx.world),
            Stage::Forces => motion::forces(ctx.world, ctx.def),
            Stage::MoveX => motion::move_x(ctx.world, dt, carries),
            Stage::ResolveX => separate::resolve_x(&mut ctx, &mut self.separate, &self.slopes),
            Stage::MoveY => motion::move_y(ctx.world, dt, carries),
            Stage::ResolveY => separate::resolve_y(&mut ctx, &mut self.separate),
            Stage::Turn => motion::turn(ctx.world, dt),
            Stage::Detect => detect::run(
                &mut ctx,
                &mut self.detect,
                self.capture_detect_poses,
                &self.workers,
            ),
            Stage::Lifetimes => lifetimes::run(&mut ctx),
            Stage::Bounds => bounds::run(&mut ctx),
            Stage::Sleep => sleep::run(&mut ctx),
            Stage::Touch => touch::run(&mut ctx, &mut self.touch),
        }
    }

    /// `move_x`, `resolve_x`, `move_y`, `resolve_y` and `turn` of a scene without per-axis
    /// layer pairs, where neither `resolve` stage has work and no body has a carrier: the
    /// three motion stages in one pass over the active bodies ([`World::integrate`]), each
    /// part run, and counted as run or skipped, exactly when its own stage would be.
    /// Moving changes no velocity and no body's activity, so each stage's `has_work` gives
    /// the same answer here as in its turn. True when all three parts ran: the usual pass,
    /// which moves every active body as a reader predicts ([`crate::Disturbed`]).
    fn run_motion(&mut self, out: &mut FrameOutput) -> bool {
        let mut run = [false; MOTION.len()];
        for (r, &stage) in run.iter_mut().zip(&MOTION) {
            *r = self.has_work(stage, out);
            if *r {
                out.stats.stages_run.insert(stage);
            } else {
                out.stats.stages_skipped.insert(stage);
            }
        }
        let [x, resolve_x, y, resolve_y, turn] = run;
        debug_assert!(!resolve_x && !resolve_y, "no per-axis pairs, no resolve");
        if x || y || turn {
            self.world.integrate(self.scenario.world.dt, x, y, turn);
        }
        x && y && turn
    }

    /// Whether a body may ride a carrier: a per-axis (`separate`) pair of boxes, or a
    /// `one_way` pair (a kinematic platform carries).
    fn carries(&self) -> bool {
        self.separate.carries() || self.one_way.any()
    }

    /// Runs one frame and reports what happened.
    pub fn step(&mut self) -> FrameOutput {
        self.world.begin_step();
        if self.frame == 0 || self.carries() || self.scenario.world.gravity != Vec2::ZERO {
            // No usual pass (frame 0 moves nothing; a per-axis scene moves box by box), or
            // nearly every body's velocity changes: every body named now, so the stages'
            // own names cost a branch.
            self.world.disturb_all();
        }
        self.queries.invalidate(&self.world);
        let mut out = FrameOutput {
            frame: self.frame,
            ..FrameOutput::default()
        };
        // Swept tests run from here to wherever the frame's motion ends. Static bodies never
        // move, so only the moving ones need it.
        let w = &mut self.world;
        w.start_frame();
        let mut fused = false;
        // Whether the usual integration ran (see [`crate::Disturbed`]): if not, every body
        // is named as disturbed.
        let mut usual = false;
        for stage in Stage::ALL {
            let allowed = self.frame > 0 || FRAME_ZERO.contains(&stage);
            if fused && MOTION.contains(&stage) {
                // Run (or skipped) with `move_x`.
                continue;
            }
            if stage == Stage::Detect
                && self.frame > 0
                && one_way::has_work(&self.world, &self.one_way)
            {
                // The one-way platforms' pass: not a counted stage (the stage list is in
                // every log's stats), run only in a scene with a `one_way` pair.
                let mut ctx = StageCtx {
                    world: &mut self.world,
                    def: &self.scenario.world,
                    templates: &self.scenario.templates,
                    out: &mut out,
                };
                one_way::run(&mut ctx, &mut self.one_way);
            }
            if stage == Stage::Unground && self.frame > 0 {
                // Who was grounded at the end of the last frame, for the snap after
                // `detect`: `unground` is about to forget it. Not a counted stage.
                self.slopes.start_frame(&self.world, &self.scenario.world);
            }
            if allowed && stage == Stage::MoveX && !self.carries() {
                fused = true;
                usual = self.run_motion(&mut out);
                continue;
            }
            if allowed && self.has_work(stage, &out) {
                self.run(stage, &mut out);
                out.stats.stages_run.insert(stage);
            } else {
                out.stats.stages_skipped.insert(stage);
            }
            if stage == Stage::Detect && self.frame > 0 && self.slopes.has_work() {
                // The snap to sloped ground (`stages/slope.rs`): only in a scene with a
                // sloped static body, and not a counted stage (as the one-way pass).
                self.slopes.snap(&mut self.world, &self.scenario.world);
            }
        }
        if !usual {
            self.world.disturb_all();
        }
        self.world.end_step();
        out.stats.bodies = self.world.len();
        out.stats.contacts = out.contacts.len() as u64;
        out.stats.kinetic_energy = self.world.step_kinetic_energy();
        if self.history.on() {
            // After every stage: the end of the frame, as a snapshot taken now holds it.
            self.history.record(&self.world, self.frame);
        }
        self.frame += 1;
        // The step moved bodies: the moving trees (and, if a static body changed, the
        // static ones) are stale. Dropping an empty cell costs a branch.
        self.queries.invalidate(&self.world);
        out
    }
}
