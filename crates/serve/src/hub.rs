//! The live side of `ricochet serve`: the channels, the connected clients and what each
//! subscribed to, shared between the simulation thread (which publishes every frame's
//! messages) and the WebSocket tasks (which add and drop clients and subscriptions).
//!
//! Publishing never waits on a client: each has a queue bounded in bytes
//! ([`CLIENT_BUDGET`]). On a whole-state topic ([`LATEST`]: `/scene`, `/scene/static`,
//! `/tf`, `/scene/contacts`) a client's queue holds at most the latest undelivered message:
//! a newer one replaces the queued older one in place, so a slow viewer gets the latest
//! state, not a backlog; and each is written at most at [`STATE_RATE`] bytes a second (a
//! browser viewer drains its socket faster than it can draw). On the other topics a message that does not fit is dropped whole
//! for that client (counted, and the client is told once by a status message when it
//! catches up, and sent the latest `/scene` again if it missed one). The simulation and
//! the recording never lose a frame.

use std::collections::{BTreeMap, BTreeSet};
use std::sync::{Arc, Mutex, MutexGuard};

use tokio_tungstenite::tungstenite::Message;

use crate::protocol::{self, Channel};

pub use crate::queue::{CLIENT_BUDGET, ClientQueue, Latest, STATE_RATE, client_queue};

/// Channels one client may advertise (`clientPublish`): Foxglove's panels advertise a few
/// (the 3D panel's click tools, a Publish panel each); more are refused with a status, so
/// their memory is bounded.
pub const MAX_CLIENT_CHANNELS: usize = 256;

/// Topics whose last message is sent again to a client that subscribes: each is a whole
/// state (`/scene` and `/scene/static` are sent only when their bodies change, `/tf`, the
/// camera's frame, only when it moves).
const LATCHED: [&str; 3] = ["/scene", "/scene/static", "/tf"];

/// Topics each of whose messages is a whole state replacing the one before: a client's
/// queue holds at most the latest undelivered one of each (see [`ClientQueue::offer_latest`]).
/// What a viewer that can't keep up wants is the latest state, not a backlog (Foxglove's
/// SDK keeps the latest too). The other topics (`/bodies` deltas, `/events`, `/stats`,
/// `/contacts`, ...) are queued in order and dropped past the budget.
pub const LATEST: [&str; 4] = ["/scene", "/scene/static", "/tf", "/scene/contacts"];

/// Inputs waiting for the next frame, from all clients, beyond which new ones are refused.
pub const MAX_PENDING_INPUTS: usize = 10_000;

/// Clicked points waiting for the simulation loop, from all clients, beyond which new ones
/// are refused (each is answered between frames, so a few are ever waiting).
pub const MAX_PENDING_CLICKS: usize = 64;

/// The topic Lichtblick's 3D panel publishes its "publish point" clicks on (its default).
pub const CLICKED_POINT: &str = "/clicked_point";

/// What a client's channel carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Publication {
    /// Inputs (`/input`, JSON).
    Input,
    /// Clicked points (`/clicked_point`, JSON: Lichtblick's `geometry_msgs/PointStamped`).
    Click,
    /// Anything else (the 3D panel's pose tools, a Publish panel): advertised, refused.
    Other,
}

/// One connected client.
struct Client {
    queue: ClientQueue,
    /// Its channels, by its id.
    publishes: BTreeMap<u32, Publication>,
    /// By channel id: the client's subscription id.
    subscriptions: BTreeMap<u32, u32>,
    /// Messages dropped since it was last told.
    dropped: u64,
    /// Latched channels whose message was dropped for it: sent again when it catches up.
    stale: BTreeSet<u32>,
    /// Ends its connection, saying why (a room that closes).
    kick: Option<tokio::sync::oneshot::Sender<String>>,
}

/// Everything the simulation thread and the connections share.
#[derive(Default)]
pub struct Shared {
    channels: Vec<Channel>,
    /// The last message of each latched channel: (time, payload).
    latched: BTreeMap<u32, (u64, Vec<u8>)>,
    clients: BTreeMap<u64, Client>,
    next_client: u64,
    /// Inputs in the order they came, with the client that sent each: the next frame takes
    /// them all.
    pub inputs: std::collections::VecDeque<(u64, String)>,
    /// Clicked points in the order they came (the JSON, not yet read), with the client that
    /// sent each: answered between frames, never applied to the simulation.
    pub clicks: std::collections::VecDeque<(u64, Vec<u8>)>,
    /// Service calls in the order they came, with the client that made each.
    pub calls: std::collections::VecDeque<(u64, protocol::ServiceCall)>,
    /// Playback-control requests in the order they came, with the client that made each.
    pub playback: std::collections::VecDeque<(u64, protocol::PlaybackControl)>,
    /// The timeline's end, ns (the scenario's last frame), for `serverInfo`.
    pub data_end_ns: u64,
    /// Messages dropped for slow clients, in all.
    pub dropped: u64,
    /// A room's: the clients that disconnected since the room last looked (its players
    /// leave), kept only when set.
    pub track_leaves: bool,
    /// The clients that disconnected (with [`Shared::track_leaves`]), in order.
    pub left: Vec<u64>,
    /// Inputs waiting beyond which new ones are refused, if not [`MAX_PENDING_INPUTS`] (a
    /// room's cap is smaller: there are many rooms).
    pub input_cap: Option<usize>,
    /// The room closed: no client connects any more.
    pub closed: bool,
}

/// A handle on the shared state.
#[derive(Clone, Default)]
pub struct Hub(Arc<Mutex<Shared>>);

impl Hub {
    /// The shared state (a poisoned lock is recovered: the state stays consistent).
    pub fn lock(&self) -> MutexGuard<'_, Shared> {
        self.0
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }
}

impl Shared {
    /// The advertised channels.
    pub fn channels(&self) -> &[Channel] {
        &self.channels
    }

    /// A new client with its outgoing queue; returns its id, and what tells its connection
    /// to end (see [`Shared::close_all`]).
    pub fn connect(&mut self, queue: ClientQueue) -> (u64, tokio::sync::oneshot::Receiver<String>) {
        let (kick, kicked) = tokio::sync::oneshot::channel();
        let id = self.next_client;
        self.next_client += 1;
        self.clients.insert(
            id,
            Client {
                queue,
                publishes: BTreeMap::new(),
                subscriptions: BTreeMap::new(),
                dropped: 0,
                stale: BTreeSet::new(),
                kick: Some(kick),
            },
        );
        (id, kicked)
    }

    /// Ends every client's connection: a status saying `why` (level 2), then a close frame
    /// with it; no client connects after.
    pub fn close_all(&mut self, why: &str) {
        self.closed = true;
        for c in self.clients.values_mut() {
            let status = protocol::ServerMessage::Status {
                level: 2,
                message: why,
            };
            let _ = c.queue.answer(Message::text(status.json()));
            if let Some(kick) = c.kick.take() {
                let _ = kick.send(why.to_owned());
            }
        }
    }

    /// Whether some client subscribes to `topic` (a room nobody records builds only what
    /// is watched).
    pub fn watched(&self, topic: &str) -> bool {
        self.any_subscriber(topic, |_, _| true)
    }

    /// Whether some client subscribed to `topic` passes `test` (given with the channel).
    fn any_subscriber(&self, topic: &str, test: impl Fn(&Client, u32) -> bool) -> bool {
        self.channels
            .iter()
            .find(|c| c.topic == topic)
            .is_some_and(|c| {
                self.clients
                    .values()
                    .any(|k| k.subscriptions.contains_key(&c.id) && test(k, c.id))
            })
    }

    /// Whether some client subscribed to the whole-state `topic` wants a newer state by
    /// `by` (the next frame's start; see [`ClientQueue::wants_latest`]).
    pub fn state_wanted(&self, topic: &str, by: std::time::Instant) -> bool {
        let by = tokio::time::Instant::from_std(by);
        self.any_subscriber(topic, |k, channel| k.queue.wants_latest(channel, by))
    }

    /// Whether the frame about to be stepped, which ends `period` from now, must draw
    /// `/scene`: some subscriber is due a newer state by then ([`Self::state_wanted`]); a
    /// client paced by its bytes, or one that stopped reading, makes no drawing it would not
    /// be sent. A `period` so long that no `Instant` holds its end: whether any client
    /// watches `/scene` (whatever is due comes before it). `serve` and unrecorded rooms
    /// draw by this.
    pub fn scene_due(&self, period: std::time::Duration) -> bool {
        match std::time::Instant::now().checked_add(period) {
            Some(by) => self.state_wanted("/scene", by),
            None => self.watched("/scene"),
        }
    }

    /// How many clients are connected.
    pub fn client_count(&self) -> usize {
        self.clients.len()
    }

    /// Forgets a client.
    pub fn disconnect(&mut self, client: u64) {
        if self.clients.remove(&client).is_some() && self.track_leaves {
            self.left.push(client);
        }
    }

    /// Subscribes `client` to `channel` as `subscription`; an unknown channel is an error
    /// message for the client. A latched channel's last message is sent at once.
    pub fn subscribe(
        &mut self,
        client: u64,
        subscription: u32,
        channel: u32,
    ) -> Result<(), String> {
        if !self.channels.iter().any(|c| c.id == channel) {
            return Err(format!("no channel {channel}"));
        }
        let latched = self.latched.get(&channel).cloned();
        if let Some(c) = self.clients.get_mut(&client) {
            c.subscriptions.insert(channel, subscription);
            if let Some((time, payload)) = latched {
                let data = protocol::message_data(subscription, time, &payload);
                match c.queue.offer_latest(channel, Message::binary(data)) {
                    // Replaced: the client subscribed again (a viewer applying its layout
                    // does) before the copy sent at its first subscription was written; it
                    // gets the latest instead, and missed nothing.
                    Latest::Queued | Latest::Thinned | Latest::Replaced => {}
                    Latest::Dropped => {
                        c.dropped += 1;
                        c.stale.insert(channel);
                    }
                }
            }
        }
        Ok(())
    }

    /// `client` will publish on its channel `id`. Any channel may be advertised (Foxglove's
    /// 3D panel advertises its click tools' topics); only messages on `/input` and
    /// [`CLICKED_POINT`] in JSON are taken, others are refused when they come. Past
    /// [`MAX_CLIENT_CHANNELS`] a new channel is refused (an error for the client's status).
    pub fn advertise(
        &mut self,
        client: u64,
        id: u32,
        topic: &str,
        encoding: &str,
    ) -> Result<(), String> {
        let publication = match (topic, encoding) {
            ("/input", "json") => Publication::Input,
            (CLICKED_POINT, "json") => Publication::Click,
            _ => Publication::Other,
        };
        if let Some(c) = self.clients.get_mut(&client) {
            if c.publishes.len() >= MAX_CLIENT_CHANNELS && !c.publishes.contains_key(&id) {
                return Err(format!(
                    "advertise: channel {id} refused, a client may advertise at most \
                     {MAX_CLIENT_CHANNELS} channels (unadvertise some first)"
                ));
            }
            c.publishes.insert(id, publication);
        }
        Ok(())
    }

    /// `client` stops publishing on `ids`.
    pub fn unadvertise(&mut self, client: u64, ids: &[u32]) {
        if let Some(c) = self.clients.get_mut(&client) {
            c.publishes.retain(|id, _| !ids.contains(id));
        }
    }

    /// A message `client` published on its channel `channel`: an input, queued for the next
    /// frame, or a clicked point, queued for the loop's next look at its clients.
    pub fn input(&mut self, client: u64, channel: u32, payload: &[u8]) -> Result<(), String> {
        let advertised = self
            .clients
            .get(&client)
            .and_then(|c| c.publishes.get(&channel).copied());
        if advertised == Some(Publication::Click) {
            if payload.len() > ricochet_record::session::MAX_INPUT {
                return Err(format!(
                    "a clicked point of {} bytes, more than {}",
                    payload.len(),
                    ricochet_record::session::MAX_INPUT
                ));
            }
            if self.clicks.len() >= MAX_PENDING_CLICKS {
                return Err("too many clicked points waiting".to_owned());
            }
            self.clicks.push_back((client, payload.to_vec()));
            return Ok(());
        }
        if advertised != Some(Publication::Input) {
            return Err(format!(
                "channel {channel} is not an advertised /input channel, nor {CLICKED_POINT} (both JSON)"
            ));
        }
        if payload.len() > ricochet_record::session::MAX_INPUT {
            return Err(format!(
                "an input of {} bytes, more than {}",
                payload.len(),
                ricochet_record::session::MAX_INPUT
            ));
        }
        if self.inputs.len() >= self.input_cap.unwrap_or(MAX_PENDING_INPUTS) {
            return Err("too many inputs waiting for the next frame".to_owned());
        }
        let text = std::str::from_utf8(payload).map_err(|_| "an input that is not UTF-8")?;
        self.inputs.push_back((client, text.to_owned()));
        Ok(())
    }

    /// A service call from `client`, queued for the next frame boundary.
    pub fn call(&mut self, client: u64, call: protocol::ServiceCall) -> Result<(), String> {
        if self.calls.len() >= 64 {
            return Err("too many service calls waiting".to_owned());
        }
        self.calls.push_back((client, call));
        Ok(())
    }

    /// Sends the playback state to every client.
    pub fn playback_state(&mut self, state: Vec<u8>) {
        let state = Message::binary(state);
        for c in self.clients.values_mut() {
            if !c.queue.answer(state.clone()) {
                c.dropped += 1;
            }
        }
    }

    /// Answers `client`'s call: its JSON response, or why it failed.
    pub fn answer(&mut self, client: u64, service: u32, call: u32, result: Result<String, String>) {
        let Some(c) = self.clients.get_mut(&client) else {
            return;
        };
        let message = match result {
            Ok(json) => Message::binary(protocol::service_response(service, call, json.as_bytes())),
            Err(why) => Message::text(
                protocol::ServerMessage::ServiceCallFailure {
                    service_id: service,
                    call_id: call,
                    message: &why,
                }
                .json(),
            ),
        };
        let _ = c.queue.answer(message);
    }

    /// Tells `client` something (a status message), if it is still there.
    pub fn tell(&mut self, client: u64, level: u8, text: &str) {
        if let Some(c) = self.clients.get_mut(&client) {
            let status = protocol::ServerMessage::Status {
                level,
                message: text,
            };
            let _ = c.queue.answer(Message::text(status.json()));
        }
    }

    /// Ends `client`'s subscriptions `ids`.
    pub fn unsubscribe(&mut self, client: u64, ids: &[u32]) {
        if let Some(c) = self.clients.get_mut(&client) {
            c.subscriptions.retain(|_, sub| !ids.contains(sub));
        }
    }

    /// Sends `data` to every client (the time, a status), dropping it for full queues.
    pub fn broadcast(&mut self, data: &Message) {
        for c in self.clients.values_mut() {
            if !c.queue.offer(data.clone()) {
                c.dropped += 1;
            }
        }
    }

    /// Publishes a message on `channel` to its subscribers.
    /// The id of the channel on `topic`, added (as `make` builds it from its id) if there is
    /// none: a new session (after a reset) adds the same topics, and they keep their ids,
    /// and the clients their subscriptions.
    pub(crate) fn channel(&mut self, topic: &str, make: impl FnOnce(u32) -> Channel) -> u32 {
        if let Some(c) = self.channels.iter().find(|c| c.topic == topic) {
            return c.id;
        }
        let id = self.channels.len() as u32 + 1;
        self.channels.push(make(id));
        id
    }

    pub(crate) fn publish(&mut self, channel: u32, time_ns: u64, payload: Vec<u8>) {
        let mut dropped = 0;
        let topic = self.channels.iter().find(|c| c.id == channel);
        let latched = topic.is_some_and(|c| LATCHED.contains(&c.topic.as_str()));
        let latest = topic.is_some_and(|c| LATEST.contains(&c.topic.as_str()));
        // One message per subscription id, shared by the clients that chose the same id (two
        // viewers of one layout do): its bytes are copied once, not once per client.
        let mut built: BTreeMap<u32, Message> = BTreeMap::new();
        for c in self.clients.values_mut() {
            let Some(&sub) = c.subscriptions.get(&channel) else {
                continue;
            };
            let data = built
                .entry(sub)
                .or_insert_with(|| Message::binary(protocol::message_data(sub, time_ns, &payload)))
                .clone();
            let queued = if latest {
                match c.queue.offer_latest(channel, data) {
                    Latest::Queued | Latest::Thinned => true,
                    Latest::Replaced => {
                        // The latest is queued; the older state it replaced is lost: counted
                        // in the server's tally, but the client is not told it was too slow
                        // (it gets the latest state, which is what it subscribed to).
                        dropped += 1;
                        true
                    }
                    Latest::Dropped => false,
                }
            } else {
                c.queue.offer(data)
            };
            if !queued {
                c.dropped += 1;
                dropped += 1;
                if latched {
                    c.stale.insert(channel);
                }
                continue;
            }
            if latched {
                c.stale.remove(&channel);
            }
            // It caught up (half its budget free): say how much it missed, and send again
            // the latest state of the latched channels it missed.
            if c.dropped > 0 && c.queue.queued() < CLIENT_BUDGET / 2 {
                let text = format!(
                    "this client was too slow: {} messages were dropped for it",
                    c.dropped
                );
                let status = protocol::ServerMessage::Status {
                    level: 1,
                    message: &text,
                };
                if c.queue.answer(Message::text(status.json())) {
                    c.dropped = 0;
                }
                for stale in std::mem::take(&mut c.stale) {
                    let (Some(&sub), Some((time, payload))) =
                        (c.subscriptions.get(&stale), self.latched.get(&stale))
                    else {
                        continue;
                    };
                    let data = protocol::message_data(sub, *time, payload);
                    if c.queue.offer_latest(stale, Message::binary(data)) == Latest::Dropped {
                        c.stale.insert(stale);
                    }
                }
            }
        }
        self.dropped += dropped;
        if latched {
            self.latched.insert(channel, (time_ns, payload));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::queue::client_queue;

    /// A client subscribing again to a whole-state topic before the state sent at its first
    /// subscription was written (Lichtblick does, applying its layout) gets the latest in
    /// its place: it missed nothing, so nothing is counted against it.
    #[test]
    fn subscribing_again_to_a_whole_state_drops_nothing() {
        let hub = Hub::default();
        let mut s = hub.lock();
        s.channels
            .push(Channel::json(1, "/scene/static", "x", "{}"));
        s.publish(1, 0, b"{}".to_vec());
        let (queue, _receiver) = client_queue();
        let (id, _kicked) = s.connect(queue);
        s.subscribe(id, 7, 1).unwrap();
        s.subscribe(id, 8, 1).unwrap();
        assert_eq!(s.clients[&id].dropped, 0);
    }

    /// A whole state replaced in a client's queue before it was written (a client a frame
    /// behind) is counted in the server's tally of messages dropped, and the client is not
    /// sent a "too slow" status for it: it gets the latest state, as documented. The real
    /// viewer showed that status as a problem on small scenes whenever the machine was busy.
    #[test]
    fn a_replaced_state_is_tallied_but_not_told_to_the_client() {
        let hub = Hub::default();
        let mut s = hub.lock();
        s.channels.push(Channel::json(1, "/scene", "x", "{}"));
        let (queue, _receiver) = client_queue();
        let (id, _kicked) = s.connect(queue);
        s.subscribe(id, 7, 1).unwrap();
        s.publish(1, 0, b"{}".to_vec());
        s.publish(1, 1, b"{}".to_vec());
        assert_eq!((s.clients[&id].dropped, s.dropped), (0, 1));
    }
}
