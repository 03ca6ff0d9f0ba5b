//! A session: a scenario stepped frame by frame with inputs from outside (the clients of
//! `ricochet serve`), recorded with every input on `/input`, so that `ricochet replay` can
//! step it again and write the same log, byte for byte.
//!
//! An input is JSON, the script's actions addressed by body name:
//! `{"action": "thrust", "body": "ship", "on": true}`, `{"action": "turn", "body": "ship",
//! "input": -0.5}`, `fire`, `move` (`input`), `jump`, `set_velocity` (`velocity: [x, y]`),
//! `apply_impulse` (`impulse`), `set_force` (`force`), `destroy`, and `spawn` (`template`,
//! `position`, optional `name`, `velocity`, `angle`: a body from one of the scenario's
//! templates). It is applied at the next
//! frame boundary (the step that follows), inputs of one frame in the order they came. Every
//! input is recorded on `/input` at the frame it applies to, refused ones too: a replay
//! refuses them again, with the same `/events` line.

use ricochet_geom::Vec2;
use ricochet_log::messages::ricochet::Input;
use ricochet_log::messages::{Schema, fox::Log, fox::log::Level, timestamp};
use ricochet_log::{ChannelId, LogError, MessageSink};
use ricochet_sim::{ActionFile, BodyKind, FrameOutput, Scenario, Simulation};

use crate::channels::Channels;
use crate::record::Recorder;

/// The largest input accepted, bytes.
pub const MAX_INPUT: usize = 4096;

/// The name of the attachment that holds a session's scenario.
pub const SCENARIO_ATTACHMENT: &str = "scenario.toml";

/// A scenario being stepped, its frames written to `S` with every input.
pub struct Session<S: MessageSink> {
    sim: Simulation,
    recorder: Recorder<S>,
    input: ChannelId,
    events: Option<ChannelId>,
    /// The frame the next step makes.
    next: u64,
}

impl<S: MessageSink> Session<S> {
    /// A session of `scenario` writing to `sink` (`live`: see [`Recorder::new`]).
    pub fn new(scenario: &Scenario, sink: S, live: bool) -> Result<Session<S>, LogError> {
        let mut recorder = Recorder::new(sink, scenario.world.dt, Channels::default(), live)?;
        let input = recorder
            .sink_mut()
            .add_protobuf_channel("/input", Schema::ricochet("ricochet.Input"))?;
        let events = recorder.events_channel();
        Ok(Session {
            sim: Simulation::new(scenario),
            recorder,
            input,
            events,
            next: 0,
        })
    }

    /// A session going on from `sim` (a snapshot), writing to a new `sink` from its next
    /// frame: the first frame written lists every body, as a first frame does.
    pub fn resume(sim: Simulation, sink: S, live: bool) -> Result<Session<S>, LogError> {
        let mut recorder = Recorder::new(sink, sim.dt(), Channels::default(), live)?;
        let input = recorder
            .sink_mut()
            .add_protobuf_channel("/input", Schema::ricochet("ricochet.Input"))?;
        let events = recorder.events_channel();
        let next = sim.frame();
        Ok(Session {
            sim,
            recorder,
            input,
            events,
            next,
        })
    }

    /// Takes an input for the next step, recording it; why it was refused, if it was (also
    /// written to `/events`).
    pub fn input(&mut self, text: &str) -> Result<Result<(), String>, LogError> {
        let t = self.next * self.recorder.dt_ns();
        let message = Input {
            frame: self.next,
            text: text.to_owned(),
        };
        self.recorder.sink_mut().write(self.input, t, message)?;
        let verdict = self.apply(text);
        if let (Err(why), Some(ch)) = (&verdict, self.events) {
            let line = Log {
                timestamp: Some(timestamp(t)),
                level: Level::Warning as i32,
                message: format!("input refused: {why}"),
                name: "input".to_owned(),
                file: String::new(),
                line: 0,
            };
            self.recorder.sink_mut().write(ch, t, line)?;
        }
        Ok(verdict)
    }

    fn apply(&mut self, text: &str) -> Result<(), String> {
        if text.len() > MAX_INPUT {
            return Err(format!("{} bytes, more than {MAX_INPUT}", text.len()));
        }
        // The script's actions, in JSON: the same type the scenario files' script reads.
        let input: ActionFile = serde_json::from_str(text).map_err(|e| format!("{e}"))?;
        if let ActionFile::Spawn {
            template,
            name,
            position,
            velocity,
            angle,
        } = &input
        {
            return self.spawn(template, name.as_deref(), *position, *velocity, *angle);
        }
        let Some((body, action)) = input.body_action() else {
            return Err("an action that names no body".to_owned());
        };
        if let Some(field) = action.out_of_range() {
            return Err(format!("{}: {field} out of range", action.name()));
        }
        let e = self
            .sim
            .entity_named(body)
            .ok_or_else(|| format!("no body named {body:?}"))?;
        self.sim.apply(e, action).map_err(|e| e.to_string())
    }

    /// A body from the scenario's template `template`, as the script's `spawn` makes one; it
    /// is in the world for the next step.
    fn spawn(
        &mut self,
        template: &str,
        name: Option<&str>,
        position: [f64; 2],
        velocity: Option<[f64; 2]>,
        angle: Option<f64>,
    ) -> Result<(), String> {
        let Some(base) = self.sim.scenario().templates.get(template) else {
            let known: Vec<&String> = self.sim.scenario().templates.keys().collect();
            return Err(format!(
                "no template {template:?} (the scenario has {known:?})"
            ));
        };
        let mut def = base.clone();
        if let Some(n) = name {
            def.name = n.to_owned();
        }
        let finite = |v: [f64; 2]| v[0].is_finite() && v[1].is_finite();
        if !finite(position) || !velocity.is_none_or(finite) || !angle.is_none_or(f64::is_finite) {
            return Err("spawn: position, velocity and angle must be finite".to_owned());
        }
        def.position = Vec2::new(position[0], position[1]);
        if let Some(v) = velocity {
            if def.kind == BodyKind::Static {
                return Err(format!(
                    "spawn: template {template:?} is static: it can't move"
                ));
            }
            def.velocity = Vec2::new(v[0], v[1]);
        }
        if let Some(a) = angle {
            def.angle = a;
        }
        self.sim.spawn(&def);
        Ok(())
    }

    /// Steps one frame and records it.
    pub fn step(&mut self) -> Result<FrameOutput, LogError> {
        let out = self.sim.step();
        self.recorder.record(&self.sim, &out)?;
        self.next = out.frame + 1;
        Ok(out)
    }

    /// Sends live viewers the whole current state: both scenes and every body's frame (after
    /// a reset or a seek). Never recorded.
    pub fn refresh_live(&mut self) -> Result<(), LogError> {
        let frame = self.next.saturating_sub(1);
        self.recorder.refresh_live(&self.sim, frame)
    }

    /// The simulation.
    pub fn sim(&self) -> &Simulation {
        &self.sim
    }

    /// The recorder (to ask for every transform again, say).
    pub fn recorder(&mut self) -> &mut Recorder<S> {
        &mut self.recorder
    }

    /// The frame the next step makes.
    pub fn next_frame(&self) -> u64 {
        self.next
    }

    /// The sink, back.
    pub fn into_sink(self) -> S {
        self.recorder.into_sink()
    }
}
