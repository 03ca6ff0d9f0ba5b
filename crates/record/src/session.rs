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
//!
//! Inputs are checked as strictly as a scenario file's values: every vector (a velocity, an
//! impulse, a force, a spawn's position and velocity) finite and within ±1e15
//! (`ricochet_geom::MAX_COORDINATE`), and an impulse or a force refused when the velocity it
//! makes (in one frame, for a force) would be beyond that. What still overflows (gravity of
//! 1e308, say) stops the session at its last good frame: the frame that overflowed, and its
//! inputs, are never written, so the log holds frames 0 to N, complete, as `run` leaves it.

use ricochet_geom::Vec2;
use ricochet_log::messages::ricochet::Input;
use ricochet_log::messages::{Schema, fox::Log, fox::log::Level, timestamp};
use ricochet_log::{ChannelId, LogError, MessageSink};
use ricochet_sim::{Action, ActionFile, BodyKind, FrameOutput, Scenario, Simulation};

use crate::Recorder;
use crate::channels::Channels;

/// The largest input accepted, bytes.
pub const MAX_INPUT: usize = 4096;

/// The name of the attachment that holds a session's scenario.
pub const SCENARIO_ATTACHMENT: &str = "scenario.toml";

/// The largest velocity an input may set or make, units/s, and the largest vector it may
/// carry: the coordinates Ricochet accepts (a scenario file's ±1e15).
pub const MAX_INPUT_VALUE: f64 = ricochet_geom::MAX_COORDINATE;

/// Why a step was not recorded.
#[derive(Debug, thiserror::Error)]
pub enum StepError {
    /// Writing the frame failed.
    #[error(transparent)]
    Log(#[from] LogError),
    /// The step made a value non-finite: neither it nor its inputs were written, and the
    /// session steps no more (its simulation can't be trusted).
    #[error("frame {frame}: {what}; the simulation overflowed")]
    Overflow {
        /// The frame that overflowed (the log holds the frames before it).
        frame: u64,
        /// Which body and value.
        what: String,
    },
}

/// A non-finite body for people: `body NAME #id:generation has a non-finite FIELD [x, y]`
/// (the name's control characters escaped).
pub fn describe(sim: &Simulation, bad: &ricochet_sim::NonFinite) -> String {
    let w = sim.world();
    let name = w.index_of(bad.body).map_or("?", |i| w.name(i));
    format!(
        "body {} #{} has a non-finite {} {}",
        ricochet_log::escape_controls(name),
        bad.body,
        bad.field,
        ricochet_geom::Numbers(bad.value)
    )
}

/// A scenario being stepped, its frames written to `S` with every input.
pub struct Session<S: MessageSink> {
    sim: Simulation,
    recorder: Recorder<S>,
    input: ChannelId,
    events: Option<ChannelId>,
    /// The frame the next step makes.
    next: u64,
    /// The next frame's inputs, each with its refusal's `/events` line: written just before
    /// the frame (the order they always had), so a frame that overflows leaves no trace.
    unwritten: Vec<(Input, Option<Log>)>,
    /// The step that overflowed, if one did (then nothing more is stepped).
    overflowed: Option<(u64, String)>,
}

impl<S: MessageSink> Session<S> {
    /// A session of `scenario` writing to `sink`.
    pub fn new(scenario: &Scenario, sink: S) -> Result<Session<S>, LogError> {
        let mut recorder = Recorder::new(sink, scenario.world.dt, Channels::default())?;
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
            unwritten: Vec::new(),
            overflowed: None,
        })
    }

    /// A session going on from `sim` (a snapshot), writing to a new `sink` from its next
    /// frame: the first frame written lists every body, as a first frame does.
    pub fn resume(sim: Simulation, sink: S) -> Result<Session<S>, LogError> {
        let mut recorder = Recorder::new(sink, sim.dt(), Channels::default())?;
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
            unwritten: Vec::new(),
            overflowed: None,
        })
    }

    /// Takes an input for the next step, recorded with it; why it was refused, if it was
    /// (also written to `/events`).
    pub fn input(&mut self, text: &str) -> Result<Result<(), String>, LogError> {
        let t = self.next.saturating_mul(self.recorder.dt_ns());
        let message = Input {
            frame: self.next,
            text: text.to_owned(),
        };
        let verdict = self.apply(text);
        let line = match (&verdict, self.events) {
            (Err(why), Some(_)) => Some(Log {
                timestamp: Some(timestamp(t)),
                level: Level::Warning as i32,
                message: format!("input refused: {why}"),
                name: "input".to_owned(),
                file: String::new(),
                line: 0,
            }),
            _ => None,
        };
        self.unwritten.push((message, line));
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
        if let Action::SetVelocity(v) | Action::ApplyImpulse(v) | Action::SetForce(v) = action
            && !within(v)
        {
            return Err(format!(
                "{}: {} beyond ±{MAX_INPUT_VALUE:e}",
                action.name(),
                vector(v)
            ));
        }
        if self.overflowed.is_some() {
            return Err("the session overflowed: it steps no more".to_owned());
        }
        let e = self
            .sim
            .entity_named(body)
            .ok_or_else(|| format!("no body named {body:?}"))?;
        self.check_velocity(e, &action)?;
        self.sim.apply(e, action).map_err(|e| e.to_string())
    }

    /// Refuses an impulse, or a force, that would make a dynamic body's velocity (after one
    /// frame, for a force) non-finite or beyond ±[`MAX_INPUT_VALUE`]: a tiny mass turns a
    /// bounded impulse into any speed.
    fn check_velocity(&self, e: ricochet_sim::Entity, action: &Action) -> Result<(), String> {
        let w = self.sim.world();
        let Some(i) = w.index_of(e) else {
            return Ok(());
        };
        if w.kind[i] != BodyKind::Dynamic {
            return Ok(());
        }
        let v = w.velocity(i);
        let made = match action {
            Action::ApplyImpulse(j) => v + *j / w.mass(i),
            Action::SetForce(f) => v + *f / w.mass(i) * self.sim.dt(),
            _ => return Ok(()),
        };
        if within(made) {
            Ok(())
        } else {
            Err(format!(
                "{}: it would make {:?}'s velocity {}, beyond ±{MAX_INPUT_VALUE:e}",
                action.name(),
                w.name(i),
                vector(made)
            ))
        }
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
        let ok = |v: [f64; 2]| within(Vec2::new(v[0], v[1]));
        if !ok(position) || !velocity.is_none_or(ok) || !angle.is_none_or(f64::is_finite) {
            return Err(format!(
                "spawn: position and velocity must be finite and within ±{MAX_INPUT_VALUE:e}, \
                 the angle finite"
            ));
        }
        if self.overflowed.is_some() {
            return Err("the session overflowed: it steps no more".to_owned());
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

    /// Steps one frame and records it with its inputs. A step that overflows is not
    /// recorded, nor are its inputs, and every later call fails the same way: the log ends
    /// with the last good frame.
    pub fn step(&mut self) -> Result<FrameOutput, StepError> {
        if let Some((frame, what)) = &self.overflowed {
            return Err(StepError::Overflow {
                frame: *frame,
                what: what.clone(),
            });
        }
        let out = self.sim.step();
        if let Some(bad) = self.sim.first_non_finite() {
            let what = describe(&self.sim, &bad);
            self.unwritten.clear();
            self.overflowed = Some((out.frame, what.clone()));
            return Err(StepError::Overflow {
                frame: out.frame,
                what,
            });
        }
        let t = out.frame.saturating_mul(self.recorder.dt_ns());
        for (message, line) in std::mem::take(&mut self.unwritten) {
            self.recorder.sink_mut().write(self.input, t, message)?;
            if let (Some(line), Some(ch)) = (line, self.events) {
                self.recorder.sink_mut().write(ch, t, line)?;
            }
        }
        self.recorder.record(&self.sim, &out)?;
        self.next = out.frame + 1;
        Ok(out)
    }

    /// The frame that overflowed and what did, if one did.
    pub fn overflowed(&self) -> Option<(u64, &str)> {
        self.overflowed.as_ref().map(|(f, w)| (*f, w.as_str()))
    }

    /// Sends live viewers the whole current state: both scenes and the camera's frame (after
    /// a reset or a seek). Never recorded.
    pub fn refresh_live(&mut self) -> Result<(), LogError> {
        let frame = self.next.saturating_sub(1);
        self.recorder.refresh_live(&self.sim, frame)
    }

    /// Sends live clients an `/events` line at the last frame stepped (the answer to a
    /// click): never recorded, so a replay never needs it (see [`MessageSink::write_live`]).
    pub fn event_live(&mut self, line: crate::events::EventLine) -> Result<(), LogError> {
        let Some(ch) = self.events else {
            return Ok(());
        };
        let t = self
            .next
            .saturating_sub(1)
            .saturating_mul(self.recorder.dt_ns());
        let message = Log {
            timestamp: Some(timestamp(t)),
            level: line.level as i32,
            message: line.message,
            name: line.kind.to_owned(),
            file: String::new(),
            line: 0,
        };
        self.recorder.sink_mut().write_live(ch, t, message)
    }

    /// Where the layout's camera looks now: the `view` frame's origin in `world`.
    pub fn view_at(&self) -> Vec2 {
        self.recorder.view_at(&self.sim)
    }

    /// The simulation.
    pub fn sim(&self) -> &Simulation {
        &self.sim
    }

    /// The recorder (to ask for every transform again, say).
    pub fn recorder(&mut self) -> &mut Recorder<S> {
        &mut self.recorder
    }

    /// A frame's length, ns (the log's clock).
    pub fn dt_ns(&self) -> u64 {
        self.recorder.dt_ns()
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

/// Whether `v` is finite and within ±[`MAX_INPUT_VALUE`] on both axes.
fn within(v: Vec2) -> bool {
    v.is_finite() && v.abs().max_element() <= MAX_INPUT_VALUE
}

/// `[x, y]` in a short form that reads back the same (`1.7e308`, not 309 digits).
fn vector(v: Vec2) -> String {
    let number = |x: f64| {
        if x != 0.0 && x.is_finite() && !(1e-4..1e6).contains(&x.abs()) {
            format!("{x:e}")
        } else {
            format!("{x:?}")
        }
    };
    format!("[{}, {}]", number(v.x), number(v.y))
}
