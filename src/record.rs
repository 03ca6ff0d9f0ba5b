//! Recording a run as an MCAP log: five channels per frame, all JSON with a JSON Schema.
//!
//! | topic | schema | content |
//! |---|---|---|
//! | `/scene` | `foxglove.SceneUpdate` | every body drawn in the XY plane, contact arrows, deletions |
//! | `/bodies` | `ricochet.Bodies` | every body at the end of the frame, and the removed ones |
//! | `/contacts` | `ricochet.Contacts` | every contact, with the poses it was detected at |
//! | `/stats` | `ricochet.Stats` | deterministic counters, for Foxglove's Plot panel |
//! | `/events` | `foxglove.Log` | inputs, spawns, destructions and collision events |
//!
//! `log_time = publish_time = frame * dt_ns`, with `dt_ns` the step rounded to whole
//! nanoseconds: nothing from the wall clock reaches the file.

use std::collections::BTreeMap;
use std::path::Path;

use ricochet_geom::{Pose, ShapeDef, Vec2};
use ricochet_log::foxglove::{Log, Timestamp};
use ricochet_log::{ChannelId, LogError, LogWriter};
use ricochet_sim::{BodyKind, FrameOutput, Layers, RemovedBody, Simulation};
use serde::Serialize;

use crate::channels::Channels;

/// The `library` field of every log's header.
pub const LIBRARY: &str = concat!("ricochet ", env!("CARGO_PKG_VERSION"));

const BODIES_SCHEMA: &str = include_str!("schemas/Bodies.json");
const CONTACTS_SCHEMA: &str = include_str!("schemas/Contacts.json");
const STATS_SCHEMA: &str = include_str!("schemas/Stats.json");

#[derive(Serialize)]
struct BodyMsg<'a> {
    id: u32,
    generation: u32,
    name: &'a str,
    layer: &'a str,
    shape: ShapeDef,
    position: [f64; 2],
    angle: f64,
    velocity: [f64; 2],
    #[serde(rename = "static")]
    is_static: bool,
}

#[derive(Serialize)]
struct BodiesMsg<'a> {
    frame: u64,
    time: f64,
    bodies: Vec<BodyMsg<'a>>,
    removed: Vec<BodyMsg<'a>>,
}

#[derive(Serialize)]
struct ContactMsg {
    a: u32,
    a_generation: u32,
    b: u32,
    b_generation: u32,
    phase: &'static str,
    normal: [f64; 2],
    depth: f64,
    point: [f64; 2],
    pose_a: [f64; 3],
    pose_b: [f64; 3],
    response: &'static str,
    resolved: [f64; 2],
}

#[derive(Serialize)]
struct ContactsMsg {
    frame: u64,
    contacts: Vec<ContactMsg>,
}

#[derive(Serialize)]
struct StatsMsg {
    frame: u64,
    bodies: usize,
    broad_phase: &'static str,
    broad_pairs: u64,
    narrow_tests: u64,
    contacts: u64,
    layer_pairs_skipped: u64,
    frozen: usize,
    asleep: usize,
    stages_run: usize,
    stages_skipped: usize,
    skipped: Vec<&'static str>,
    /// `"a/b"` layer names: sorted by the names, as a JSON object's keys.
    tests_by_layer_pair: BTreeMap<String, u64>,
    kinetic_energy: f64,
}

fn xy(v: Vec2) -> [f64; 2] {
    [v.x, v.y]
}

fn pose3(p: &Pose) -> [f64; 3] {
    [p.position.x, p.position.y, p.angle]
}

fn removed_msg<'a>(r: &'a RemovedBody, layers: &'a Layers) -> BodyMsg<'a> {
    BodyMsg {
        id: r.entity.index,
        generation: r.entity.generation,
        name: &r.name,
        layer: layers.name(r.layer),
        shape: ShapeDef::from_shape(&r.shape),
        position: xy(r.pose.position),
        angle: r.pose.angle,
        velocity: xy(r.velocity),
        is_static: r.kind == BodyKind::Static,
    }
}

/// Writes a run's frames to an MCAP file.
pub struct Recorder {
    writer: LogWriter,
    dt_ns: u64,
    scene: Option<ChannelId>,
    bodies: Option<ChannelId>,
    contacts: Option<ChannelId>,
    stats: Option<ChannelId>,
    events: Option<ChannelId>,
    validation: Option<ChannelId>,
}

impl Recorder {
    /// Creates the file now (so a bad path fails before the simulation starts) and adds the
    /// chosen channels (all five by default).
    pub fn create(path: &Path, dt: f64, channels: Channels) -> Result<Recorder, LogError> {
        let mut writer = LogWriter::create(path, LIBRARY)?;
        let mut add = |on: bool,
                       make: &mut dyn FnMut(&mut LogWriter) -> Result<ChannelId, LogError>|
         -> Result<Option<ChannelId>, LogError> {
            if on {
                make(&mut writer).map(Some)
            } else {
                Ok(None)
            }
        };
        let scene = add(channels.scene, &mut |w| w.add_scene_channel("/scene"))?;
        let bodies = add(channels.bodies, &mut |w| {
            w.add_json_channel("/bodies", "ricochet.Bodies", BODIES_SCHEMA)
        })?;
        let contacts = add(channels.contacts, &mut |w| {
            w.add_json_channel("/contacts", "ricochet.Contacts", CONTACTS_SCHEMA)
        })?;
        let stats = add(channels.stats, &mut |w| {
            w.add_json_channel("/stats", "ricochet.Stats", STATS_SCHEMA)
        })?;
        let events = add(channels.events, &mut |w| w.add_log_channel("/events"))?;
        Ok(Recorder {
            writer,
            // Whole nanoseconds per step; `f64 as u64` saturates and the scenario checks
            // dt > 0 and finite.
            dt_ns: (dt * 1e9).round() as u64,
            scene,
            bodies,
            contacts,
            stats,
            events,
            validation: None,
        })
    }

    /// Adds the `/validation` channel (`ricochet run --validate`).
    pub fn add_validation_channel(&mut self) -> Result<(), LogError> {
        let id = self.writer.add_json_channel(
            "/validation",
            "ricochet.Validation",
            crate::validation_channel::SCHEMA,
        )?;
        self.validation = Some(id);
        Ok(())
    }

    /// Writes the referee's verdict on a frame to `/validation`.
    pub fn record_validation(&mut self, r: &ricochet_oracle::FrameReport) -> Result<(), LogError> {
        if let Some(ch) = self.validation {
            let msg = crate::validation_channel::ValidationMsg::from_report(r);
            self.writer.write(ch, r.frame * self.dt_ns, &msg)?;
        }
        Ok(())
    }

    /// Writes one frame on every channel.
    pub fn record(&mut self, sim: &Simulation, out: &FrameOutput) -> Result<(), LogError> {
        let t = out.frame * self.dt_ns;
        let ts = Timestamp::from_nanos(t);
        let w = sim.world();
        let layers = &sim.scenario().world.layers;
        if let Some(ch) = self.scene {
            self.writer
                .write(ch, t, &crate::scene::scene_update(w, out, ts))?;
        }
        if let Some(ch) = self.bodies {
            self.write_bodies(ch, sim, out)?;
        }
        if let Some(ch) = self.contacts {
            write_contacts(&mut self.writer, ch, t, out)?;
        }
        if let Some(ch) = self.stats {
            write_stats(&mut self.writer, ch, t, out, layers)?;
        }
        if let Some(ch) = self.events {
            for e in &out.events {
                let line = crate::events::line(e, w, out);
                let log = Log::new(ts, line.level, line.kind, line.message);
                self.writer.write(ch, t, &log)?;
            }
        }
        Ok(())
    }

    /// `/bodies`: every body at the end of the frame, and the removed ones.
    fn write_bodies(
        &mut self,
        ch: ChannelId,
        sim: &Simulation,
        out: &FrameOutput,
    ) -> Result<(), LogError> {
        let t = out.frame * self.dt_ns;
        let w = sim.world();
        let layers = &sim.scenario().world.layers;
        let bodies = (0..w.len())
            .map(|i| BodyMsg {
                id: w.entity[i].index,
                generation: w.entity[i].generation,
                name: &w.name[i],
                layer: layers.name(w.layer[i]),
                shape: ShapeDef::from_shape(&w.shape[i]),
                position: xy(w.position[i]),
                angle: w.angle[i],
                velocity: xy(w.velocity[i]),
                is_static: w.kind[i] == BodyKind::Static,
            })
            .collect();
        let removed = out.removed.iter().map(|r| removed_msg(r, layers)).collect();
        let msg = BodiesMsg {
            frame: out.frame,
            time: out.frame as f64 * sim.dt(),
            bodies,
            removed,
        };
        self.writer.write(ch, t, &msg)
    }

    /// Writes the summary and index. Called after an interrupted run too.
    pub fn finish(self) -> Result<(), LogError> {
        self.writer.finish()
    }
}

/// `/contacts`: every contact of the frame with the poses it was found at.
fn write_contacts(
    writer: &mut LogWriter,
    ch: ChannelId,
    t: u64,
    out: &FrameOutput,
) -> Result<(), LogError> {
    let contacts = out
        .contacts
        .iter()
        .map(|c| ContactMsg {
            a: c.a.index,
            a_generation: c.a.generation,
            b: c.b.index,
            b_generation: c.b.generation,
            phase: c.phase.name(),
            normal: xy(c.normal),
            depth: c.depth,
            point: xy(c.point),
            pose_a: pose3(&c.pose_a),
            pose_b: pose3(&c.pose_b),
            response: c.response.name(),
            resolved: xy(c.resolved),
        })
        .collect();
    writer.write(
        ch,
        t,
        &ContactsMsg {
            frame: out.frame,
            contacts,
        },
    )
}

/// `/stats`: the frame's counters, layer pairs and stages named.
fn write_stats(
    writer: &mut LogWriter,
    ch: ChannelId,
    t: u64,
    out: &FrameOutput,
    layers: &Layers,
) -> Result<(), LogError> {
    let s = &out.stats;
    let stats = StatsMsg {
        frame: out.frame,
        bodies: s.bodies,
        broad_phase: s.broad_phase.map_or("", |k| k.name()),
        broad_pairs: s.broad_pairs,
        narrow_tests: s.narrow_tests,
        contacts: s.contacts,
        layer_pairs_skipped: s.layer_pairs_skipped,
        frozen: s.frozen,
        asleep: s.asleep,
        stages_run: s.stages_run.len(),
        stages_skipped: s.stages_skipped.len(),
        skipped: s.stages_skipped.iter().map(|st| st.name()).collect(),
        tests_by_layer_pair: s
            .tests_by_layer_pair
            .iter()
            .map(|&((a, b), n)| (format!("{}/{}", layers.name(a), layers.name(b)), n))
            .collect(),
        kinetic_energy: s.kinetic_energy,
    };
    writer.write(ch, t, &stats)
}
