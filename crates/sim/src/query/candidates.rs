//! The bodies (and, in a wrap world, images) a query must test exactly.

use ricochet_geom::{Bounds, Ray, Vec2};

use super::QueryFilter;
use super::images;
use crate::pipeline::Simulation;

impl Simulation {
    /// Calls `f(i, offset)` for every body `i` the filter accepts whose bounds, translated
    /// by `offset` (zero, or whole world sizes in a wrap world), meet `region`.
    pub(super) fn region_candidates(
        &self,
        region: &Bounds,
        filter: &QueryFilter,
        mut f: impl FnMut(usize, Vec2),
    ) {
        let w = &self.world;
        let world = self.scenario.world.bounds.as_ref();
        for i in 0..w.len() {
            if !filter.accepts(w.layer[i], w.entity[i]) {
                continue;
            }
            let b = w.shape(i).bounds(&w.pose(i));
            images::offsets(world, &b, region, |o| f(i, o));
        }
    }

    /// Calls `f(i, offset)` for every body (image) whose bounds the ray meets within
    /// `max_distance`; `f` returns how far the search must still go, if it hit.
    pub(super) fn ray_candidates(
        &self,
        ray: &Ray,
        max_distance: f64,
        filter: &QueryFilter,
        mut f: impl FnMut(usize, Vec2) -> Option<f64>,
    ) {
        let a = ray.origin();
        let b = ray.point_at(max_distance);
        let region = Bounds {
            min: a.min(b),
            max: a.max(b),
        };
        self.region_candidates(&region, filter, |i, o| {
            f(i, o);
        });
    }
}
