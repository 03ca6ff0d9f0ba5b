//! The motion stages' passes over the columns, by row where the stage allows it: forces,
//! the fused move and turn, lifetimes, and the `has_work` scans whose usual answer is no
//! (asked of a row column in blocks first, see [`any_in_blocks`]).

use ricochet_geom::Vec2;

use super::{Disturbed, Inputs, World};
use crate::def::{BodyKind, Controller};
use crate::entity::Entity;

impl World {
    /// Counts down every lifetime of a body not frozen, and lists the bodies whose lifetime
    /// ran out, in id order.
    pub(crate) fn count_down_lifetimes(&mut self, expired: &mut Vec<Entity>) {
        // Scenery has no lifetime, so the rows are every body that may have one: walked in
        // row order (two narrow columns, no gather through the dense index), the few that
        // ran out then sorted into id order.
        let rows = &mut self.rows;
        // The rows from the first that may have a lifetime (`Rows::no_lifetime_below`).
        let from = rows.no_lifetime_below.min(rows.lifetime.len());
        debug_assert!(
            rows.lifetime[..from].iter().all(Option::is_none),
            "no lifetime below the mark"
        );
        let lifetimes = rows.lifetime[from..].iter_mut();
        for ((l, &frozen), &e) in lifetimes
            .zip(&rows.frozen[from..])
            .zip(&rows.entity[from..])
        {
            if let Some(l) = l
                && !frozen
            {
                *l = l.saturating_sub(1);
                if *l == 0 {
                    expired.push(e);
                }
            }
        }
        expired.sort_unstable();
    }

    /// The `forces` stage's `v += (force + thrust + g * (m * gravity_scale)) / m * dt` for
    /// every active dynamic body, `thrust` giving a controlled body's engine force from its
    /// controller, inputs and angle (zero for a body without a controller). The columns
    /// are read by row directly: one pass, no per-column check for scenery. A body whose
    /// velocity's bits changed is named as disturbed ([`World::disturbed`]), unless every
    /// body already is (the step names them all up front under gravity, where nearly every
    /// velocity changes: `Simulation::step`).
    pub(crate) fn accelerate(
        &mut self,
        dt: f64,
        g: Vec2,
        thrust: impl Fn(&Controller, &Inputs, f64) -> Vec2,
    ) {
        // Velocities change: the kept kinetic energy is dropped.
        self.kept_energy = None;
        if self.disturbed.all() {
            self.accelerate_naming::<false>(dt, g, thrust);
        } else {
            self.accelerate_naming::<true>(dt, g, thrust);
        }
    }

    /// [`World::accelerate`]'s pass, naming each body whose velocity changed when `NAME`
    /// (two copies of the loop: the one that names nothing is the loop as it was).
    fn accelerate_naming<const NAME: bool>(
        &mut self,
        dt: f64,
        g: Vec2,
        thrust: impl Fn(&Controller, &Inputs, f64) -> Vec2,
    ) {
        if self.controlled_count() == 0
            && let Some(run) = self.active_run()
        {
            // The usual case without a controller, over one run (`runs.rs`): each column a
            // slice, in place; the loop below with a zero thrust. Without a force or a
            // gravity scale anywhere (counted), neither column is read: 24 bytes a body the
            // pass would bring in for nothing.
            let rows = &mut self.rows;
            let columns = RunColumns {
                kind: &self.kind[run.indices()],
                entity: &self.entity[run.indices()],
                mass: &rows.mass[run.rows()],
                force: &rows.force[run.rows()],
                scale: &rows.gravity_scale[run.rows()],
                velocity: &mut rows.velocity[run.rows()],
                disturbed: &mut self.disturbed,
                len: self.entity.len(),
            };
            let energy = if self.with_force == 0 && rows.scaled == 0 {
                debug_assert!(columns.force.iter().all(|f| *f == Vec2::ZERO));
                debug_assert!(columns.scale.iter().all(|s| !super::rows::is_scaled(*s)));
                let exact = self.gravity_exact.holds(self.layout, &rows.mass, g);
                if exact {
                    columns.accelerate::<NAME, true, true>(dt, g)
                } else {
                    columns.accelerate::<NAME, true, false>(dt, g)
                }
            } else {
                columns.accelerate::<NAME, false, false>(dt, g)
            };
            // Every mover active: the run is the movers' one, and its sum is the kinetic
            // energy's terms in its order (`measures.rs`), kept until a velocity changes
            // again. Summed here, the pass's own reads of the velocities feed it, and its
            // chain of additions runs beside the pass's work instead of after it.
            if self.active.len() == self.movers.len() {
                self.kept_energy = Some(energy);
            }
            return;
        }
        let (row, rows, kind, angle) = (&self.row, &mut self.rows, &self.kind, &self.angle);
        let (entity, disturbed) = (&self.entity, &mut self.disturbed);
        for &i in &self.active {
            let i = i as usize;
            if kind[i] != BodyKind::Dynamic {
                continue;
            }
            let r = row[i] as usize;
            let push = match &rows.controller[r] {
                Some(c) => thrust(c, &rows.inputs[r], angle[i]),
                None => Vec2::ZERO,
            };
            let v = rows.velocity[r];
            let (m, scale) = (rows.mass[r], rows.gravity_scale[r]);
            let changed = accelerated(v, rows.force[r] + push, g, m, scale, dt);
            if NAME && differs(changed, v) {
                disturbed.name(entity[i], entity.len());
            }
            rows.velocity[r] = changed;
        }
    }

    /// Whether an active dynamic body's thrust input is on.
    pub(crate) fn any_thrust_input(&self) -> bool {
        let inputs = &self.rows.inputs;
        // Counted, not scanned: a ship's engine is off most frames.
        self.thrusting() > 0
            && self.any_active(|i, r| self.kind[i] == BodyKind::Dynamic && inputs[r].thrust)
    }

    /// Whether an active body is grounded.
    pub(crate) fn any_active_grounded(&self) -> bool {
        let grounded = &self.rows.grounded;
        any_in_blocks(grounded, |&g| g) && self.any_active(|_, r| grounded[r])
    }

    /// Whether an active body has a controller: each body with one looked up (a few),
    /// not every active body.
    pub(crate) fn any_active_controller(&self) -> bool {
        let any = (0..self.controlled_count()).any(|k| self.active_controlled(k).is_some());
        debug_assert_eq!(
            any,
            self.any_active(|_, r| self.rows.controller[r].is_some()),
            "the controlled bodies' answer is the active bodies'"
        );
        any
    }

    /// Whether an active body `i` ([`World::active`]), of row `r`, has `on(i, r)`. The
    /// callers ask the row column first ([`any_in_blocks`]): no row with it (the usual
    /// answer) means no active body with it, and costs no gather through the active list.
    fn any_active(&self, on: impl Fn(usize, usize) -> bool) -> bool {
        self.active.iter().any(|&i| {
            let i = i as usize;
            on(i, self.row[i] as usize)
        })
    }

    /// `x += vx * dt`, `y += vy * dt` and `angle += angular_velocity * dt` for every active
    /// body, each where its flag says: the `move_x`, `move_y` and `turn` stages in one pass,
    /// for a scene with no per-axis pass between them (so no body has a carrier). Each
    /// body's arithmetic is the stages' own, and no body's depends on another's, so the
    /// result is the same bits as three passes.
    pub(crate) fn integrate(&mut self, dt: f64, x: bool, y: bool, turn: bool) {
        if x && y
            && turn
            && let Some(run) = self.active_run()
        {
            // The usual case over one run (`runs.rs`): each column a slice, in place.
            let rows = &self.rows;
            let bodies = self.position[run.indices()]
                .iter_mut()
                .zip(&mut self.angle[run.indices()]);
            let motion = rows.velocity[run.rows()]
                .iter()
                .zip(&rows.angular_velocity[run.rows()]);
            for ((p, angle), (v, w)) in bodies.zip(motion) {
                p.x += v.x * dt;
                p.y += v.y * dt;
                *angle += w * dt;
            }
            return;
        }
        // Sliced to their exact lengths: the columns of one index share one bounds check.
        let n = self.row.len();
        let (row, position, angle) = (
            &self.row[..n],
            &mut self.position[..n],
            &mut self.angle[..n],
        );
        let m = self.rows.velocity.len();
        let (velocity, angular_velocity) =
            (&self.rows.velocity[..m], &self.rows.angular_velocity[..m]);
        if x && y && turn {
            // The usual case, without a flag tested per body.
            for &i in &self.active {
                let i = i as usize;
                let r = row[i] as usize;
                let v = velocity[r];
                let p = &mut position[i];
                p.x += v.x * dt;
                p.y += v.y * dt;
                angle[i] += angular_velocity[r] * dt;
            }
            return;
        }
        for &i in &self.active {
            let i = i as usize;
            // Moving bodies always have a row.
            let r = row[i] as usize;
            let v = velocity[r];
            let p = &mut position[i];
            if x {
                p.x += v.x * dt;
            }
            if y {
                p.y += v.y * dt;
            }
            if turn {
                angle[i] += angular_velocity[r] * dt;
            }
        }
    }
    /// The active bodies whose position is not inside `[min, max)` on both axes (a NaN
    /// coordinate is not inside), in active order, into `out`: the wrap's and the `bounds`
    /// stage's one question about every active body, asked in one tight loop so that the
    /// few answers go to their slower code. Asked again in the same step with the same box
    /// and nothing touched since the answer was kept ([`World::keep_not_inside`]), the kept
    /// answer is given without the loop.
    pub(crate) fn active_not_inside(&self, min: Vec2, max: Vec2, out: &mut Vec<u32>) {
        let kept = &self.kept_outside;
        let bits = |v: Vec2| [v.x.to_bits(), v.y.to_bits()];
        if kept.mark == Some(self.disturbed.mark())
            && bits(kept.min) == bits(min)
            && bits(kept.max) == bits(max)
        {
            out.extend_from_slice(&kept.list);
            #[cfg(debug_assertions)]
            {
                let mut scanned = Vec::new();
                self.scan_not_inside(min, max, &mut scanned);
                assert_eq!(kept.list, scanned, "nothing touched, the same answer");
            }
            return;
        }
        self.scan_not_inside(min, max, out);
    }

    /// Keeps the answer of [`World::active_not_inside`] for `[min, max)` now, from
    /// `candidates`: its answer before the caller moved some of them (and nothing else).
    /// A body outside now was outside then, or it did not move.
    pub(crate) fn keep_not_inside(&mut self, min: Vec2, max: Vec2, candidates: &[u32]) {
        let position = &self.position;
        let outside = |p: &Vec2| !(p.x >= min.x && p.x < max.x && p.y >= min.y && p.y < max.y);
        let kept = &mut self.kept_outside;
        kept.list.clear();
        kept.list.extend(
            candidates
                .iter()
                .filter(|&&i| outside(&position[i as usize])),
        );
        (kept.min, kept.max) = (min, max);
        kept.mark = Some(self.disturbed.mark());
    }

    /// [`World::active_not_inside`]'s loop.
    fn scan_not_inside(&self, min: Vec2, max: Vec2, out: &mut Vec<u32>) {
        let position = &self.position;
        let outside = |p: &Vec2| !(p.x >= min.x && p.x < max.x && p.y >= min.y && p.y < max.y);
        let active = &self.active;
        // `active` is sorted and without repeats: when its first and last are as far apart
        // as its length says, it is a run of consecutive indices (every body of an asteroid
        // field), whose positions are read in place, 32 at a time without an early exit
        // (which the compiler vectorises), a block looked into only when it holds an answer.
        if let (Some(&first), Some(&last)) = (active.first(), active.last())
            && (last - first) as usize + 1 == active.len()
        {
            let run = &position[first as usize..=last as usize];
            for (c, block) in run.chunks(32).enumerate() {
                if block.iter().fold(false, |any, p| any | outside(p)) {
                    let start = first + (c * 32) as u32;
                    for (k, p) in (start..).zip(block) {
                        if outside(p) {
                            out.push(k);
                        }
                    }
                }
            }
            return;
        }
        for &i in active {
            if outside(&position[i as usize]) {
                out.push(i);
            }
        }
    }
}

/// Whether `on` holds for an item of `column`: in blocks without an early exit inside, which
/// the compiler unrolls (the usual answer is no, after every item).
pub(super) fn any_in_blocks<T>(column: &[T], on: impl Fn(&T) -> bool) -> bool {
    column
        .chunks(32)
        .any(|c| c.iter().fold(false, |any, x| any | on(x)))
}

/// An answer of [`World::active_not_inside`] kept for the next ask in the same step, with
/// the mark of what the world had touched then ([`super::Disturbed`]).
#[derive(Clone, Debug, Default)]
pub(super) struct KeptOutside {
    mark: Option<(u64, u64, u64)>,
    min: Vec2,
    max: Vec2,
    list: Vec<u32>,
}

/// Velocity `v` after `dt` under the body's own force and thrust `pushed` and gravity `g` at
/// `scale`, for mass `m`: `v + (pushed + g * (m * scale)) / m * dt`, in that order (the
/// order is part of the log).
#[inline]
fn accelerated(v: Vec2, pushed: Vec2, g: Vec2, m: f64, scale: f64, dt: f64) -> Vec2 {
    v + acceleration(pushed, g, m, scale) * dt
}

/// [`accelerated`]'s acceleration.
#[inline]
fn acceleration(pushed: Vec2, g: Vec2, m: f64, scale: f64) -> Vec2 {
    (pushed + g * (m * scale)) / m
}

/// Whether every row's acceleration under gravity alone, `(+0 + g * (m * 1)) / m` as
/// [`accelerated`] computes it, is `g` itself, bit for bit, with the world's layout, the
/// count of rows and the `g` it was found for. Usually so (a product divided by the same
/// mass gives the number back, and each mass is checked), and then the forces pass divides
/// by no mass: a division a body bounded that pass at 10,000 bodies. A mass is set only
/// when its row is made (`Rows::push`), which a new layout or another count of rows tells.
#[derive(Clone, Debug, Default)]
pub(super) struct GravityExact(Option<(u64, usize, [u64; 2], bool)>);

impl GravityExact {
    /// Whether it holds for `mass` (every row's) under `g` in a world of `layout`: kept,
    /// or found again (a pass over the masses) when any of them changed.
    fn holds(&mut self, layout: u64, mass: &[f64], g: Vec2) -> bool {
        let at = (layout, mass.len(), [g.x.to_bits(), g.y.to_bits()]);
        match self.0 {
            Some((l, n, bits, holds)) if (l, n, bits) == at => holds,
            _ => {
                let same = |a: Vec2| [a.x.to_bits(), a.y.to_bits()] == at.2;
                let holds = mass
                    .iter()
                    .all(|&m| same(acceleration(Vec2::ZERO, g, m, 1.0)));
                self.0 = Some((at.0, at.1, at.2, holds));
                holds
            }
        }
    }

    /// The count of rows it was last found for, and whether it held.
    #[cfg(test)]
    pub(super) fn found(&self) -> Option<(usize, bool)> {
        self.0.map(|(_, n, _, holds)| (n, holds))
    }
}

/// What [`World::accelerate`] reads and writes over one run of rows.
struct RunColumns<'a> {
    kind: &'a [BodyKind],
    entity: &'a [Entity],
    mass: &'a [f64],
    force: &'a [Vec2],
    scale: &'a [f64],
    velocity: &'a mut [Vec2],
    disturbed: &'a mut Disturbed,
    len: usize,
}

impl RunColumns<'_> {
    /// The pass, naming each changed body when `NAME`; when `PLAIN` (no force, every
    /// gravity scale 1), neither column is read: a force of ±0 plus the zero thrust is +0,
    /// and a scale of 1 multiplies exactly, so the bits are the same. When `EXACT` too,
    /// every body's acceleration is `g` itself ([`GravityExact`]), and no mass divides: the
    /// pass is `v + g * dt`, the same bits. Returns the dynamic bodies' kinetic energy at
    /// their new velocities: [`World::kinetic_energy`]'s terms, summed in its order from
    /// its start.
    #[inline(always)]
    fn accelerate<const NAME: bool, const PLAIN: bool, const EXACT: bool>(
        self,
        dt: f64,
        g: Vec2,
    ) -> f64 {
        debug_assert!(PLAIN || !EXACT, "exact under gravity alone");
        let RunColumns {
            kind,
            entity,
            mass,
            force,
            scale,
            velocity,
            disturbed,
            len,
        } = self;
        // `Iterator::sum`'s start, whatever its zero's sign.
        let mut sum: f64 = std::iter::empty::<f64>().sum();
        for k in 0..velocity.len() {
            if kind[k] != BodyKind::Dynamic {
                continue;
            }
            let v = velocity[k];
            // `+ Vec2::ZERO` is the loop's zero thrust, added as there: it turns a force
            // of -0.0 into +0.0, which can change the sum's sign bit, so the log's.
            let (pushed, s) = if PLAIN {
                (Vec2::ZERO, 1.0)
            } else {
                (force[k] + Vec2::ZERO, scale[k])
            };
            let changed = if EXACT {
                v + g * dt
            } else {
                accelerated(v, pushed, g, mass[k], s, dt)
            };
            if NAME && differs(changed, v) {
                disturbed.name(entity[k], len);
            }
            velocity[k] = changed;
            sum += super::measures::energy(mass[k], changed);
        }
        sum
    }
}

/// Whether `a` and `b` differ in any bit.
#[inline]
fn differs(a: Vec2, b: Vec2) -> bool {
    a.x.to_bits() != b.x.to_bits() || a.y.to_bits() != b.y.to_bits()
}
