//! What `ricochet serve` serves: the session, the inputs kept for a seek back, the
//! snapshots, and the seek or `/step` under way, which runs in slices between which the loop
//! answers its clients, reports progress and notices SIGTERM.
//!
//! Bounds, whatever the clients do:
//! - no frame past the session's last (`--frames`, else [`ricochet_sim::MAX_FRAMES`]) is
//!   stepped, by real time, `/step`, `/seek` or the timeline alike;
//! - the inputs kept for seeks back are the accepted ones, at most
//!   [`MAX_KEPT_INPUT_BYTES`]; a refused input changes nothing, so a seek back that steps
//!   the session again refuses nothing and needs none of them (the new recording doesn't
//!   hold them, and so replays on its own);
//! - a seek back while recording writes the segment's file again from frame 0 (the branch
//!   left is dropped, as its inputs are): a seek never adds a file, and at most
//!   [`MAX_SEGMENTS`] files are written (`/reset` and `/load` start one each).

use std::path::PathBuf;
use std::time::Duration;

use ricochet_sim::{Scenario, Simulation};
use tokio_tungstenite::tungstenite::Message;

use crate::common::{Note, ServeError};
use crate::hub::Hub;
use crate::protocol;
use crate::services;
use crate::sink::{ServeSink, finish, segment, start};
use ricochet_record::session::{Session, StepError};

mod drawing;
mod seek;

use seek::KeptInputs;
pub use seek::{Asker, Running};

/// Frames between two snapshots of a session that is not recorded.
pub const SNAPSHOT_EVERY: u64 = 600;
/// Snapshots kept at most: their memory is bounded whatever the session's length.
pub const MAX_SNAPSHOTS: usize = 16;
/// The inputs kept for seeks back, at most, bytes (each input's text and 32 bytes): past
/// it, inputs are no longer kept, and a seek back can reach only the frame of the first one
/// that was not.
pub const MAX_KEPT_INPUT_BYTES: usize = 64 << 20;
/// Recording files a server writes at most (`/reset` and `/load` each start one).
pub const MAX_SEGMENTS: u32 = 1000;
/// A seek or a `/step` runs at most this long before the loop looks at its clients again.
const SLICE: Duration = Duration::from_millis(50);
/// How often a long seek or step tells the clients how far it got.
const PROGRESS_EVERY: Duration = Duration::from_millis(500);

/// What is being served.
pub struct Serving {
    pub session: Session<ServeSink>,
    pub scenario: Scenario,
    pub text: String,
    segment: u32,
    kept: KeptInputs,
    /// Simulation seconds per wall second (`/speed`).
    pub speed: f64,
    /// Snapshots to seek back from, when not recording: every [`SNAPSHOT_EVERY`] frames, at
    /// most [`MAX_SNAPSHOTS`] (then every other one is dropped, and they thin out).
    snapshots: Vec<(u64, Simulation)>,
    pub paused: bool,
    /// The last frame the session may step.
    pub last: u64,
    /// What sets [`Serving::last`], for messages.
    last_why: &'static str,
    record: Option<PathBuf>,
    /// The seek or step under way.
    pub running: Option<Running>,
    /// Frames stepped in all (seeks' and steps' included).
    pub stepped: u64,
    note: Note,
}

/// What the plain server's options say to its session (`crate::Options`, less the rooms).
pub struct PlainOptions {
    /// Simulation seconds per wall second.
    pub speed: f64,
    /// Start paused.
    pub paused: bool,
    /// The last frame after frame 0, if bounded.
    pub frames: Option<u64>,
    /// Where the session records.
    pub record: Option<PathBuf>,
    /// Where notes go.
    pub note: Note,
}

impl Serving {
    /// Serves `session` of `scenario` (the file's `text`), stepping at most to frame
    /// `frames` (`None`: [`ricochet_sim::MAX_FRAMES`]).
    pub fn new(
        session: Session<ServeSink>,
        scenario: Scenario,
        text: String,
        o: PlainOptions,
    ) -> Serving {
        Serving {
            session,
            scenario,
            text,
            segment: 0,
            kept: KeptInputs::default(),
            speed: o.speed,
            snapshots: Vec::new(),
            paused: o.paused,
            last: o.frames.unwrap_or(ricochet_sim::MAX_FRAMES),
            last_why: if o.frames.is_some() {
                "--frames"
            } else {
                "the most a log holds"
            },
            record: o.record,
            note: o.note,
            running: None,
            stepped: 0,
        }
    }

    /// Why the session can't step (it overflowed), for a client.
    fn halted(&self) -> Option<String> {
        self.session.overflowed().map(|(frame, what)| {
            let (good, kept) = match frame.checked_sub(1) {
                Some(f) => (format!("frame {f}"), format!("frames 0 to {f}")),
                None => ("no frame".to_owned(), "no frame".to_owned()),
            };
            let kept = if self.record.is_some() {
                format!(" (the recording holds {kept})")
            } else {
                String::new()
            };
            format!(
                "frame {frame}: {what}; the simulation overflowed. The session is paused at \
                 {good}{kept}: /seek back, /reset or /load go on"
            )
        })
    }

    /// Carries out a service call (from `asker`); the JSON response, or why it failed, or
    /// `None` when the answer comes when a seek or step is done.
    pub fn command(
        &mut self,
        command: services::Command,
        hub: &Hub,
        asker: Asker,
    ) -> Result<Option<Result<String, String>>, ServeError> {
        let mut recording = None;
        match command {
            services::Command::Pause => self.paused = true,
            services::Command::Play => {
                if let Some(why) = self.halted() {
                    return Ok(Some(Err(why)));
                }
                self.paused = false;
            }
            services::Command::Step(n) => {
                if let Some(why) = self.halted() {
                    return Ok(Some(Err(why)));
                }
                let next = self.session.next_frame();
                let end = next.saturating_add(n);
                if end > self.last.saturating_add(1) {
                    return Ok(Some(Err(format!(
                        "frames: the session ends at frame {} ({}); at most {} more",
                        self.last,
                        self.last_why,
                        (self.last + 1).saturating_sub(next)
                    ))));
                }
                self.paused = true;
                self.begin(end, true, asker, None);
                return Ok(None);
            }
            services::Command::Reset | services::Command::Load(_) => {
                if self.record.is_some() && self.segment + 1 >= MAX_SEGMENTS {
                    return Ok(Some(Err(format!(
                        "the recording has {MAX_SEGMENTS} files, the most a server writes: \
                         restart the server to record more"
                    ))));
                }
                if let services::Command::Load(path) = command {
                    match crate::load_path::load(&path) {
                        Ok((scenario, text)) => (self.scenario, self.text) = (scenario, text),
                        Err(why) => return Ok(Some(Err(why))),
                    }
                }
                recording = self.restart(hub, true)?;
                self.kept = KeptInputs::default();
                self.snapshots.clear();
                self.session.refresh_live()?;
            }
            services::Command::Speed(x) => self.speed = x,
            services::Command::Query(request) => {
                // After an overflow the simulation holds the frame that overflowed, which no
                // client was sent.
                if let Some(why) = self.halted() {
                    return Ok(Some(Err(why)));
                }
                let next = self.session.next_frame();
                return Ok(Some(crate::query::answer(
                    self.session.sim(),
                    next,
                    &request,
                )));
            }
            services::Command::Seek(target) => {
                return match self.seek(target, hub, asker)? {
                    Ok(()) => Ok(None),
                    Err(why) => Ok(Some(Err(why))),
                };
            }
        }
        Ok(Some(Ok(self.response(recording))))
    }

    /// `{"frame": F, "paused": P}`, with `"recording"` if a file was (re)started.
    fn response(&self, recording: Option<String>) -> String {
        let mut response = serde_json::json!({
            "frame": self.session.next_frame(),
            "paused": self.paused,
        });
        if let Some(file) = recording {
            response["recording"] = serde_json::Value::String(file);
        }
        response.to_string()
    }

    /// Tells every client the playback state.
    pub fn playback_state(&self, hub: &Hub, sought: bool, request_id: &str) {
        let t = self
            .session
            .next_frame()
            .saturating_sub(1)
            .saturating_mul(self.session.dt_ns());
        let state =
            protocol::playback_state(!self.paused, t, self.speed as f32, sought, request_id);
        hub.lock().playback_state(state);
    }

    /// A new session of the current scenario from frame 0: in a new recording file, or
    /// (a seek back) writing the current one again; the file, if recording.
    fn restart(&mut self, hub: &Hub, new_file: bool) -> Result<Option<String>, ServeError> {
        if new_file && self.record.is_some() {
            self.segment += 1;
        }
        let next = start(
            &self.scenario,
            &self.text,
            hub,
            self.record.as_deref(),
            self.segment,
        )?;
        let old = std::mem::replace(&mut self.session, next);
        if new_file {
            finish(old)?;
        }
        // Else the old recording's temporary file is removed with it: the new one holds the
        // session as it now stands.
        Ok(self
            .record
            .as_deref()
            .map(|p| segment(p, self.segment).display().to_string()))
    }

    /// One frame: the clients' inputs, then the step; false if it overflowed.
    pub fn frame(&mut self, hub: &Hub) -> Result<bool, ServeError> {
        let dt_ns = self.session.recorder().dt_ns();
        let inputs = std::mem::take(&mut hub.lock().inputs);
        for (client, text) in inputs {
            let at = self.session.next_frame();
            match self.session.input(&text)? {
                Ok(()) => self.kept.keep(at, text),
                Err(why) => hub.lock().tell(client, 2, &format!("input refused: {why}")),
            }
        }
        let t = self.session.next_frame().saturating_mul(dt_ns);
        hub.lock().broadcast(&Message::binary(protocol::time(t)));
        self.step(hub)
    }

    /// Steps the session, keeping a snapshot every [`SNAPSHOT_EVERY`] frames; false if the
    /// step overflowed (then the session is paused at its last good frame and every client
    /// told).
    fn step(&mut self, hub: &Hub) -> Result<bool, ServeError> {
        self.choose_drawing(hub);
        match self.session.step() {
            Ok(_) => {}
            Err(StepError::Overflow { .. }) => {
                self.paused = true;
                let why = self.halted().unwrap_or_default();
                (self.note)(&format!("error: {why}"));
                broadcast_status(hub, 2, &why);
                return Ok(false);
            }
            Err(e) => return Err(e.into()),
        }
        self.stepped += 1;
        let next = self.session.next_frame();
        if self.record.is_none() && next.is_multiple_of(SNAPSHOT_EVERY) {
            self.snapshots.push((next, self.session.sim().clone()));
            if self.snapshots.len() > MAX_SNAPSHOTS {
                let mut k = 0;
                self.snapshots.retain(|_| {
                    k += 1;
                    k % 2 == 0
                });
            }
        }
        Ok(true)
    }

    /// Answers the clicked points that came since the last look (`click.rs`): each with an
    /// `/events` line for the live clients, listing the bodies at the point in the state
    /// they were last sent. Never recorded. While a seek or step is under way, or after an
    /// overflow, the clicker is told why there is no answer.
    pub fn clicks(&mut self, hub: &Hub) -> Result<(), ServeError> {
        let clicks = std::mem::take(&mut hub.lock().clicks);
        for (client, payload) in clicks {
            if let Some(why) = self.busy().or_else(|| self.halted()) {
                hub.lock()
                    .tell(client, 1, &format!("clicked point not answered: {why}"));
                continue;
            }
            let click = match crate::click::parse(&payload) {
                Ok(c) => c,
                Err(why) => {
                    hub.lock().tell(client, 2, &why);
                    continue;
                }
            };
            let at = click.in_world(self.session.view_at());
            let sim = self.session.sim();
            let bodies = sim.overlap_point(at, &ricochet_sim::QueryFilter::all());
            let line = ricochet_record::events::click(sim, at, &bodies);
            self.session.event_live(line)?;
        }
        Ok(())
    }

    /// Refuses a call or a timeline request while a seek or step is under way.
    pub fn busy(&self) -> Option<String> {
        self.running.as_ref().map(|r| {
            format!(
                "busy: {} to frame {} (at frame {}); ask again when it is done",
                if r.live { "stepping" } else { "seeking" },
                r.target,
                self.session.next_frame()
            )
        })
    }
}

/// A status message for every client (0 info, 1 warning, 2 error).
fn broadcast_status(hub: &Hub, level: u8, text: &str) {
    let status = protocol::ServerMessage::Status {
        level,
        message: text,
    };
    hub.lock().broadcast(&Message::text(status.json()));
}
