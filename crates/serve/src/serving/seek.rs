//! A seek or `/step` under way, run in slices between which the loop answers its clients,
//! and the inputs kept for a seek back.

use std::time::Instant;

use super::{MAX_KEPT_INPUT_BYTES, PROGRESS_EVERY, SLICE, Serving, broadcast_status};
use crate::common::ServeError;
use crate::hub::Hub;
use crate::sink::{LiveSink, ServeSink};
use ricochet_record::session::Session;

/// The inputs of a session that were accepted, with their frames, in order: what a seek
/// back steps again.
#[derive(Default)]
pub(super) struct KeptInputs {
    pub(super) list: Vec<(u64, String)>,
    bytes: usize,
    /// The frame of the first accepted input that was not kept (the budget was spent).
    pub(super) unkept_from: Option<u64>,
}

impl KeptInputs {
    pub(super) fn keep(&mut self, frame: u64, text: String) {
        let cost = text.len() + 32;
        if self.unkept_from.is_some() || self.bytes + cost > MAX_KEPT_INPUT_BYTES {
            self.unkept_from.get_or_insert(frame);
            return;
        }
        self.bytes += cost;
        self.list.push((frame, text));
    }

    /// Forgets the inputs of frame `frame` and after.
    pub(super) fn truncate(&mut self, frame: u64) {
        self.list.retain(|(f, _)| *f < frame);
        self.bytes = self.list.iter().map(|(_, t)| t.len() + 32).sum();
        if self.unkept_from.is_some_and(|u| u >= frame) {
            self.unkept_from = None;
        }
    }
}

/// Who asked for a seek or step, to be answered when it is done.
pub enum Asker {
    /// A service call.
    Call {
        /// The client.
        client: u64,
        /// The service.
        service: u32,
        /// The call's id.
        call: u32,
    },
    /// Foxglove's timeline (`playbackControl`): every client gets the playback state.
    Playback {
        /// Play after the seek (else pause).
        play: bool,
        /// The request's id.
        request_id: String,
    },
}

/// A seek or `/step` under way.
pub struct Running {
    /// The next frame when it is done.
    pub(super) target: u64,
    /// A `/step`: each frame takes the clients' inputs and is sent live. A seek: the kept
    /// inputs, muted.
    pub(super) live: bool,
    /// The next kept input to apply (a seek).
    cursor: usize,
    asker: Asker,
    /// The recording file a seek back writes again, for the answer.
    recording: Option<String>,
    progress_at: Instant,
}

impl Serving {
    /// Starts a seek to `target` (the next frame once there), or says why it can't be:
    /// every seek, a service's or the timeline's, is checked here.
    pub fn seek(
        &mut self,
        target: u64,
        hub: &Hub,
        asker: Asker,
    ) -> Result<Result<(), String>, ServeError> {
        if target > self.last {
            return Ok(Err(format!(
                "frame {target} is past the session's last frame, {} ({})",
                self.last, self.last_why
            )));
        }
        let next = self.session.next_frame();
        let halted = self.halted();
        if let Some(why) = &halted
            && target > next
        {
            return Ok(Err(why.clone()));
        }
        let mut recording = None;
        if target < next || halted.is_some() {
            if let Some(u) = self.kept.unkept_from
                && target > u
            {
                return Ok(Err(format!(
                    "frame {target}: a seek back reaches frame {u} at most: the inputs since \
                     were not kept (at most {} MiB of inputs are)",
                    MAX_KEPT_INPUT_BYTES >> 20
                )));
            }
            self.kept.truncate(target);
            self.snapshots.retain(|(f, _)| *f <= target);
            match self.snapshots.last() {
                // Not recording: from the latest snapshot at or before `target`.
                Some((_, snapshot)) if self.record.is_none() => {
                    let sink = ServeSink {
                        live: LiveSink::new(hub.clone()),
                        file: None,
                        muted: false,
                    };
                    self.session = Session::resume(snapshot.clone(), sink)?;
                }
                // Recording (the file must hold the session from frame 0, to replay on its
                // own: it is written again), or no snapshot: from frame 0.
                _ => recording = self.restart(hub, false)?,
            }
        }
        let from = self.session.next_frame();
        let cursor = self.kept.list.partition_point(|(f, _)| *f < from);
        self.begin(target, false, asker, recording);
        if let Some(r) = &mut self.running {
            r.cursor = cursor;
        }
        Ok(Ok(()))
    }

    pub(super) fn begin(
        &mut self,
        target: u64,
        live: bool,
        asker: Asker,
        recording: Option<String>,
    ) {
        self.session.recorder().sink_mut().muted = !live;
        self.running = Some(Running {
            target,
            live,
            cursor: 0,
            asker,
            recording,
            progress_at: Instant::now() + PROGRESS_EVERY,
        });
    }

    /// Goes on with the seek or step under way for one slice; answers its asker when it is
    /// done.
    pub fn slice(&mut self, hub: &Hub) -> Result<(), ServeError> {
        let Some(mut run) = self.running.take() else {
            return Ok(());
        };
        let until = Instant::now() + SLICE;
        let mut failed = None;
        while self.session.next_frame() < run.target {
            let ok = if run.live {
                self.frame(hub)?
            } else {
                let at = self.session.next_frame();
                while let Some((f, text)) = self.kept.list.get(run.cursor)
                    && *f == at
                {
                    let _ = self.session.input(text)?;
                    run.cursor += 1;
                }
                self.step(hub)?
            };
            if !ok {
                failed = self.halted();
                break;
            }
            if Instant::now() >= until {
                break;
            }
        }
        let at = self.session.next_frame();
        if failed.is_none() && at < run.target {
            if Instant::now() >= run.progress_at {
                run.progress_at = Instant::now() + PROGRESS_EVERY;
                let what = if run.live { "stepping" } else { "seeking" };
                let text = format!("{what} to frame {}: at frame {at}", run.target);
                broadcast_status(hub, 0, &text);
            }
            self.running = Some(run);
            return Ok(());
        }
        self.session.recorder().sink_mut().muted = false;
        if !run.live {
            self.session.refresh_live()?;
        }
        match run.asker {
            Asker::Call {
                client,
                service,
                call,
            } => {
                let result = match failed {
                    Some(why) => Err(why),
                    None => Ok(self.response(run.recording)),
                };
                hub.lock().answer(client, service, call, result);
            }
            Asker::Playback { play, request_id } => {
                if failed.is_none() {
                    self.paused = !play;
                }
                self.playback_state(hub, true, &request_id);
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::KeptInputs;
    use crate::serving::MAX_KEPT_INPUT_BYTES;

    /// The inputs kept for seeks stop at their budget, from a frame on, and a seek back to
    /// that frame or before spends it again.
    #[test]
    fn kept_inputs_stop_at_their_budget_and_a_seek_back_frees_it() {
        let mut kept = KeptInputs::default();
        let text = "x".repeat(4064); // 4,096 bytes with the 32 of bookkeeping
        let fit = MAX_KEPT_INPUT_BYTES / 4096;
        for i in 0..fit as u64 + 10 {
            kept.keep(i / 100, text.clone());
        }
        assert_eq!(kept.list.len(), fit);
        assert_eq!(kept.bytes, MAX_KEPT_INPUT_BYTES);
        let first_unkept = fit as u64 / 100;
        assert_eq!(kept.unkept_from, Some(first_unkept));
        // A later input that would fit is not kept either: the inputs must run unbroken.
        kept.truncate(first_unkept + 1);
        assert_eq!(kept.unkept_from, Some(first_unkept));
        kept.truncate(first_unkept);
        assert_eq!(kept.unkept_from, None);
        assert_eq!(kept.list.len(), first_unkept as usize * 100);
        assert_eq!(kept.bytes, kept.list.len() * 4096);
        kept.keep(first_unkept, "y".to_owned());
        assert_eq!(
            kept.list.last().map(|(f, t)| (*f, t.as_str())),
            Some((first_unkept, "y"))
        );
    }
}
