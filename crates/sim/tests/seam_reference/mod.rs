//! The reference of the wrap seam's tests and the left-out layer's: every pair of bodies of
//! layers that meet, tested exactly at the poses `detect` saw, directly and (in a wrapping
//! world) at each of the nine translations by whole world sizes; and the rock both use.

use ricochet_geom::{Pose, Shape, Vec2, contact};
use ricochet_sim::{BodyKind, FrameOutput, Simulation, WorldBounds};

/// Every overlapping pair `(i, j, depth, where b was met)` of bodies of layers that `meets`
/// (a dynamic body in each): the deepest overlap of each pair, the first in
/// `image_offsets` order on a tie (the direct one first), as `detect` reports it. Needs
/// `capture_detect_poses`.
pub fn reference(
    sim: &Simulation,
    frame: &FrameOutput,
    bounds: &WorldBounds,
    meets: impl Fn(u8, u8) -> bool,
) -> Vec<(usize, usize, f64, Vec2)> {
    let w = sim.world();
    // Where `detect` saw the bodies (before `bounds` wrapped them).
    let poses = frame.detect_poses.as_ref().unwrap();
    let pose = |i: usize| poses[i].1;
    let offsets = if bounds.wrap {
        bounds.image_offsets().to_vec()
    } else {
        vec![Vec2::ZERO]
    };
    let mut out = Vec::new();
    for i in 0..w.len() {
        for j in i + 1..w.len() {
            let resting = w.kind[i] != BodyKind::Dynamic && w.kind[j] != BodyKind::Dynamic;
            if resting || !meets(w.layer[i], w.layer[j]) {
                continue;
            }
            let mut best: Option<(f64, Vec2)> = None;
            for &o in &offsets {
                let image = if o == Vec2::ZERO {
                    pose(j)
                } else {
                    Pose::new(pose(j).position + o, pose(j).angle)
                };
                let c = contact(w.shape(i), &pose(i), w.shape(j), &image);
                if best.is_none_or(|(d, _)| c.depth > d) {
                    best = Some((c.depth, image.position));
                }
            }
            if let Some((d, p)) = best
                && d > 0.0
            {
                out.push((i, j, d, p));
            }
        }
    }
    out
}

/// The frame's contacts in [`reference`]'s form: `(i, j, depth, where b was met)`.
pub fn contacts(sim: &Simulation, frame: &FrameOutput) -> Vec<(usize, usize, f64, Vec2)> {
    let w = sim.world();
    (frame.contacts.iter())
        .map(|c| {
            let (i, j) = (w.index_of(c.a).unwrap(), w.index_of(c.b).unwrap());
            (i, j, c.depth, c.pose_b.position)
        })
        .collect()
}

/// A rock: an irregular pentagon about `r` across.
pub fn pentagon(r: f64) -> Shape {
    let v = [
        (1.0, 0.1),
        (0.3, 0.95),
        (-0.8, 0.6),
        (-0.9, -0.5),
        (0.2, -1.0),
    ];
    Shape::polygon(&v.map(|(x, y)| Vec2::new(x * r, y * r))).unwrap()
}
