//! A run's error against the reference run, at the simulation times both reach
//! ([`FrameMap`]): named bodies' positions, energy, touch events, and the pairs in contact.

use std::collections::BTreeMap;

use ricochet_geom::Vec2;
use ricochet_sim::WorldBounds;
use serde::{Deserialize, Serialize};

use super::time::FrameMap;
use super::trace::{Touch, Trace};

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

/// Measures `run` against `reference` (`bounds`: the run's world, for wrapping distances).
#[must_use]
pub fn measure(run: &Trace, reference: &Trace, bounds: Option<&WorldBounds>) -> Measures {
    let map = FrameMap::new(run.dt, reference.dt);
    let mut m = Measures::default();
    let (mut sum_sq, mut count) = (0.0, 0u64);
    let mut last_energy = None;
    for (k, s) in run.samples.iter().enumerate() {
        let Some(r) = map
            .reference_frame(k as u64)
            .and_then(|j| reference.samples.get(usize::try_from(j).ok()?))
        else {
            continue;
        };
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
                    let e = distance(s.bodies[i].1, r.bodies[j].1, bounds);
                    sum_sq += e * e;
                    count += 1;
                    // NaN (a run that overflowed) is the worst error there is.
                    if e > m.position_max || (e.is_nan() && !m.position_max.is_nan()) {
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
        last_energy = Some(s.energy);
        m.false_positives += missing_from(&s.touching, &r.touching);
        m.false_negatives += missing_from(&r.touching, &s.touching);
    }
    if count > 0 {
        m.position_rms = (sum_sq / count as f64).sqrt();
    }
    if let (Some(last), Some(first)) = (last_energy, run.samples.first()) {
        m.energy_drift = last - first.energy;
    }
    // Touch events: the n-th event of a kind and pair in one run is the n-th in the other.
    fn by_key(t: &Trace) -> BTreeMap<&Touch, Vec<u64>> {
        let mut k: BTreeMap<&Touch, Vec<u64>> = BTreeMap::new();
        for (f, touch) in &t.touches {
            k.entry(touch).or_default().push(*f);
        }
        k
    }
    let (ours, theirs) = (by_key(run), by_key(reference));
    for (key, frames) in &ours {
        let refs = theirs.get(key).map_or(&[][..], Vec::as_slice);
        m.events_appear += frames.len().saturating_sub(refs.len()) as u64;
        m.events_moved += frames
            .iter()
            .zip(refs)
            .filter(|&(&f, &j)| f != map.covering_frame(j))
            .count() as u64;
    }
    for (key, refs) in &theirs {
        let n = ours.get(key).map_or(0, Vec::len);
        m.events_vanish += refs.len().saturating_sub(n) as u64;
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn multisets_differ_by_what_is_left_over() {
        assert_eq!(missing_from(&[1, 2, 2, 3], &[2, 3, 4]), 2);
        assert_eq!(missing_from(&[2, 3, 4], &[1, 2, 2, 3]), 1);
        assert_eq!(missing_from::<u8>(&[], &[1]), 0);
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
