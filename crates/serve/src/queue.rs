//! A client's outgoing queue: bounded in bytes ([`CLIENT_BUDGET`]), in order, but for
//! whole-state messages, each of which replaces, in its place, its channel's message still
//! waiting (see [`ClientQueue::offer_latest`]), and is written at most at [`STATE_RATE`]
//! (held back until due, while newer states replace it).

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Duration;

use tokio::time::Instant;

use tokio::sync::mpsc;
use tokio_tungstenite::tungstenite::Message;

/// Bytes of messages queued for one client before new ones are dropped for it: 8 MiB, a
/// few frames of a scene of thousands of bodies (a 3,000-body frame is about 0.3 MB). A
/// message larger than the budget is queued only when the queue is empty, so a client holds
/// at most `max(CLIENT_BUDGET, its largest message)` (plus the one being written), and a
/// newer whole state replacing a queued one may pass it by their difference: at most one
/// message per whole-state channel more.
///
/// Dropping whole messages, not disconnecting: each message on a channel is whole (a pose
/// set, a stats record, a scene), so a viewer that missed some shows the next ones right;
/// a stall of a second (a tab in the background) should not cost the connection. The
/// latched `/scene` is sent again when it catches up.
pub const CLIENT_BUDGET: usize = 8 << 20;

/// Room beyond the budget for the server's answers (status, service responses, playback
/// states: small, and a client waits for them), so they are not lost with the data.
const ANSWER_ROOM: usize = 1 << 20;

/// What one queued message is counted as beyond its payload: the queue's slot and the
/// message's allocation (so a flood of tiny messages is bounded too).
const MESSAGE_OVERHEAD: usize = 64;

/// Bytes a second of one whole-state channel (`/scene`, ...) written to one client at most:
/// after writing a state of `n` bytes, the server waits `n / STATE_RATE` before the
/// channel's next (newer states replace it meanwhile). 2 MB/s: a 10,000-body `/scene`
/// (about 1.5 MB) goes about once a second, a 2,000-body one (0.3 MB) 6 times, a 250-body
/// one every frame at 60 Hz. A browser viewer (Lichtblick) decodes and draws every scene it
/// is sent, and its socket drains as fast as the server writes, so the connection's own
/// pace does not hold it back: on the project's 2-core machine it froze at 90 MB/s (every
/// 10,000-body frame) and at 8 MB/s, lagged by seconds at 4 MB/s, and kept up at 2 MB/s
/// (BENCHMARKS.md, "Live at 10,000 bodies").
pub const STATE_RATE: f64 = 2e6;

/// A state held back by its channel's pace ([`STATE_RATE`]) that was due this long ago and
/// is still not taken: the connection is not draining (one that drains takes it when it is
/// due), so it counts as waiting to be written, and the server stops drawing newer states
/// for that client (it only replaced them, unsent). A second: far longer than any frame.
pub const STALLED: Duration = Duration::from_secs(1);

/// A queued message whose content a newer one may replace until it is written: the
/// latest state of one channel.
type Slot = Arc<Mutex<Held>>;

/// What a [`Slot`] holds.
#[derive(Default)]
struct Held {
    message: Option<Message>,
    /// Held back by [`STATE_RATE`]: a newer state replacing it is thinning, not loss.
    paced: bool,
}

/// One entry of a client's queue.
enum Queued {
    /// Written as it is, in order.
    Message(Message),
    /// Written with whatever the slot holds when its turn comes (and its channel's pace
    /// allows).
    Latest(u32, Slot),
}

/// A client's outgoing queue: unbounded in count, bounded in bytes by [`CLIENT_BUDGET`]
/// (the connection's task gives the bytes back as it writes each message).
#[derive(Clone)]
pub struct ClientQueue {
    sender: mpsc::UnboundedSender<Queued>,
    queued: Arc<AtomicUsize>,
    /// By channel id: the slot of its latest message, still queued if the slot is full
    /// (one per whole-state channel, so bounded by the channel count).
    latest: Arc<Mutex<BTreeMap<u32, Slot>>>,
    /// By whole-state channel: when its next state may be written (the receiver's pace),
    /// for [`ClientQueue::wants_latest`].
    due: Due,
}

/// By whole-state channel: when its next state may be written, shared by a client's queue
/// and its receiver (one entry per such channel, so bounded by the channel count).
type Due = Arc<Mutex<BTreeMap<u32, Instant>>>;

/// The connection's end of a [`ClientQueue`].
pub struct ClientQueueReceiver {
    receiver: mpsc::UnboundedReceiver<Queued>,
    queued: Arc<AtomicUsize>,
    /// By whole-state channel: when its next state may be written.
    due: Due,
    /// By whole-state channel: its slot, held back until due (still replaced in place).
    paced: BTreeMap<u32, Slot>,
    /// The whole state last returned (channel, bytes): written once the next is asked for.
    writing: Option<(u32, usize)>,
}

/// A new queue for one client.
pub fn client_queue() -> (ClientQueue, ClientQueueReceiver) {
    let (sender, receiver) = mpsc::unbounded_channel();
    let queued = Arc::new(AtomicUsize::new(0));
    let due = Due::default();
    (
        ClientQueue {
            sender,
            queued: Arc::clone(&queued),
            latest: Arc::default(),
            due: Arc::clone(&due),
        },
        ClientQueueReceiver {
            receiver,
            queued,
            due,
            paced: BTreeMap::new(),
            writing: None,
        },
    )
}

/// Locks `m`, recovering from poison (the guarded values stay consistent: each is replaced
/// whole).
fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// The bytes a message is counted as.
fn weight(message: &Message) -> usize {
    message.len() + MESSAGE_OVERHEAD
}

impl ClientQueue {
    /// Queues a data message if it fits the budget; `false` if it was dropped.
    pub fn offer(&self, message: Message) -> bool {
        self.offer_within(message, CLIENT_BUDGET)
    }

    /// Queues one of the server's answers (status, service response, playback state), which
    /// may use [`ANSWER_ROOM`] beyond the budget; `false` if it was dropped.
    pub fn answer(&self, message: Message) -> bool {
        self.offer_within(message, CLIENT_BUDGET + ANSWER_ROOM)
    }

    /// Queues the latest whole state of `channel`: it replaces, in its place in the queue,
    /// the channel's message still waiting there, if any (a replacement always fits: the
    /// queue holds at most one message per such channel); else it is queued if it fits the
    /// budget.
    pub fn offer_latest(&self, channel: u32, message: Message) -> Latest {
        let mut latest = lock(&self.latest);
        if let Some(slot) = latest.get(&channel) {
            let mut held = lock(slot);
            if let Some(old) = held.message.as_ref() {
                // Add before taking away, so the count never underflows for the reader.
                self.queued.fetch_add(weight(&message), Ordering::AcqRel);
                self.queued.fetch_sub(weight(old), Ordering::AcqRel);
                held.message = Some(message);
                return if held.paced {
                    Latest::Thinned
                } else {
                    Latest::Replaced
                };
            }
        }
        let weight = weight(&message);
        if !self.fits(weight, CLIENT_BUDGET) {
            return Latest::Dropped;
        }
        let slot: Slot = Arc::new(Mutex::new(Held {
            message: Some(message),
            paced: false,
        }));
        self.queued.fetch_add(weight, Ordering::AcqRel);
        if self
            .sender
            .send(Queued::Latest(channel, Arc::clone(&slot)))
            .is_err()
        {
            self.queued.fetch_sub(weight, Ordering::AcqRel);
            return Latest::Dropped;
        }
        latest.insert(channel, slot);
        Latest::Queued
    }

    /// Whether `weight` more bytes fit `budget` (a message larger than the budget fits an
    /// empty queue).
    fn fits(&self, weight: usize, budget: usize) -> bool {
        let queued = self.queued.load(Ordering::Acquire);
        queued == 0 || queued + weight <= budget
    }

    fn offer_within(&self, message: Message, budget: usize) -> bool {
        let weight = weight(&message);
        // Producers hold the hub's lock, but for the client's own task (its statuses): two
        // may pass the check at once, so a queue may exceed its budget by one message.
        if !self.fits(weight, budget) {
            return false;
        }
        self.queued.fetch_add(weight, Ordering::AcqRel);
        if self.sender.send(Queued::Message(message)).is_err() {
            self.queued.fetch_sub(weight, Ordering::AcqRel);
            return false;
        }
        true
    }

    /// Whether a newer state of `channel` offered now would be written by `by`, or sooner:
    /// none is waiting to be written in its queue (one is, behind other messages or a
    /// socket that does not drain: it goes first, and whatever is built meanwhile would only
    /// replace it), and its pace ([`STATE_RATE`]) lets the channel's next state go by then.
    /// A state held back by the pace counts as none waiting: a newer one replaces it;
    /// unless it has been due for [`STALLED`] and is still not taken. The server builds a
    /// costly whole state (`/scene`) only when some client wants it.
    pub fn wants_latest(&self, channel: u32, by: Instant) -> bool {
        self.wants_latest_at(channel, Instant::now(), by)
    }

    /// [`ClientQueue::wants_latest`] asked at `now`.
    fn wants_latest_at(&self, channel: u32, now: Instant, by: Instant) -> bool {
        let due = lock(&self.due).get(&channel).copied();
        if let Some(slot) = lock(&self.latest).get(&channel) {
            let held = lock(slot);
            let stalled = due
                .and_then(|at| at.checked_add(STALLED))
                .is_some_and(|late| late <= now);
            if held.message.is_some() && (!held.paced || stalled) {
                return false;
            }
        }
        due.is_none_or(|at| at <= by)
    }

    /// Bytes queued now.
    pub fn queued(&self) -> usize {
        self.queued.load(Ordering::Acquire)
    }
}

impl ClientQueueReceiver {
    /// The next message to write (its bytes are given back to the budget), `None` once
    /// every sender is gone. A whole state whose channel is not yet due (by
    /// [`STATE_RATE`], from when the channel's last state was written: when this is called
    /// again) is held back, in its slot, and the messages after it go first.
    pub async fn recv(&mut self) -> Option<Message> {
        self.written(Instant::now());
        loop {
            let now = Instant::now();
            if let Some(message) = self.take_due(now) {
                return Some(message);
            }
            let wake = {
                let due = lock(&self.due);
                self.paced.keys().filter_map(|c| due.get(c)).min().copied()
            };
            let queued = match wake {
                Some(at) => tokio::select! {
                    biased;
                    queued = self.receiver.recv() => queued?,
                    () = tokio::time::sleep_until(at) => continue,
                },
                None => self.receiver.recv().await?,
            };
            if let Some(message) = self.take(queued, Instant::now()) {
                return Some(message);
            }
        }
    }

    /// The message [`recv`](Self::recv) would return now, without waiting, if any: paced
    /// the same way (a whole state not yet due stays held back). What a connection adds to
    /// the write it is making.
    pub fn ready(&mut self) -> Option<Message> {
        self.written(Instant::now());
        if let Some(message) = self.take_due(Instant::now()) {
            return Some(message);
        }
        loop {
            let queued = self.receiver.try_recv().ok()?;
            if let Some(message) = self.take(queued, Instant::now()) {
                return Some(message);
            }
        }
    }

    /// The next message if one is queued now, paced or not (a connection closing sends what
    /// it holds).
    pub fn try_recv(&mut self) -> Result<Message, mpsc::error::TryRecvError> {
        self.writing = None;
        loop {
            let queued = match self.receiver.try_recv() {
                Ok(queued) => queued,
                Err(e) => match self.paced.pop_first() {
                    Some((_, slot)) => match self.take_slot(&slot) {
                        Some(message) => return Ok(message),
                        None => continue,
                    },
                    None => return Err(e),
                },
            };
            let message = match queued {
                Queued::Message(message) => Some(self.taken(message)),
                Queued::Latest(_, slot) => self.take_slot(&slot),
            };
            if let Some(message) = message {
                return Ok(message);
            }
        }
    }

    /// The state returned last was written (at `now`): its channel's next is due after its
    /// bytes at [`STATE_RATE`].
    fn written(&mut self, now: Instant) {
        if let Some((channel, bytes)) = self.writing.take() {
            let wait = Duration::from_secs_f64(bytes as f64 / STATE_RATE);
            lock(&self.due).insert(channel, now + wait);
        }
    }

    /// A held-back state whose channel is due at `now`, if any.
    fn take_due(&mut self, now: Instant) -> Option<Message> {
        let channel = {
            let due = lock(&self.due);
            *self
                .paced
                .keys()
                .find(|c| due.get(c).is_none_or(|&at| at <= now))?
        };
        let slot = self.paced.remove(&channel)?;
        let message = self.take_slot(&slot)?;
        self.writing = Some((channel, message.len()));
        Some(message)
    }

    /// The message an entry holds now (its bytes given back to the budget); `None` for a
    /// slot already emptied, or held back until its channel is due.
    fn take(&mut self, queued: Queued, now: Instant) -> Option<Message> {
        match queued {
            Queued::Message(message) => Some(self.taken(message)),
            Queued::Latest(channel, slot) => {
                let held_back = lock(&self.due).get(&channel).is_some_and(|&at| at > now);
                if held_back {
                    lock(&slot).paced = true;
                    self.paced.insert(channel, slot);
                    return None;
                }
                let message = self.take_slot(&slot)?;
                self.writing = Some((channel, message.len()));
                Some(message)
            }
        }
    }

    /// A slot's message, if it still holds one (its bytes given back to the budget).
    fn take_slot(&self, slot: &Slot) -> Option<Message> {
        let message = lock(slot).message.take()?;
        Some(self.taken(message))
    }

    /// `message`, its bytes given back to the budget.
    fn taken(&self, message: Message) -> Message {
        self.queued.fetch_sub(weight(&message), Ordering::AcqRel);
        message
    }
}

/// What became of a whole state offered to a client ([`ClientQueue::offer_latest`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Latest {
    /// Queued.
    Queued,
    /// Queued in place of the channel's older state, which the client never gets (a
    /// message dropped for a slow client, counted as one).
    Replaced,
    /// Queued in place of the channel's older state held back by [`STATE_RATE`]: the
    /// client gets fewer, fresher states by design, not because it is slow (not counted).
    Thinned,
    /// Dropped: it did not fit the budget.
    Dropped,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn text(t: &str) -> Message {
        Message::text(t.to_owned())
    }

    #[test]
    fn a_newer_state_replaces_the_queued_one_in_place_and_others_keep_their_order() {
        let (queue, mut receiver) = client_queue();
        assert!(queue.offer(text("stats 1")));
        assert_eq!(queue.offer_latest(1, text("scene 1")), Latest::Queued);
        assert!(queue.offer(text("stats 2")));
        assert_eq!(queue.offer_latest(1, text("scene 2")), Latest::Replaced);
        assert_eq!(queue.offer_latest(2, text("tf 2")), Latest::Queued);
        assert!(queue.offer(text("stats 3")));
        assert_eq!(queue.offer_latest(1, text("scene 3")), Latest::Replaced);
        let mut got = Vec::new();
        while let Ok(m) = receiver.try_recv() {
            got.push(m.into_text().unwrap().to_string());
        }
        // scene 3 in scene 1's place; tf in its own.
        assert_eq!(got, ["stats 1", "scene 3", "stats 2", "tf 2", "stats 3"]);
        assert_eq!(queue.queued(), 0);
        // Once written, the channel's next state is queued anew, after what came before.
        assert!(queue.offer(text("stats 4")));
        assert_eq!(queue.offer_latest(1, text("scene 4")), Latest::Queued);
        let got: Vec<String> = std::iter::from_fn(|| receiver.try_recv().ok())
            .map(|m| m.into_text().unwrap().to_string())
            .collect();
        assert_eq!(got, ["stats 4", "scene 4"]);
        assert_eq!(queue.queued(), 0);
    }

    #[test]
    fn states_past_the_budget_take_one_place_while_other_messages_are_dropped() {
        let (queue, mut receiver) = client_queue();
        let big = |c: char| Message::text(c.to_string().repeat(CLIENT_BUDGET / 4));
        let mut taken = 0;
        for c in ['a', 'b', 'c', 'd', 'e', 'f', 'g', 'h'] {
            taken += usize::from(queue.offer(big(c)));
        }
        // Three fit beside each other (with their overhead, not four).
        assert_eq!(taken, 3);
        // A full queue takes no new state, but replaces one already queued.
        assert_eq!(queue.offer_latest(1, big('s')), Latest::Dropped);
        let (queue2, mut receiver2) = client_queue();
        assert_eq!(queue2.offer_latest(1, big('s')), Latest::Queued);
        for c in ['t', 'u', 'v', 'w', 'x', 'y', 'z'] {
            assert_eq!(queue2.offer_latest(1, big(c)), Latest::Replaced);
        }
        assert_eq!(queue2.queued(), weight(&big('z')));
        let got = receiver2.try_recv().unwrap().into_text().unwrap();
        assert!(got.starts_with('z'));
        assert!(receiver2.try_recv().is_err());
        assert_eq!(queue2.queued(), 0);
        let n = std::iter::from_fn(|| receiver.try_recv().ok()).count();
        assert_eq!(n, 3);
    }

    /// A whole state written holds its channel's next back for its bytes at
    /// [`STATE_RATE`] (4 MB: 2 s, far longer than this test between two calls): what was
    /// queued after the held state goes first, a newer state replaces the held one without
    /// counting as a drop, and a closing connection still gets it.
    #[tokio::test]
    async fn a_written_state_holds_its_channels_next_back_and_others_pass_it() {
        let (queue, mut receiver) = client_queue();
        let big = Message::binary(vec![0u8; 4_000_000]);
        assert_eq!(queue.offer_latest(1, big), Latest::Queued);
        assert_eq!(receiver.recv().await.unwrap().len(), 4_000_000);
        assert_eq!(queue.offer_latest(1, text("scene 2")), Latest::Queued);
        assert!(queue.offer(text("stats 2")));
        assert_eq!(queue.offer_latest(2, text("tf 2")), Latest::Queued);
        let got = receiver.recv().await.unwrap().into_text().unwrap();
        assert_eq!(got.as_str(), "stats 2");
        // Another channel has its own pace.
        let got = receiver.recv().await.unwrap().into_text().unwrap();
        assert_eq!(got.as_str(), "tf 2");
        assert_eq!(queue.offer_latest(1, text("scene 3")), Latest::Thinned);
        let got = receiver.try_recv().unwrap().into_text().unwrap();
        assert_eq!(got.as_str(), "scene 3");
        assert!(receiver.try_recv().is_err());
        assert_eq!(queue.queued(), 0);
    }

    /// A client wants a newer state of a channel when none waits in its queue to be
    /// written and its pace lets the next go by the time asked about: a state held back by
    /// the pace counts as none (a newer one replaces it).
    #[tokio::test]
    async fn a_client_wants_a_state_only_when_one_would_be_written_by_then() {
        let (queue, mut receiver) = client_queue();
        let now = Instant::now();
        assert!(queue.wants_latest(1, now), "never sent one");
        assert_eq!(
            queue.offer_latest(1, Message::binary(vec![0u8; 4_000_000])),
            Latest::Queued
        );
        assert!(!queue.wants_latest(1, now), "one waits, not yet written");
        assert_eq!(receiver.recv().await.unwrap().len(), 4_000_000);
        assert_eq!(queue.offer_latest(1, text("scene 2")), Latest::Queued);
        // Written: its next is due 2 s later, and scene 2 is held back till then.
        assert!(receiver.ready().is_none());
        let now = Instant::now();
        assert!(!queue.wants_latest(1, now));
        assert!(queue.wants_latest(1, now + Duration::from_secs(3)));
        assert!(
            queue.wants_latest(2, now),
            "another channel has its own pace"
        );
    }

    /// A state held back by the pace and not taken long after it was due (the connection
    /// stopped draining, say blocked in a write) counts as waiting: the server stops
    /// drawing for that client.
    #[tokio::test]
    async fn a_held_state_not_taken_long_after_it_was_due_is_waiting() {
        let (queue, mut receiver) = client_queue();
        assert_eq!(
            queue.offer_latest(1, Message::binary(vec![0u8; 4_000_000])),
            Latest::Queued
        );
        assert_eq!(receiver.recv().await.unwrap().len(), 4_000_000);
        assert_eq!(queue.offer_latest(1, text("scene 2")), Latest::Queued);
        assert!(
            receiver.ready().is_none(),
            "scene 2 is held back: due in 2 s"
        );
        let now = Instant::now();
        let frame = Duration::from_millis(16);
        // Due 2 s after it was written (4 MB at 2 MB/s); this test runs well within 1 s.
        let due = now + Duration::from_secs(2);
        assert!(
            !queue.wants_latest_at(1, now, now + frame),
            "not due by then"
        );
        assert!(
            queue.wants_latest_at(1, due, due + frame),
            "due: a newer one would be written in its place"
        );
        let late = due + STALLED + Duration::from_millis(100);
        assert!(
            !queue.wants_latest_at(1, late, late + frame),
            "due over a second ago and not taken: the connection is not draining"
        );
    }

    /// What a connection adds to a write without waiting ([`ClientQueueReceiver::ready`]) is
    /// paced as [`recv`](ClientQueueReceiver::recv) is: a state whose channel is not yet due
    /// stays held back while the messages after it go.
    #[tokio::test]
    async fn a_batched_write_holds_a_state_back_as_recv_does() {
        let (queue, mut receiver) = client_queue();
        assert_eq!(
            queue.offer_latest(1, Message::binary(vec![0u8; 4_000_000])),
            Latest::Queued
        );
        assert_eq!(receiver.recv().await.unwrap().len(), 4_000_000);
        assert_eq!(queue.offer_latest(1, text("scene 2")), Latest::Queued);
        assert!(queue.offer(text("stats 2")));
        let got = receiver.ready().unwrap().into_text().unwrap();
        assert_eq!(got.as_str(), "stats 2");
        assert!(receiver.ready().is_none(), "scene 2 is not due for 2 s");
        assert_eq!(queue.offer_latest(1, text("scene 3")), Latest::Thinned);
    }
}
