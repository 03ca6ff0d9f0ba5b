//! Drawing `/scene` only when a client will be sent it: not recording, a live client's whole
//! states are paced by their bytes ([`crate::hub::STATE_RATE`]), so a 10,000-body scene
//! (1.5 MB) goes to a viewer about once a second; drawing and encoding it in every frame
//! for that was most of the frame's time (BENCHMARKS.md, "Live at 10,000 bodies").

use std::time::Duration;

use super::Serving;
use crate::common::ServeError;
use crate::hub::Hub;

impl Serving {
    /// Whether the next frame draws `/scene`: always when recording (the file gets every
    /// frame, byte for byte); else only when some client is due a newer one before the frame
    /// after it starts (see [`crate::hub::ClientQueue::wants_latest`]), and never in a seek
    /// (muted: its last frame is sent whole when it is done). What a client is sent is
    /// unchanged: the state of the last frame before its channel is due.
    pub(super) fn choose_drawing(&mut self, hub: &Hub) {
        if self.record.is_some() {
            return;
        }
        let muted = self.session.recorder().sink_mut().muted;
        let period = Duration::try_from_secs_f64(self.scenario.world.dt / self.speed)
            .unwrap_or(Duration::MAX);
        let draw = !muted && hub.lock().scene_due(period);
        self.session.recorder().draw_moving(draw);
    }

    /// Sends the last frame stepped's `/scene`, if it was not drawn: stepping stopped
    /// (paused, a `/step` done), so no later frame will draw it. Not after an overflow (the
    /// simulation holds the frame that overflowed, which no client is sent).
    pub fn show_last(&mut self) -> Result<(), ServeError> {
        if self.session.overflowed().is_none() {
            self.session.show_moving_live()?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use tokio_tungstenite::tungstenite::Message;

    use super::super::{PlainOptions, Serving};
    use crate::hub::{ClientQueue, Hub, Latest, STATE_RATE, client_queue};
    use crate::protocol;
    use crate::queue::ClientQueueReceiver;
    use crate::sink::start;

    /// Two asteroids drifting in a bounded world (so the camera's frame stays put): each
    /// frame writes `/bodies`, `/contacts` and `/stats`, and `/scene` when drawn (they
    /// move); no contact, no event, no static body.
    const DRIFT: &str = r#"
name = "drift"
hz = 60
frames = 600
layers = ["rock"]

[world]
gravity = [0, 0]
bounds = { min = [0, 0], max = [100.0, 100.0], wrap = true }

[[collide]]
a = "rock"
b = "rock"
response = "ignore"

[[bodies]]
name = "a"
layer = "rock"
shape = { kind = "circle", radius = 1.0 }
position = [20.0, 20.0]
velocity = [1.0, 0.5]

[[bodies]]
name = "b"
layer = "rock"
shape = { kind = "circle", radius = 1.0 }
position = [60.0, 60.0]
velocity = [-1.0, 0.25]
"#;

    /// Messages built per frame besides `/scene`: `/bodies`, `/contacts`, `/stats`.
    const OTHERS: u64 = 3;

    fn serving() -> (Serving, Hub) {
        let scenario = ricochet_sim::load_scenario(DRIFT, "drift.toml").unwrap();
        let hub = Hub::default();
        let session = start(&scenario, "", &hub, None, 0).unwrap();
        let plain = PlainOptions {
            speed: 1.0,
            paused: false,
            frames: None,
            record: None,
            note: Arc::new(|_: &str| {}),
        };
        let mut serving = Serving::new(session, scenario, String::new(), plain);
        // Frame 0 sends the camera's frame once.
        serving.frame(&hub).unwrap();
        (serving, hub)
    }

    fn scene_channel(hub: &Hub) -> u32 {
        let s = hub.lock();
        s.channels()
            .iter()
            .find(|c| c.topic == "/scene")
            .unwrap()
            .id
    }

    /// A client subscribed to `/scene` as subscription 7.
    fn client(hub: &Hub) -> (ClientQueue, ClientQueueReceiver) {
        let (queue, rx) = client_queue();
        let channel = scene_channel(hub);
        let mut s = hub.lock();
        let (id, _kicked) = s.connect(queue.clone());
        s.subscribe(id, 7, channel).unwrap();
        (queue, rx)
    }

    /// A client whose connection just wrote a 20 MB scene: its next is due in 10 s at
    /// [`STATE_RATE`] (2 MB/s), far longer than this test.
    fn paced_client(hub: &Hub) -> (ClientQueue, ClientQueueReceiver) {
        let (queue, mut rx) = client(hub);
        let big = Message::binary(vec![0u8; 20_000_000]);
        const { assert!(20e6 / STATE_RATE >= 10.0) };
        assert_eq!(queue.offer_latest(scene_channel(hub), big), Latest::Queued);
        assert_eq!(rx.ready().map(|m| m.len()), Some(20_000_000));
        // Asking again is what tells the queue it was written.
        assert!(rx.ready().is_none());
        (queue, rx)
    }

    /// Messages the recorder built in `n` frames; `read` drains the receivers after each
    /// frame, as a connection writing at once does.
    fn built_in(
        serving: &mut Serving,
        hub: &Hub,
        n: u64,
        read: &mut [&mut ClientQueueReceiver],
    ) -> u64 {
        let before = serving.session.recorder().built();
        for _ in 0..n {
            serving.frame(hub).unwrap();
            for rx in read.iter_mut() {
                while rx.ready().is_some() {}
            }
        }
        serving.session.recorder().built() - before
    }

    /// The times of the `/scene` messages (subscription 7) a receiver holds, paced or not.
    fn scene_times(rx: &mut ClientQueueReceiver) -> Vec<u64> {
        let mut got = Vec::new();
        while let Ok(m) = rx.try_recv() {
            let data = m.into_data();
            if data.first() == Some(&protocol::OP_MESSAGE_DATA) && data[1..5] == 7u32.to_le_bytes()
            {
                got.push(u64::from_le_bytes(data[5..13].try_into().unwrap()));
            }
        }
        got
    }

    /// Not recording, `/scene` is drawn only in the frames some client is due one: none for
    /// nobody, none for a client whose pace holds its next back, one a frame for a client
    /// that reads every one, and one in all for a client that never reads (its queue holds
    /// that one; a newer one would only replace it).
    #[test]
    fn the_scene_is_drawn_only_when_a_client_is_due_one() {
        let (mut serving, hub) = serving();
        assert_eq!(
            built_in(&mut serving, &hub, 10, &mut []),
            10 * OTHERS,
            "nobody"
        );
        let (_paced, mut paced_rx) = paced_client(&hub);
        assert_eq!(
            built_in(&mut serving, &hub, 10, &mut [&mut paced_rx]),
            10 * OTHERS,
            "a client paced for 10 s"
        );
        let (_stuck, _stuck_rx) = client(&hub);
        assert_eq!(
            built_in(&mut serving, &hub, 10, &mut [&mut paced_rx]),
            10 * OTHERS + 1,
            "and a client that never reads"
        );
        let (_reader, mut reader_rx) = client(&hub);
        // Its connection writes at once the scene it was sent on subscribing (the last
        // drawn, for the client that never reads).
        assert_eq!(scene_times(&mut reader_rx).len(), 1);
        assert_eq!(
            built_in(&mut serving, &hub, 10, &mut [&mut paced_rx, &mut reader_rx]),
            10 * (OTHERS + 1),
            "and a client that reads every scene"
        );
    }

    /// Stepping stopped after frames whose `/scene` was not drawn: the last one is sent
    /// whole, once, to the client waiting for it.
    #[test]
    fn the_last_frame_undrawn_is_sent_when_stepping_stops() {
        let (mut serving, hub) = serving();
        let (_paced, mut rx) = paced_client(&hub);
        assert_eq!(built_in(&mut serving, &hub, 3, &mut []), 3 * OTHERS);
        assert_eq!(scene_times(&mut rx), Vec::<u64>::new());
        serving.show_last().unwrap();
        let dt_ns = serving.session.dt_ns();
        // Frames 0 to 3 stepped: frame 3's scene.
        assert_eq!(scene_times(&mut rx), [3 * dt_ns]);
        serving.show_last().unwrap();
        assert_eq!(scene_times(&mut rx), Vec::<u64>::new(), "sent once");
    }
}
