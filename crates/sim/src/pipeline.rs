//! The simulation: a world, its scenario, and the fixed stage order.
//!
//! Frame 0 is the initial state: its script events run and contacts are detected, but
//! nothing moves. Every later frame runs every stage in this order, skipping a stage the
//! scene has nothing for (and counting the skip in [`crate::Stats`]):
//!
//! | stage | does |
//! |---|---|
//! | `script` | this frame's script events: inputs, spawns, destroys, velocity/force edits |
//! | `cull` | freeze the moving bodies outside the active region, thaw those inside it |
//! | `unground` | clear `grounded`: it is set again below by whatever holds a body up |
//! | `controls` | controllers turn inputs into angular velocity (ship) or x velocity (runner, walker) |
//! | `forces` | semi-implicit Euler, velocity half: `a = sum(f) / m`, `v += a * dt` |
//! | `move_x` | `x += vx * dt` for every moving body |
//! | `resolve_x` | per-axis separation along x (boxes in `separate` layer pairs) |
//! | `move_y` | `y += vy * dt` |
//! | `resolve_y` | per-axis separation along y; a push upwards sets `grounded` |
//! | `turn` | `angle += angular_velocity * dt` |
//! | `detect` | broad phase, exact narrow phase, `report`/`destroy`/`separate` responses |
//! | `lifetimes` | count down lifetimes; remove expired bodies |
//! | `bounds` | wrap around (Asteroids) or remove bodies that left the world |
//! | `sleep` | count the frames each dynamic body rested; put to sleep those that rested long enough |
//!
//! The motion stages visit only the *active* bodies ([`World::active`]): moving, not frozen,
//! not asleep. Static bodies are never visited after they are indexed.

use std::collections::BTreeMap;

use crate::def::{BodyDef, Event};
use crate::output::FrameOutput;
use crate::scenario::Scenario;
use crate::stage_set::Stage as StageId;
use crate::stages;
use crate::stages::detect::DetectState;
use crate::stages::separate::SeparateState;
use crate::world::World;

/// How far two solid bodies may still overlap after `separate` has pushed them apart, in
/// world units: positions are set exactly flush, so what remains is rounding.
pub const SLOP: f64 = 1e-9;

/// A stage: a plain function over the simulation, with a test of whether it has work.
pub(crate) struct Stage {
    pub id: StageId,
    pub has_work: fn(&Simulation) -> bool,
    pub run: fn(&mut Simulation, &mut FrameOutput),
}

/// The stage order. See the module docs.
pub(crate) const STAGES: [Stage; 14] = [
    Stage {
        id: StageId::Script,
        has_work: stages::script::has_work,
        run: stages::script::run,
    },
    Stage {
        id: StageId::Cull,
        has_work: stages::rest::has_region,
        run: stages::rest::cull,
    },
    Stage {
        id: StageId::Unground,
        has_work: stages::motion::has_grounded,
        run: stages::motion::unground,
    },
    Stage {
        id: StageId::Controls,
        has_work: stages::motion::has_controls,
        run: stages::motion::controls,
    },
    Stage {
        id: StageId::Forces,
        has_work: stages::motion::has_forces,
        run: stages::motion::forces,
    },
    Stage {
        id: StageId::MoveX,
        has_work: stages::motion::has_motion,
        run: stages::motion::move_x,
    },
    Stage {
        id: StageId::ResolveX,
        has_work: stages::separate::has_work,
        run: stages::separate::resolve_x,
    },
    Stage {
        id: StageId::MoveY,
        has_work: stages::motion::has_motion,
        run: stages::motion::move_y,
    },
    Stage {
        id: StageId::ResolveY,
        has_work: stages::separate::has_work,
        run: stages::separate::resolve_y,
    },
    Stage {
        id: StageId::Turn,
        has_work: stages::motion::has_turning,
        run: stages::motion::turn,
    },
    Stage {
        id: StageId::Detect,
        has_work: stages::detect::has_work,
        run: stages::detect::run,
    },
    Stage {
        id: StageId::Lifetimes,
        has_work: stages::lifetimes::has_work,
        run: stages::lifetimes::run,
    },
    Stage {
        id: StageId::Bounds,
        has_work: stages::bounds::has_work,
        run: stages::bounds::run,
    },
    Stage {
        id: StageId::Sleep,
        has_work: stages::rest::has_sleep,
        run: stages::rest::sleep,
    },
];

/// The stages frame 0 runs: the initial state is scripted and checked, never moved. Lifetimes
/// count frame 0, so a body lives `lifetime` frames whether it starts there or is spawned
/// later.
const FRAME_ZERO: [StageId; 4] = [
    StageId::Script,
    StageId::Cull,
    StageId::Detect,
    StageId::Lifetimes,
];

/// A running simulation.
pub struct Simulation {
    /// The scenario it runs.
    pub scenario: Scenario,
    /// The bodies.
    pub world: World,
    /// The next frame to run.
    pub(crate) frame: u64,
    /// Index of the next script event.
    pub(crate) cursor: usize,
    /// Templates by name (shared with the scenario; cloned once for spawning).
    pub(crate) templates: BTreeMap<String, BodyDef>,
    /// Whether each frame reports every body's pose at the start of `detect`
    /// ([`FrameOutput::detect_poses`]). Off by default: it costs a copy per frame.
    pub capture_detect_poses: bool,
    /// The body the active region follows, once found.
    pub(crate) focus: Option<crate::Entity>,
    /// The broad phase and buffers of `detect`.
    pub(crate) detect: DetectState,
    /// The obstacle grids of `resolve_x` and `resolve_y`.
    pub(crate) separate: SeparateState,
}

impl Simulation {
    /// A simulation at the start of frame 0, with the scenario's bodies spawned in file order.
    #[must_use]
    pub fn new(scenario: &Scenario) -> Simulation {
        let mut world = World::new();
        world.reserve(scenario.bodies.len());
        for b in &scenario.bodies {
            world.spawn(b);
        }
        // The bodies live in the world; the simulation's copy of the scenario keeps the rest.
        let rest = Scenario {
            name: scenario.name.clone(),
            world: scenario.world.clone(),
            frames: scenario.frames,
            templates: scenario.templates.clone(),
            bodies: Vec::new(),
            script: scenario.script.clone(),
        };
        Simulation::with_world(rest, world)
    }

    /// A simulation of `scenario` that takes its bodies instead of copying them: for large
    /// scenes, where a second copy of every body would double the memory.
    #[must_use]
    pub fn from_scenario(mut scenario: Scenario) -> Simulation {
        let mut world = World::new();
        let mut bodies = std::mem::take(&mut scenario.bodies);
        world.reserve(bodies.len());
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

    fn with_world(scenario: Scenario, world: World) -> Simulation {
        let layers = &scenario.world.layers;
        Simulation {
            templates: scenario.templates.clone(),
            detect: DetectState::new(layers, scenario.world.broad_phase),
            separate: SeparateState::new(layers),
            scenario,
            world,
            frame: 0,
            cursor: 0,
            capture_detect_poses: false,
            focus: None,
        }
    }

    /// The frame the next [`step`](Self::step) will run.
    #[must_use]
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// Seconds per step.
    #[must_use]
    pub fn dt(&self) -> f64 {
        self.scenario.world.dt
    }

    /// The script events due at the current frame.
    pub(crate) fn due_events(&self) -> &[Event] {
        let rest = &self.scenario.script[self.cursor..];
        let n = rest.iter().take_while(|e| e.frame == self.frame).count();
        &rest[..n]
    }

    /// Runs one frame and reports what happened.
    pub fn step(&mut self) -> FrameOutput {
        let mut out = FrameOutput {
            frame: self.frame,
            ..FrameOutput::default()
        };
        // Swept tests run from here to wherever the frame's motion ends. Static bodies never
        // move, so only the moving ones need it.
        let w = &mut self.world;
        if 2 * w.movers().len() >= w.len() {
            // Mostly moving bodies: one straight copy is cheaper than a gather.
            w.start_position.copy_from_slice(&w.position);
        } else {
            for k in 0..w.movers().len() {
                let i = w.movers()[k] as usize;
                w.start_position[i] = w.position[i];
            }
        }
        for stage in &STAGES {
            let allowed = self.frame > 0 || FRAME_ZERO.contains(&stage.id);
            if allowed && (stage.has_work)(self) {
                (stage.run)(self, &mut out);
                out.stats.stages_run.insert(stage.id);
            } else {
                out.stats.stages_skipped.insert(stage.id);
            }
        }
        out.stats.bodies = self.world.len();
        out.stats.contacts = out.contacts.len() as u64;
        out.stats.kinetic_energy = self.world.kinetic_energy();
        self.frame += 1;
        out
    }
}
