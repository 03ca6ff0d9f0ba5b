//! When the scene's channels are drawn: in every frame while the drawing is small, less
//! often when it is big, so that recording keeps up with the simulation (issue #37).
//!
//! A frame's drawing (`/scene`, `/scene/static`, `/tf`, `/scene/contacts`) of `n` encoded
//! bytes is followed by the next drawing no sooner than `ceil(n / DRAW_BYTES_PER_FRAME)`
//! frames later. A scene drawn body by body (at most 256 bodies when recording starts:
//! `scene::PER_BODY_LIMIT`; every shipped scenario) is drawn in every frame it changes, as
//! before, and so is a bigger one whose drawing is at most [`DRAW_BYTES_PER_FRAME`] (about
//! 80 moving bodies drawn in batches); 10,000 moving asteroids (1.5 MB a frame) are drawn
//! every 124th frame (about every 2 s of a 60 Hz game; the viewer redraws a live
//! 10,000-body scene about once a second).
//! The rule depends only on the bytes, never on time, so a log stays the same bytes on any
//! machine and with any thread count.
//!
//! What the other channels do is unchanged: `/bodies`, `/contacts`, `/stats` and `/events`
//! are exact in every frame. What a viewer shows at a time between two drawings is the
//! earlier drawing (Foxglove takes each topic's last message at or before the time), and a
//! body that lives only between two drawings is never drawn. [`DrawPace::every_frame`]
//! draws every frame (`ricochet run --draw-every-frame`): exact seeks, at the recording
//! speed of a log of 1.5 MB a frame (about 300 frames/s for 10,000 moving bodies here, where
//! issue #21 measured 190).
//!
//! Why bytes and not a fixed rate in log time: what costs is bytes. Measured on the 2-core
//! machine (BENCHMARKS.md, "Recording at the simulation's speed"), 10,000 asteroids drawn
//! every frame record at about 5% of the simulation's rate; the 10,000-asteroid level,
//! with its keyframes (`bodies.rs`) every 420 frames, at 50% with 32 KiB a frame and 56% with
//! 24 KiB (with keyframes every 240 frames: 47% and 52%; BENCHMARKS.md, "Then: the budgets
//! chosen again"). The step then got faster (a step's kinetic energy kept while no velocity
//! changes: the level's simulation 23,400 to 33,300 frames/s), and the same 24 KiB recorded
//! it at 48%; 20 KiB at 52%, 16 KiB at 56% (BENCHMARKS.md, "Then: the budget chosen again
//! for a faster step"). The step got faster again (the level's simulation 43,000 frames/s),
//! and over its 600 frames the same 16 KiB recorded it at 49.9% (the median of ten
//! alternated rounds, with the first frame's keyframe and drawing made cheaper), 14 KiB at
//! 50.0%, 12 KiB at 54.7%, the budget chosen (BENCHMARKS.md, "Then: the first frame made
//! cheaper, and the budget at 12 KiB"). A scene of 200 bodies costs nothing to draw at
//! 60 Hz.

/// Encoded drawing bytes a frame may average (see the module docs).
pub const DRAW_BYTES_PER_FRAME: u64 = 12 * 1024;

/// Which frames draw the scene, and what changed since the last drawing.
#[derive(Clone, Debug, Default)]
pub struct DrawPace {
    every_frame: bool,
    /// The first frame that may draw again.
    next: u64,
    /// A moving (static) body changed since the last drawing: the next drawing sends
    /// `/scene` (`/scene/static`).
    pub scene_pending: bool,
    /// See `scene_pending`.
    pub statics_pending: bool,
}

impl DrawPace {
    /// A pace that draws in every frame, whatever the drawing's size.
    pub fn every_frame() -> DrawPace {
        DrawPace {
            every_frame: true,
            ..DrawPace::default()
        }
    }

    /// Whether `frame` draws.
    pub fn due(&self, frame: u64) -> bool {
        self.every_frame || frame >= self.next
    }

    /// Frame `frame` drew `bytes` encoded bytes (0: it had nothing to send).
    pub fn drawn(&mut self, frame: u64, bytes: u64) {
        if bytes > 0 {
            let wait = bytes.div_ceil(DRAW_BYTES_PER_FRAME).max(1);
            self.next = frame.saturating_add(wait);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_small_drawing_draws_every_frame_and_a_big_one_waits_its_bytes() {
        let mut p = DrawPace::default();
        assert!(p.due(0));
        p.drawn(0, DRAW_BYTES_PER_FRAME);
        assert!(p.due(1));
        // 1.5 MB: 1_500_000 / 12_288 = 122.07, so 123 frames.
        p.drawn(1, 1_500_000);
        assert!(!p.due(123));
        assert!(p.due(124));
        // Nothing to send: the next change draws at once.
        p.drawn(124, 0);
        assert!(p.due(125));
    }

    #[test]
    fn every_frame_ignores_the_bytes() {
        let mut p = DrawPace::every_frame();
        p.drawn(0, u64::MAX);
        assert!(p.due(1));
    }
}
