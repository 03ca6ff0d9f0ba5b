//! A run's error against the reference run, at the simulation times both reach
//! ([`super::time::FrameMap`]): named bodies' positions, energy, touch events, and the
//! pairs in contact, measured as the two runs step ([`Measuring`]).

use std::collections::BTreeMap;

use ricochet_geom::Vec2;
use ricochet_sim::WorldBounds;
use serde::{Deserialize, Serialize};

use super::trace::{Sample, Touch};

/// The error of one run against the reference.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Measures {
    /// Frames of the run compared (at a time the reference reaches).
    pub matched_frames: u64,
    /// Largest position error of any named moving body at any compared time, units.
    #[serde(with = "super::item::exact")]
    pub position_max: f64,
    /// Root mean square of every named body's position error at every compared time.
    #[serde(with = "super::item::exact")]
    pub position_rms: f64,
    /// The body with the largest error (empty when every error is 0).
    pub worst_body: String,
    /// Named moving bodies alive at a compared time in one run and not in the other (a
    /// ship destroyed in one run only): their positions can't be compared.
    pub bodies_unmatched: u64,
    /// This run's energy at its last compared frame minus at frame 0.
    #[serde(with = "super::item::exact")]
    pub energy_drift: f64,
    /// Largest `|E_run − E_reference|` at a compared time.
    #[serde(with = "super::item::exact")]
    pub energy_error: f64,
    /// Touch events (begin or end, by the pair's names) the run has and the reference not.
    pub events_appear: u64,
    /// Touch events the reference has and the run not.
    pub events_vanish: u64,
    /// Touch events both have, at another frame than the one covering the reference's.
    pub events_moved: u64,
    /// (pair, compared frame) in contact in the run and not in the reference.
    pub false_positives: u64,
    /// (pair, compared frame) in contact in the reference and not in the run.
    pub false_negatives: u64,
}

/// The shortest distance, across the edges of a wrapping world.
fn distance(a: Vec2, b: Vec2, bounds: Option<&WorldBounds>) -> f64 {
    let mut d = a - b;
    if let Some(w) = bounds.filter(|w| w.wrap) {
        let size = w.size();
        let fold = |x: f64, s: f64| {
            let x = x.rem_euclid(s);
            x.min(s - x)
        };
        d = Vec2::new(fold(d.x, size.x), fold(d.y, size.y));
    }
    d.length()
}

/// How many items of sorted `a` are not matched in sorted `b` (as multisets).
fn missing_from<T: Ord>(a: &[T], b: &[T]) -> u64 {
    let (mut i, mut j, mut n) = (0, 0, 0);
    while i < a.len() {
        if j == b.len() || a[i] < b[j] {
            n += 1;
            i += 1;
        } else if a[i] > b[j] {
            j += 1;
        } else {
            i += 1;
            j += 1;
        }
    }
    n
}

/// One touch event's key (kind and pair) waiting for its counterpart in the other run:
/// the n-th event of a key in one run is the n-th in the other. Only one side waits at a
/// time (two waiting events would have matched).
#[derive(Debug, Default)]
struct Waiting {
    /// The run's events with no reference event yet: any later match is at another frame.
    run: u64,
    /// The reference's events whose covering frame has passed: any match is moved.
    stale: u64,
    /// The reference's events covering the run's frame `fresh.0`, not stepped yet.
    fresh: (u64, u64),
}

impl Waiting {
    /// The fresh events covering a frame before `k` are stale.
    fn age(&mut self, k: u64) {
        if self.fresh.1 > 0 && self.fresh.0 < k {
            self.stale += self.fresh.1;
            self.fresh.1 = 0;
        }
    }
}

/// The error of one run against the reference, measured as both step: the comparison
/// ([`super::compare`]) hands it each compared frame's samples and each touch event, in
/// time order, so nothing is kept per frame.
#[derive(Debug)]
pub struct Measuring<'a> {
    m: Measures,
    bounds: Option<&'a WorldBounds>,
    sum_sq: f64,
    count: u64,
    first_energy: Option<f64>,
    last_energy: Option<f64>,
    touches: BTreeMap<Touch, Waiting>,
}

impl<'a> Measuring<'a> {
    /// Nothing measured yet (`bounds`: the run's world, for wrapping distances).
    #[must_use]
    pub fn new(bounds: Option<&'a WorldBounds>) -> Self {
        Measuring {
            m: Measures::default(),
            bounds,
            sum_sq: 0.0,
            count: 0,
            first_energy: None,
            last_energy: None,
            touches: BTreeMap::new(),
        }
    }

    /// The run's frame 0 energy, for the drift.
    pub fn start(&mut self, energy: f64) {
        self.first_energy = Some(energy);
    }

    /// A compared frame: the run's sample `s` and the reference's `r`, at the same time.
    pub fn frame(&mut self, s: &Sample, r: &Sample) {
        let m = &mut self.m;
        m.matched_frames += 1;
        // Both lists are sorted by name: walk them together.
        let (mut i, mut j) = (0, 0);
        while i < s.bodies.len() && j < r.bodies.len() {
            match s.bodies[i].0.cmp(&r.bodies[j].0) {
                std::cmp::Ordering::Less => {
                    m.bodies_unmatched += 1;
                    i += 1;
                }
                std::cmp::Ordering::Greater => {
                    m.bodies_unmatched += 1;
                    j += 1;
                }
                std::cmp::Ordering::Equal => {
                    let e = distance(s.bodies[i].1, r.bodies[j].1, self.bounds);
                    self.sum_sq += e * e;
                    self.count += 1;
                    if e > m.position_max {
                        m.position_max = e;
                        m.worst_body.clone_from(&s.bodies[i].0);
                    }
                    i += 1;
                    j += 1;
                }
            }
        }
        m.bodies_unmatched += (s.bodies.len() - i + r.bodies.len() - j) as u64;
        m.energy_error = m.energy_error.max((s.energy - r.energy).abs());
        self.last_energy = Some(s.energy);
        m.false_positives += missing_from(&s.touching, &r.touching);
        m.false_negatives += missing_from(&r.touching, &s.touching);
    }

    /// A touch event of the run at its frame `k`. Every reference event covered by a frame
    /// up to `k` has been given before it.
    pub fn run_touch(&mut self, k: u64, touch: Touch) {
        let w = self.touches.entry(touch).or_default();
        w.age(k);
        if w.stale > 0 {
            w.stale -= 1;
            self.m.events_moved += 1;
        } else if w.fresh.1 > 0 {
            // Covering this very frame: the same event, not moved.
            w.fresh.1 -= 1;
        } else {
            w.run += 1;
        }
    }

    /// A touch event of the reference, whose frame the run's frame `covering` covers
    /// ([`super::time::FrameMap::covering_frame`]). Every run event of a frame before
    /// `covering` has been given before it, and none after.
    pub fn reference_touch(&mut self, covering: u64, touch: Touch) {
        let w = self.touches.entry(touch).or_default();
        if w.run > 0 {
            // The run's event came at an earlier frame.
            w.run -= 1;
            self.m.events_moved += 1;
        } else {
            w.age(covering);
            w.fresh = (covering, w.fresh.1 + 1);
        }
    }

    /// The measures, once both runs are done.
    #[must_use]
    pub fn finish(mut self) -> Measures {
        if self.count > 0 {
            self.m.position_rms = (self.sum_sq / self.count as f64).sqrt();
        }
        if let (Some(last), Some(first)) = (self.last_energy, self.first_energy) {
            self.m.energy_drift = last - first;
        }
        for w in self.touches.values() {
            self.m.events_appear += w.run;
            self.m.events_vanish += w.stale + w.fresh.1;
        }
        self.m
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::time::FrameMap;

    #[test]
    fn multisets_differ_by_what_is_left_over() {
        assert_eq!(missing_from(&[1, 2, 2, 3], &[2, 3, 4]), 2);
        assert_eq!(missing_from(&[2, 3, 4], &[1, 2, 2, 3]), 1);
        assert_eq!(missing_from::<u8>(&[], &[1]), 0);
    }

    /// The touch events as the whole-run matching counted them: per key, the n-th event
    /// of the run against the n-th of the reference, moved when the run's frame is not
    /// the one covering the reference's.
    fn whole_runs(
        run: &[(u64, Touch)],
        reference: &[(u64, Touch)],
        map: FrameMap,
    ) -> (u64, u64, u64) {
        let (mut appear, mut vanish, mut moved) = (0, 0, 0);
        let mut keys: Vec<&Touch> = run.iter().chain(reference).map(|(_, t)| t).collect();
        keys.sort();
        keys.dedup();
        for key in keys {
            let ours: Vec<u64> = run.iter().filter(|e| &e.1 == key).map(|e| e.0).collect();
            let theirs: Vec<u64> = reference
                .iter()
                .filter(|e| &e.1 == key)
                .map(|e| e.0)
                .collect();
            appear += ours.len().saturating_sub(theirs.len()) as u64;
            vanish += theirs.len().saturating_sub(ours.len()) as u64;
            moved += ours
                .iter()
                .zip(&theirs)
                .filter(|&(&f, &j)| f != map.covering_frame(j))
                .count() as u64;
        }
        (appear, vanish, moved)
    }

    /// Streamed in the order `compare` steps the two runs (each reference frame before the
    /// run frame covering it), the touch events count as matched over the whole runs.
    #[test]
    fn touch_events_streamed_count_as_over_the_whole_runs() {
        use crate::sweep::time::Ratio;
        let touch = |i: u64| Touch {
            begin: i.is_multiple_of(2),
            names: ("a".to_owned(), format!("b{}", i % 3)),
        };
        // A fixed pseudo-random sequence (a linear congruential generator), no state.
        let mut seed = 12_345_u64;
        let mut next = move || {
            seed = seed
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            seed >> 33
        };
        let r = |n, d| Ratio::new(n, d).unwrap();
        for (dt, dt_ref, frames, frames_ref) in [
            (r(1, 30), r(1, 120), 40, 160),
            (r(1, 50), r(1, 60), 50, 60),
            (r(1, 60), r(1, 60), 30, 30),
            (r(1, 8), r(1, 24), 16, 50),
            (r(1, 30), r(1, 120), 40, 100),
        ] {
            let map = FrameMap::new(dt, dt_ref);
            for _ in 0..50 {
                let events = |n: u64, len: u64, next: &mut dyn FnMut() -> u64| {
                    let mut e: Vec<(u64, Touch)> = (0..n)
                        .map(|_| (next() % (len + 1), touch(next())))
                        .collect();
                    e.sort_by_key(|x| x.0);
                    e
                };
                let (n, m) = (next() % 12, next() % 12);
                let run = events(n, frames, &mut next);
                let reference = events(m, frames_ref, &mut next);
                let mut measuring = Measuring::new(None);
                let mut j = 0;
                for k in 0..=frames {
                    while j < reference.len() && map.covering_frame(reference[j].0) <= k {
                        let c = map.covering_frame(reference[j].0);
                        measuring.reference_touch(c, reference[j].1.clone());
                        j += 1;
                    }
                    for (_, t) in run.iter().filter(|e| e.0 == k) {
                        measuring.run_touch(k, t.clone());
                    }
                }
                for (f, t) in &reference[j..] {
                    measuring.reference_touch(map.covering_frame(*f), t.clone());
                }
                let m = measuring.finish();
                assert_eq!(
                    (m.events_appear, m.events_vanish, m.events_moved),
                    whole_runs(&run, &reference, map),
                    "{run:?} against {reference:?}"
                );
            }
        }
    }

    #[test]
    fn wrapped_distance_goes_the_short_way() {
        let b = WorldBounds {
            min: Vec2::new(0.0, 0.0),
            max: Vec2::new(10.0, 10.0),
            wrap: true,
        };
        let d = distance(Vec2::new(9.5, 1.0), Vec2::new(0.5, 1.0), Some(&b));
        assert!((d - 1.0).abs() < 1e-12);
        let d = distance(Vec2::new(9.5, 1.0), Vec2::new(0.5, 1.0), None);
        assert!((d - 9.0).abs() < 1e-12);
    }
}
