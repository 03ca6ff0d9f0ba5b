//! Recording a run as an MCAP log of protobuf messages (MCAP's protobuf profile: every
//! channel's schema is a FileDescriptorSet, so any protobuf reader decodes it).
//!
//! | topic | schema | content |
//! |---|---|---|
//! | `/scene` | `foxglove.SceneUpdate` | every moving body, in `world`: whole, in every drawn frame (`pace.rs`: every frame for small scenes) in which, or since whose last drawing, one moved, appeared or went (`scene.rs`) |
//! | `/scene/static` | `foxglove.SceneUpdate` | every static body, the same way: whole, when one appeared, went or moved |
//! | `/tf` | `foxglove.FrameTransforms` | one frame, `view`, where the layout's camera looks: the focus body, or the world's centre |
//! | `/scene/contacts` | `foxglove.SceneUpdate` | the frame's contact normals, one line list |
//! | `/bodies` | `ricochet.Bodies` | exact body states: every body at keyframes, between them what the integrator does not predict |
//! | `/contacts` | `ricochet.Contacts` | every contact, with the poses it was detected at |
//! | `/stats` | `ricochet.Stats` | deterministic counters, for Foxglove's Plot panel |
//! | `/events` | `foxglove.Log` | inputs, spawns, destructions and collision events |
//!
//! `log_time = publish_time = frame * dt_ns`, with `dt_ns` the step rounded to whole
//! nanoseconds: nothing from the wall clock reaches the file. Messages are built here and
//! encoded and compressed on the log's writer thread.

use std::mem::take;
use std::path::Path;

use prost::Message;

use ricochet_geom::Vec2;
use ricochet_log::messages::fox::{FrameTransforms, Log, SceneUpdate, log};
use ricochet_log::messages::{Schema, ricochet as pb, timestamp};
use ricochet_log::{ChannelId, LogError, LogWriter, MessageSink, Threading};
use ricochet_sim::{FrameOutput, Layers, Simulation};

use crate::bodies::Tracker;
use crate::channels::Channels;
use crate::pace::DrawPace;
use crate::scene;

/// The `library` field of every log's header.
pub const LIBRARY: &str = concat!("ricochet ", env!("CARGO_PKG_VERSION"));

/// Setting this environment variable to `1` encodes on the calling thread instead of the
/// writer thread (the log is byte-identical; tests check it).
pub const INLINE_ENV: &str = "RICOCHET_INLINE_WRITER";

fn xy(v: ricochet_geom::Vec2) -> Vec<f64> {
    vec![v.x, v.y]
}

fn pose3(p: &ricochet_geom::Pose) -> Vec<f64> {
    vec![p.position.x, p.position.y, p.angle]
}

/// The channels of a log, those recorded.
#[derive(Default)]
struct Topics {
    scene: Option<ChannelId>,
    statics: Option<ChannelId>,
    tf: Option<ChannelId>,
    normals: Option<ChannelId>,
    bodies: Option<ChannelId>,
    contacts: Option<ChannelId>,
    stats: Option<ChannelId>,
    events: Option<ChannelId>,
    validation: Option<ChannelId>,
}

/// Writes a run's frames to an MCAP file, or to any [`MessageSink`] (a live stream).
pub struct Recorder<S: MessageSink = LogWriter> {
    writer: S,
    dt_ns: u64,
    dt: f64,
    topics: Topics,
    tracker: Tracker,
    /// The previous frame had contact normals (so this one sends an empty set if it has none).
    normals_shown: bool,
    /// How bodies become entities, chosen at the first frame (from its body count).
    style: Option<scene::Style>,
    /// Where the camera's frame was last sent, and where it looks without a focus body or
    /// world bounds (the centre of the bodies' extent at the first frame recorded).
    view: Option<(Vec2, Vec2)>,
    /// The channels whose messages [`Recorder::record`] builds (all by default): a live
    /// stream that nobody watches and nothing records skips the others (see
    /// [`Recorder::build_only`]).
    wanted: Channels,
    /// The scene's channels were skipped since they were last built: the next frame that
    /// builds them sends every one of them whole (what a new viewer needs).
    scene_skipped: bool,
    /// Whether [`Recorder::record`] draws `/scene` (see [`Recorder::draw_moving`]).
    draw_moving: bool,
    /// `/scene` was not drawn since it was last sent: the next frame that draws it sends it
    /// whether or not a body moved in that frame.
    moving_skipped: bool,
    /// Messages `record` built, all channels.
    built: u64,
    /// Which frames draw the scene's channels (`pace.rs`).
    pace: DrawPace,
}

/// A new log file at `path` (a temporary file renamed onto it when finished), with
/// Ricochet's header and the writer thread (inline with [`INLINE_ENV`]).
pub fn log_writer(path: &Path) -> Result<LogWriter, LogError> {
    let threading = if std::env::var_os(INLINE_ENV).is_some_and(|v| v == "1") {
        Threading::Inline
    } else {
        Threading::Thread
    };
    LogWriter::create_with(path, LIBRARY, threading)
}

impl Recorder<LogWriter> {
    /// Creates the file now (so a bad path fails before the simulation starts) and adds the
    /// chosen channels (all by default).
    pub fn create(path: &Path, dt: f64, channels: Channels) -> Result<Recorder, LogError> {
        Recorder::new(log_writer(path)?, dt, channels)
    }

    /// Writes the summary and index. Called after an interrupted run too.
    pub fn finish(self) -> Result<(), LogError> {
        self.writer.finish()
    }
}

impl<S: MessageSink> Recorder<S> {
    /// Adds the chosen channels to `sink`.
    pub fn new(mut w: S, dt: f64, channels: Channels) -> Result<Recorder<S>, LogError> {
        let mut t = Topics::default();
        if channels.scene {
            t.scene = Some(w.add_protobuf_channel("/scene", Schema::foxglove::<SceneUpdate>())?);
            t.statics =
                Some(w.add_protobuf_channel("/scene/static", Schema::foxglove::<SceneUpdate>())?);
            t.tf = Some(w.add_protobuf_channel("/tf", Schema::foxglove::<FrameTransforms>())?);
            t.normals =
                Some(w.add_protobuf_channel("/scene/contacts", Schema::foxglove::<SceneUpdate>())?);
        }
        if channels.bodies {
            t.bodies =
                Some(w.add_protobuf_channel("/bodies", Schema::ricochet("ricochet.Bodies"))?);
        }
        if channels.contacts {
            t.contacts =
                Some(w.add_protobuf_channel("/contacts", Schema::ricochet("ricochet.Contacts"))?);
        }
        if channels.stats {
            t.stats = Some(w.add_protobuf_channel("/stats", Schema::ricochet("ricochet.Stats"))?);
        }
        if channels.events {
            t.events = Some(w.add_protobuf_channel("/events", Schema::foxglove::<Log>())?);
        }
        Ok(Recorder {
            writer: w,
            // Whole nanoseconds per step; `f64 as u64` saturates and the scenario checks
            // dt > 0 and finite.
            dt_ns: (dt * 1e9).round() as u64,
            dt,
            topics: t,
            tracker: Tracker::default(),
            normals_shown: false,
            style: None,
            view: None,
            wanted: Channels::default(),
            scene_skipped: false,
            draw_moving: true,
            moving_skipped: false,
            built: 0,
            pace: DrawPace::default(),
        })
    }

    /// The sink, back.
    pub fn into_sink(self) -> S {
        self.writer
    }

    /// The sink, to write channels of its own.
    pub fn sink_mut(&mut self) -> &mut S {
        &mut self.writer
    }

    /// The `/events` channel, if recorded.
    pub fn events_channel(&self) -> Option<ChannelId> {
        self.topics.events
    }

    /// The step in whole nanoseconds: frame `n` is at `n * dt_ns`.
    pub fn dt_ns(&self) -> u64 {
        self.dt_ns
    }

    /// Sends live viewers the whole scene at `frame`: `/scene/static`, `/scene` and the
    /// camera's frame (never recorded: see [`MessageSink::write_live`]).
    pub fn refresh_live(&mut self, sim: &Simulation, frame: u64) -> Result<(), LogError> {
        let t = frame * self.dt_ns;
        let ts = timestamp(t);
        let (w, layers) = (sim.world(), &sim.scenario().world.layers);
        let style = self.style(w);
        for (channel, statics) in [(self.topics.statics, true), (self.topics.scene, false)] {
            if let Some(ch) = channel {
                let bytes = scene::snapshot_encoded(w, layers, statics, style, ts);
                self.writer.write_live_encoded(ch, t, bytes)?;
            }
        }
        self.send_view_live(sim, t)?;
        self.moving_skipped = false;
        Ok(())
    }

    /// Sends live viewers `/scene` (and `/tf`, stamped with it) at `frame`, the last frame
    /// recorded, if a frame's was not drawn since it was last sent
    /// ([`Recorder::draw_moving`]): stepping stopped, so no later frame will draw it. Never
    /// recorded.
    pub fn show_moving_live(&mut self, sim: &Simulation, frame: u64) -> Result<(), LogError> {
        let Some(ch) = self.topics.scene else {
            return Ok(());
        };
        if !std::mem::take(&mut self.moving_skipped) {
            return Ok(());
        }
        let t = frame * self.dt_ns;
        let (w, layers) = (sim.world(), &sim.scenario().world.layers);
        let style = self.style(w);
        let bytes = scene::snapshot_encoded(w, layers, false, style, timestamp(t));
        self.writer.write_live_encoded(ch, t, bytes)?;
        // The camera's frame with the drawing, stamped now, as `record` sends it live.
        self.send_view_live(sim, t)
    }

    /// Sends live viewers the camera's frame stamped at `t` (never recorded).
    fn send_view_live(&mut self, sim: &Simulation, t: u64) -> Result<(), LogError> {
        if let Some(ch) = self.topics.tf {
            let message = view_message(t, self.view_at(sim));
            self.writer.write_live(ch, t, message)?;
        }
        Ok(())
    }

    /// How bodies become entities: chosen at the first frame from its body count, then kept.
    fn style(&mut self, w: &ricochet_sim::World) -> scene::Style {
        *self
            .style
            .get_or_insert_with(|| scene::Style::for_bodies(w.len()))
    }

    /// The centre of the bodies' extent at the first frame recorded: where the camera looks
    /// without a focus body or world bounds.
    fn fallback_view(&self, sim: &Simulation) -> Vec2 {
        self.view.map_or_else(
            || scene::extent_centre(sim.world()),
            |(_, fallback)| fallback,
        )
    }

    /// Where the camera looks now, the `view` frame's origin in `world` (see
    /// [`scene::view_position`]).
    pub fn view_at(&self, sim: &Simulation) -> Vec2 {
        let bounds = sim.scenario().world.bounds.map(|b| (b.min, b.max));
        scene::view_position(sim.world(), sim.focus(), bounds, self.fallback_view(sim))
    }

    /// Adds the `/validation` channel (`ricochet run --validate`).
    pub fn add_validation_channel(&mut self) -> Result<(), LogError> {
        let id = self
            .writer
            .add_protobuf_channel("/validation", Schema::ricochet("ricochet.Validation"))?;
        self.topics.validation = Some(id);
        Ok(())
    }

    /// Writes a referee's verdict on a frame (its `frame` field) to `/validation`, if added.
    /// The referee is the caller's (`ricochet run --validate` uses rapier's): this crate
    /// only records it.
    pub fn record_validation(&mut self, verdict: pb::Validation) -> Result<(), LogError> {
        if let Some(ch) = self.topics.validation {
            self.writer.write(ch, verdict.frame * self.dt_ns, verdict)?;
        }
        Ok(())
    }

    /// From the next frame, [`Recorder::record`] builds only `wanted`'s channels' messages
    /// (all, by default). For a live stream only (a room nobody records): a recording must
    /// get every message. The bodies are still tracked every frame, so `/bodies` goes on
    /// from the right state; the scene's channels, when wanted again, are sent whole at
    /// once (`/scene/static` too, which is otherwise sent only when a static body changes).
    pub fn build_only(&mut self, wanted: Channels) {
        self.wanted = wanted;
    }

    /// Draws the scene's channels in every frame, whatever their size (see `pace.rs`):
    /// exact seeks in the viewer, slower recording of big scenes. Call before the first
    /// frame.
    pub fn draw_every_frame(&mut self) {
        self.pace = DrawPace::every_frame();
    }

    /// From the next frame, whether [`Recorder::record`] draws `/scene` (yes by default),
    /// when [`Recorder::build_only`] wants the scene's channels: a live stream whose clients
    /// are each sent a whole state at most so often draws it only in the frames one is due
    /// (drawing 10,000 bodies is most of such a frame). For a live stream only: a recording
    /// must get every message. The next frame that draws it sends it, moved or not;
    /// `/scene/static`, `/tf` and `/scene/contacts` go on as [`Recorder::build_only`] says.
    pub fn draw_moving(&mut self, draw: bool) {
        self.draw_moving = draw;
    }

    /// Messages [`Recorder::record`] built so far, all channels (a test's count of what
    /// was skipped).
    pub fn built(&self) -> u64 {
        self.built
    }

    /// Writes one frame on every channel (every one [`Recorder::build_only`] wants).
    pub fn record(&mut self, sim: &Simulation, out: &FrameOutput) -> Result<(), LogError> {
        let t = out.frame * self.dt_ns;
        let ts = timestamp(t);
        let w = sim.world();
        let layers = &sim.scenario().world.layers;
        let want_bodies = self.topics.bodies.is_some() && self.wanted.bodies;
        if self.topics.scene.is_some() || self.topics.bodies.is_some() {
            let style = self.style(w);
            // At the first frame every body is new (the tracker says both scenes changed),
            // so the drawing is due whatever else the tracker finds: it is drawn first, and
            // the writer compresses it while the tracker lists the keyframe (1.5 MB each for
            // 10,000 asteroids). The messages go to the writer in the same order either way.
            let first = !self.tracker.started();
            if first {
                self.pace.scene_pending = true;
                self.pace.statics_pending = true;
                self.draw(sim, out, style)?;
            }
            let mut changes = self.tracker.frame(
                w,
                out,
                &sim.scenario().world,
                want_bodies,
                style == scene::Style::PerBody,
            );
            if !first {
                self.pace.scene_pending |= changes.scene_changed;
                self.pace.statics_pending |= changes.static_changed;
                self.draw(sim, out, style)?;
            }
            if let (Some(ch), true) = (self.topics.bodies, want_bodies) {
                changes.bodies.time = out.frame as f64 * self.dt;
                let bodies = changes.encode_bodies();
                if changes.bodies.keyframe {
                    self.tracker
                        .keyframe_written(out.frame, bodies.len() as u64);
                }
                self.writer.write_encoded(ch, t, bodies)?;
                self.built += 1;
            }
        }
        if let (Some(ch), true) = (self.topics.contacts, self.wanted.contacts) {
            self.writer.write(ch, t, contacts_message(out))?;
            self.built += 1;
        }
        if let (Some(ch), true) = (self.topics.stats, self.wanted.stats) {
            self.writer.write(ch, t, stats_message(out, layers))?;
            self.built += 1;
        }
        if let (Some(ch), true) = (self.topics.events, self.wanted.events) {
            for e in &out.events {
                let line = crate::events::line(e, w, out);
                let msg = Log {
                    timestamp: Some(ts),
                    level: line.level as i32,
                    message: line.message,
                    name: line.kind.to_owned(),
                    file: String::new(),
                    line: 0,
                };
                self.writer.write(ch, t, msg)?;
                self.built += 1;
            }
        }
        Ok(())
    }

    /// Draws the scene's channels at frame `out.frame`, if due (see `pace.rs`).
    fn draw(
        &mut self,
        sim: &Simulation,
        out: &FrameOutput,
        style: scene::Style,
    ) -> Result<(), LogError> {
        let t = out.frame * self.dt_ns;
        let ts = timestamp(t);
        let w = sim.world();
        let layers = &sim.scenario().world.layers;
        // A scene drawn body by body (at most 256 bodies) is small: drawn every frame.
        let due = style == scene::Style::PerBody || self.pace.due(out.frame);
        if self.wanted.scene && due {
            let whole = std::mem::take(&mut self.scene_skipped);
            // Only a batched drawing is paced, so only its bytes are counted.
            let counted = style == scene::Style::Batched;
            let mut bytes = 0;
            let mut drew_moving = false;
            for (channel, statics, changed) in [
                (
                    self.topics.statics,
                    true,
                    take(&mut self.pace.statics_pending),
                ),
                (self.topics.scene, false, take(&mut self.pace.scene_pending)),
            ] {
                if !statics && !self.draw_moving {
                    self.moving_skipped = true;
                    continue;
                }
                let redraw = !statics && std::mem::take(&mut self.moving_skipped);
                if let (Some(ch), true) = (channel, changed || whole || redraw) {
                    let message = scene::snapshot_encoded(w, layers, statics, style, ts);
                    if counted {
                        bytes += message.len();
                    }
                    self.writer.write_encoded(ch, t, message)?;
                    self.built += 1;
                    drew_moving |= !statics;
                }
            }
            if let Some(ch) = self.topics.tf {
                let at = self.view_at(sim);
                if whole || self.view.is_none_or(|(sent, _)| !same_point(sent, at)) {
                    self.view = Some((at, self.fallback_view(sim)));
                    let transforms = view_message(t, at);
                    if counted {
                        bytes += transforms.encoded_len();
                    }
                    self.writer.write(ch, t, transforms)?;
                    self.built += 1;
                } else if drew_moving {
                    // Live viewers only (a file ignores it): the camera's frame again,
                    // stamped now, with each drawing. Lichtblick's live 3D panel does not
                    // apply a transform stamped long before the frames it shows: a viewer
                    // that connected after the camera last moved got the latched /tf of
                    // frame 0 and looked at the world's origin, not the view.
                    self.writer.write_live(ch, t, view_message(t, at))?;
                }
            }
            if let Some(ch) = self.topics.normals
                && (!out.contacts.is_empty() || self.normals_shown)
            {
                let normals = scene::contact_normals(&out.contacts, ts);
                if counted {
                    bytes += normals.encoded_len();
                }
                self.writer.write(ch, t, normals)?;
                self.normals_shown = !out.contacts.is_empty();
                self.built += 1;
            }
            self.pace.drawn(out.frame, bytes as u64);
        } else if self.topics.scene.is_some() && !self.wanted.scene {
            self.scene_skipped = true;
            if self.view.is_none() {
                // The camera's fallback is where the bodies were at the first frame,
                // whether or not it was sent then.
                self.view = Some((self.view_at(sim), self.fallback_view(sim)));
            }
        }
        Ok(())
    }
}

/// `/tf`'s message at `t`: the camera's frame looking at `at`.
fn view_message(t: u64, at: Vec2) -> FrameTransforms {
    FrameTransforms {
        transforms: vec![scene::view_transform(timestamp(t), at)],
    }
}

/// The same point, bit for bit.
fn same_point(a: Vec2, b: Vec2) -> bool {
    a.x.to_bits() == b.x.to_bits() && a.y.to_bits() == b.y.to_bits()
}

/// `/contacts`: every contact of the frame with the poses it was found at.
fn contacts_message(out: &FrameOutput) -> pb::Contacts {
    let contacts = out
        .contacts
        .iter()
        .map(|c| pb::Contact {
            a: c.a.index,
            a_generation: c.a.generation,
            b: c.b.index,
            b_generation: c.b.generation,
            phase: c.phase.name().to_owned(),
            normal: xy(c.normal),
            depth: c.depth,
            point: xy(c.point),
            pose_a: pose3(&c.pose_a),
            pose_b: pose3(&c.pose_b),
            response: c.response.name().to_owned(),
            resolved: xy(c.resolved),
        })
        .collect();
    pb::Contacts {
        frame: out.frame,
        contacts,
    }
}

/// `/stats`: the frame's counters, layer pairs and stages named.
fn stats_message(out: &FrameOutput, layers: &Layers) -> pb::Stats {
    let s = &out.stats;
    pb::Stats {
        frame: out.frame,
        bodies: s.bodies as u64,
        broad_phase: s.broad_phase.map_or("", |k| k.name()).to_owned(),
        broad_pairs: s.broad_pairs,
        narrow_tests: s.narrow_tests,
        contacts: s.contacts,
        layer_pairs_skipped: s.layer_pairs_skipped,
        frozen: s.frozen as u64,
        asleep: s.asleep as u64,
        stages_run: s.stages_run.len() as u64,
        stages_skipped: s.stages_skipped.len() as u64,
        skipped: s
            .stages_skipped
            .iter()
            .map(|st| st.name().to_owned())
            .collect(),
        tests_by_layer_pair: s
            .tests_by_layer_pair
            .iter()
            .map(|&((a, b), n)| (format!("{}/{}", layers.name(a), layers.name(b)), n))
            .collect(),
        kinetic_energy: s.kinetic_energy,
    }
}

/// The level of an event line, as `foxglove.Log` numbers it.
pub type Level = log::Level;
