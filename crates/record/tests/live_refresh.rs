//! What a live viewer that just subscribed gets (`Recorder::refresh_live`) and what it gets
//! when stepping stops with a drawing skipped (`Recorder::show_moving_live`): the whole
//! scene of that frame, as prost encodes `scene::snapshot` of it, sent to live viewers
//! only and never recorded.

use ricochet_log::messages::{Schema, timestamp};
use ricochet_log::{ChannelId, LogError, MessageSink};
use ricochet_record::scene::{self, Style};
use ricochet_record::{Channels, Recorder};
use ricochet_scenes::bench::Scene;
use ricochet_sim::Simulation;

/// A message written: live only or not, its topic, time and bytes.
type Written = (bool, String, u64, Vec<u8>);

/// Keeps every message, with its topic, and whether it was for live viewers only.
#[derive(Default)]
struct Kept {
    topics: Vec<String>,
    written: Vec<Written>,
}

impl Kept {
    fn keep(&mut self, live: bool, channel: ChannelId, time_ns: u64, bytes: Vec<u8>) {
        let topic = self.topics[usize::from(channel.index())].clone();
        self.written.push((live, topic, time_ns, bytes));
    }

    /// The live-only messages on `topic`.
    fn live(&self, topic: &str) -> Vec<&Written> {
        (self.written.iter())
            .filter(|(live, t, ..)| *live && t == topic)
            .collect()
    }
}

impl MessageSink for Kept {
    fn add_protobuf_channel(&mut self, topic: &str, _: Schema) -> Result<ChannelId, LogError> {
        self.topics.push(topic.to_string());
        Ok(ChannelId::from_index(self.topics.len() as u16 - 1))
    }

    fn write<M: prost::Message + Clone + Send + 'static>(
        &mut self,
        channel: ChannelId,
        time_ns: u64,
        message: M,
    ) -> Result<(), LogError> {
        self.keep(false, channel, time_ns, message.encode_to_vec());
        Ok(())
    }

    fn add_json_channel(&mut self, topic: &str, _: &str, _: &str) -> Result<ChannelId, LogError> {
        self.topics.push(topic.to_string());
        Ok(ChannelId::from_index(self.topics.len() as u16 - 1))
    }

    fn write_encoded(&mut self, ch: ChannelId, t: u64, bytes: Vec<u8>) -> Result<(), LogError> {
        self.keep(false, ch, t, bytes);
        Ok(())
    }

    fn write_live_encoded(
        &mut self,
        ch: ChannelId,
        t: u64,
        bytes: Vec<u8>,
    ) -> Result<(), LogError> {
        self.keep(true, ch, t, bytes);
        Ok(())
    }
}

/// `name` stepped and recorded for `frames` frames, then refreshed for a new viewer.
fn refreshed(name: &str, frames: u64) -> (Simulation, Kept, u64) {
    let scenario = Scene::parse(name).unwrap().build(frames);
    let dt = scenario.world.dt;
    let mut recorder = Recorder::new(Kept::default(), dt, Channels::default()).unwrap();
    let mut sim = Simulation::new(&scenario);
    for _ in 0..=frames {
        let out = sim.step();
        recorder.record(&sim, &out).unwrap();
    }
    recorder.refresh_live(&sim, frames).unwrap();
    let dt_ns = recorder.dt_ns();
    (sim, recorder.into_sink(), dt_ns)
}

#[test]
fn a_new_viewer_gets_the_whole_scene_as_prost_encodes_it() {
    // 2,000 asteroids are drawn in batches, 20 balls one entity a body.
    for (name, style) in [
        ("asteroids-2000", Style::Batched),
        ("asteroids-20", Style::PerBody),
    ] {
        let frames = 5;
        let (sim, kept, dt_ns) = refreshed(name, frames);
        let w = sim.world();
        assert_eq!(Style::for_bodies(w.len()), style, "{name}");
        let layers = &sim.scenario().world.layers;
        let t = frames * dt_ns;
        for (topic, statics) in [("/scene", false), ("/scene/static", true)] {
            let live = kept.live(topic);
            assert_eq!(live.len(), 1, "{name} {topic}: one live message");
            let want = scene::snapshot(w, layers, statics, style, timestamp(t));
            assert_eq!(live[0].2, t, "{name} {topic}");
            assert!(
                live[0].3 == prost::Message::encode_to_vec(&want),
                "{name} {topic}: the bytes are prost's"
            );
        }
        // The moving bodies are all drawn: every asteroid is in the live /scene.
        let movers = (0..w.len()).filter(|&i| w.kind[i] != ricochet_sim::BodyKind::Static);
        assert!(movers.count() >= 20, "{name}");
    }
}

#[test]
fn stepping_stopped_sends_the_skipped_drawing_to_live_viewers_only() {
    // The server stops drawing `/scene` while its viewers are behind
    // (`Recorder::draw_moving`): after frame 9, the drawings due (every 13th frame or so,
    // `pace.rs`) are skipped.
    let last = 40;
    let scenario = Scene::parse("asteroids-2000").unwrap().build(last);
    let dt = scenario.world.dt;
    let mut recorder = Recorder::new(Kept::default(), dt, Channels::default()).unwrap();
    let mut sim = Simulation::new(&scenario);
    for frame in 0..=last {
        recorder.draw_moving(frame < 10);
        let out = sim.step();
        recorder.record(&sim, &out).unwrap();
    }
    let recorded = |k: &Kept| k.written.iter().filter(|w| !w.0).count();
    let dt_ns = recorder.dt_ns();
    let before = recorded(recorder.sink_mut());
    recorder.show_moving_live(&sim, last).unwrap();
    // Once: the drawing is sent now.
    recorder.show_moving_live(&sim, last).unwrap();
    let kept = recorder.into_sink();
    assert_eq!(recorded(&kept), before, "nothing more recorded");
    let live = kept.live("/scene");
    assert_eq!(live.len(), 1);
    assert_eq!(live[0].2, last * dt_ns);
    let w = sim.world();
    let layers = &sim.scenario().world.layers;
    let want = scene::snapshot(w, layers, false, Style::Batched, timestamp(last * dt_ns));
    assert!(live[0].3 == prost::Message::encode_to_vec(&want));
}
