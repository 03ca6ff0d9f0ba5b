//! When a body's frame is sent on `/tf`, so that Foxglove shows its exact pose at every
//! frame while a body in steady motion costs almost nothing.
//!
//! What Foxglove (Lichtblick 1.10.8's 3D panel) does with transforms:
//! - it keeps every transform of a frame, keyed by the transform's own timestamp; one with
//!   the same timestamp replaces the earlier one;
//! - at time `t` it has read exactly the transform messages whose log time is `<= t`
//!   (preloading reads them from the file's start, also after a seek, never ahead of `t`);
//! - it shows a frame at `t` by the transform stamped `t` if there is one, else by
//!   interpolating between the ones before and after `t` (the translation linearly, the
//!   rotation spherically, the short way round), else by the last one.
//!
//! So a transform may be stamped in the future: a prediction. A body moving in a straight
//! line at a constant turn rate (an asteroid drifting, a lift) is sent once per
//! [`HORIZON`] frames: a sample on its line that far ahead, which Foxglove interpolates
//! towards. When its motion breaks (a hit, a wrap round the world's seam, a push) its pose
//! is sent exactly every frame ("dense", as before; the prediction the old line left ahead is
//! overwritten, same timestamp, with that pose, so that Foxglove holds it until the next
//! frame) until two steps in a row are equal again; then a new line starts, and that
//! prediction is overwritten with the new line's pose there. A body that does not move is
//! sent once. Every frame's pose is then given back within [`LINE_TOLERANCE`] (the seek test
//! checks every frame). Between two frames Foxglove shows a body on a line moving along it,
//! and any other body at its pose of the earlier frame; a body wrapping round the seam is
//! never drawn sliding across the world.

use ricochet_geom::Vec2;

/// How far, relative to the value (or absolutely, below 1), a frame's pose may be from its
/// line: 1e-9, some ten thousand times finer than f32 rendering.
pub const LINE_TOLERANCE: f64 = 1e-9;

/// How many frames ahead a line's prediction is stamped, at most.
pub const HORIZON: u64 = 60;

/// A pose as `/tf` interpolates it: x, y and angle.
pub type Pose3 = [f64; 3];

/// A sample to send: the body's frame at `frame`, with `pose`.
pub type Sample = (u64, Pose3);

fn pose3(position: Vec2, angle: f64) -> Pose3 {
    [position.x, position.y, angle]
}

/// `a` and `b` agree within the tolerance, component by component.
fn near(a: Pose3, b: Pose3) -> bool {
    (0..3).all(|k| (a[k] - b[k]).abs() <= LINE_TOLERANCE * a[k].abs().max(1.0))
}

/// A straight line: the pose at frame `start`, and the step per frame.
#[derive(Clone, Copy)]
struct Line {
    start: u64,
    pose: Pose3,
    step: Pose3,
}

impl Line {
    fn at(&self, frame: u64) -> Pose3 {
        let n = frame as f64 - self.start as f64;
        [
            self.pose[0] + self.step[0] * n,
            self.pose[1] + self.step[1] * n,
            self.pose[2] + self.step[2] * n,
        ]
    }

    /// Frames between two samples: the horizon, or fewer so that the rotation turns less
    /// than a quarter turn between them (slerp takes the short way round). `None` if one
    /// step already turns that much: the motion can't be a line.
    fn spacing(&self) -> Option<u64> {
        let turn = self.step[2].abs();
        if turn == 0.0 {
            return Some(HORIZON);
        }
        let frames = (std::f64::consts::FRAC_PI_2 / turn).floor();
        (frames >= 1.0).then(|| (frames as u64).min(HORIZON))
    }

    fn still(&self) -> bool {
        self.step == [0.0; 3]
    }

    /// Whether every pose it predicts up to [`HORIZON`] frames after `frame` is finite (a
    /// line is straight, so its two ends decide): a body near `f64::MAX` would otherwise
    /// be predicted at infinity while its own pose is still finite.
    fn finite_ahead(&self, frame: u64) -> bool {
        self.at(frame + HORIZON).iter().all(|x| x.is_finite())
    }
}

/// A body's motion as `/tf` has described it so far.
pub struct Motion {
    /// Live: every pose that changes is sent exactly in its frame, never a prediction (a
    /// live viewer has nothing ahead to interpolate towards).
    live: bool,
    /// The line it is on, if `/tf` describes it by one.
    line: Option<Line>,
    /// The furthest predicted sample sent (a frame later than the frame it was sent in).
    future: Option<u64>,
    /// The last two poses (frames `n - 2`, `n - 1`), for spotting a steady step.
    before: Pose3,
    last: Pose3,
}

impl Motion {
    /// A body appearing at `frame`: its pose is sent. `live`: see [`Motion::live`].
    pub fn appear(
        frame: u64,
        position: Vec2,
        angle: f64,
        live: bool,
        out: &mut Vec<Sample>,
    ) -> Motion {
        let p = pose3(position, angle);
        out.push((frame, p));
        Motion {
            live,
            line: None,
            future: None,
            before: p,
            last: p,
        }
    }

    /// The body's pose at `frame` (the frame after the last call): pushes the samples to
    /// send.
    pub fn frame(&mut self, frame: u64, position: Vec2, angle: f64, out: &mut Vec<Sample>) {
        let p = pose3(position, angle);
        let (before, last) = (self.before, self.last);
        self.before = last;
        self.last = p;
        if self.live {
            if p != last {
                out.push((frame, p));
            }
            return;
        }
        // A sample already stamped this frame (a prediction, or a pose held from a frame
        // before): right only if this frame is on the line that predicted it.
        let due = self.future == Some(frame);
        if self.future.is_some_and(|f| f <= frame) {
            self.future = None;
        }
        match self.line {
            Some(line) if near(p, line.at(frame)) && line.finite_ahead(frame) => {
                if self.future.is_none() && !line.still() {
                    self.predict(&line, frame, out);
                }
            }
            Some(_) => {
                // The line broke: exact poses until the motion is steady again.
                self.line = None;
                self.dense(frame, p, out);
            }
            None => {
                let step = [
                    last[0] - before[0],
                    last[1] - before[1],
                    last[2] - before[2],
                ];
                let line = Line {
                    start: frame - 1,
                    pose: last,
                    step,
                };
                let steady =
                    near(p, line.at(frame)) && line.spacing().is_some() && line.finite_ahead(frame);
                if steady {
                    // The pose at `frame - 1` was sent exactly: the line starts there.
                    if due {
                        // What is stamped here was held from a frame before.
                        out.push((frame, p));
                    }
                    self.line = Some(line);
                    self.start_line(&line, frame, out);
                } else {
                    self.dense(frame, p, out);
                }
            }
        }
    }

    /// An exact pose at `frame`, and the same pose at the old line's prediction if it is
    /// still ahead: between this frame and the next, Foxglove then holds this pose instead
    /// of drifting towards where the old line would have gone.
    fn dense(&mut self, frame: u64, p: Pose3, out: &mut Vec<Sample>) {
        out.push((frame, p));
        if let Some(stale) = self.future {
            out.push((stale, p));
        }
    }

    /// A new line at `frame`: a prediction ahead, and the old line's prediction (if still in
    /// the future) overwritten with this line's pose there.
    fn start_line(&mut self, line: &Line, frame: u64, out: &mut Vec<Sample>) {
        let spacing = line.spacing().unwrap_or(1);
        match self.future {
            Some(stale) => {
                // Samples on the new line up to the stale one, close enough for slerp.
                let mut at = line.start + spacing;
                while at < stale {
                    if at > frame {
                        out.push((at, line.at(at)));
                    }
                    at += spacing;
                }
                out.push((stale, line.at(stale)));
            }
            None if !line.still() => self.predict(line, frame, out),
            None => {}
        }
    }

    /// A prediction on `line`, one spacing ahead of `frame`.
    fn predict(&mut self, line: &Line, frame: u64, out: &mut Vec<Sample>) {
        let at = frame + line.spacing().unwrap_or(1);
        out.push((at, line.at(at)));
        self.future = Some(at);
    }
}

#[cfg(test)]
mod tests {
    use super::{Motion, Sample};
    use ricochet_geom::Vec2;

    /// Issue #20: no logged value may be non-finite. A body moving `1e307` a frame is finite
    /// up to frame 17 (1.7e308 < f64::MAX), but a line's prediction 60 frames ahead passes
    /// f64::MAX from its first frame on; `/tf` sends exact poses instead.
    #[test]
    fn a_line_predicting_past_f64_sends_exact_poses() {
        let mut out: Vec<Sample> = Vec::new();
        let mut m = Motion::appear(0, Vec2::ZERO, 0.0, false, &mut out);
        for frame in 1..=17u64 {
            m.frame(frame, Vec2::new(frame as f64 * 1e307, 0.0), 0.0, &mut out);
        }
        for (frame, pose) in &out {
            assert!(
                pose.iter().all(|x| x.is_finite()),
                "frame {frame}: {pose:?}"
            );
        }
        // Every frame from 1 on is sent exactly, as for any motion that is not a line.
        assert_eq!(out.len(), 18);
    }

    /// The guard changes nothing for an ordinary line: one prediction, 60 frames ahead.
    #[test]
    fn an_ordinary_line_is_still_predicted() {
        let mut out: Vec<Sample> = Vec::new();
        let mut m = Motion::appear(0, Vec2::ZERO, 0.0, false, &mut out);
        for frame in 1..=5u64 {
            m.frame(frame, Vec2::new(frame as f64, 0.0), 0.0, &mut out);
        }
        assert!(out.iter().any(|(f, _)| *f == 62), "{out:?}");
    }
}
