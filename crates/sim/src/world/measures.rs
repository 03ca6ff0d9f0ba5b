//! What the world measures of itself: its digest (the determinism gate's hash), its kinetic
//! energy (and where that sum overflows) and the heap bytes it holds.

use ricochet_geom::{Shape, Vec2};

use super::World;
use super::runs::RowRun;
use crate::def::BodyKind;

impl World {
    /// A 64-bit FNV-1a hash of every body's raw state bits in id order (entity, position,
    /// angle, velocity, angular velocity), like Box2D's determinism test: any change of any
    /// bit anywhere changes it.
    #[must_use]
    pub fn digest(&self) -> u64 {
        const PRIME: u64 = 0x0000_0100_0000_01b3;
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        let mut eat = |bits: u64| {
            for byte in bits.to_le_bytes() {
                h ^= u64::from(byte);
                h = h.wrapping_mul(PRIME);
            }
        };
        for i in 0..self.len() {
            eat(u64::from(self.entity[i].index) << 32 | u64::from(self.entity[i].generation));
            let (v, w) = (self.velocity(i), self.angular_velocity(i));
            for x in [
                self.position[i].x,
                self.position[i].y,
                self.angle[i],
                v.x,
                v.y,
                w,
            ] {
                eat(x.to_bits());
            }
        }
        h
    }

    /// True when every moving body's position, angle, velocity and angular velocity are
    /// finite; false when one is not, or (rarely) when they all are but a sum of them
    /// overflows. The caller looks value by value for the first that is not finite only when
    /// this says false.
    ///
    /// It sums whole columns, four lanes at a time: contiguous and branch-free, so the
    /// compiler vectorises it (through `movers` and `row` it cost as much as integrating). A
    /// NaN or an infinity anywhere makes a lane's sum not finite. The columns hold the static
    /// bodies' values too, which are finite (checked when set, never integrated), so reading
    /// them changes no answer; only an overflow of finite values can raise a false alarm,
    /// which the exact search then clears.
    #[must_use]
    pub(crate) fn moving_state_finite(&self) -> bool {
        let rows = &self.rows;
        lanes_finite(&self.angle)
            && lanes_finite(&rows.angular_velocity)
            && pairs_finite(&self.position)
            && pairs_finite(&rows.velocity)
    }

    /// Kinetic energy of the dynamic bodies, `sum(m v² / 2)` (translation only).
    #[must_use]
    pub fn kinetic_energy(&self) -> f64 {
        self.energy_sum(self.row_run(&self.movers))
    }

    /// [`World::kinetic_energy`], given [`World::row_run`] of the movers.
    fn energy_sum(&self, run: Option<RowRun>) -> f64 {
        if let Some(run) = run {
            // One run (`runs.rs`): the same terms, in the same order, read in place.
            let rows = &self.rows;
            return self.kind[run.indices()]
                .iter()
                .zip(&rows.mass[run.rows()])
                .zip(&rows.velocity[run.rows()])
                .filter(|((kind, _), _)| **kind == BodyKind::Dynamic)
                .map(|((_, m), v)| energy(*m, *v))
                .sum();
        }
        self.energies().map(|(_, e)| e).sum()
    }

    /// [`World::kinetic_energy`] at the end of a step, kept until a velocity changes
    /// ([`World::velocity_mut`], the forces stage), a body comes or goes, or a restore:
    /// mass and kind never change, so summing the same terms again in the same order would
    /// give the same bits. The forces stage's pass over the movers' run keeps the sum it
    /// makes of the velocities it writes (`motion.rs`). A debug build sums again and
    /// asserts them.
    pub(crate) fn step_kinetic_energy(&mut self) -> f64 {
        if let Some(kept) = self.kept_energy {
            debug_assert_eq!(
                kept.to_bits(),
                self.kinetic_energy().to_bits(),
                "no velocity changed, the same sum"
            );
            return kept;
        }
        // The movers' run as kept (`runs.rs`), not found again by a scan of their rows.
        let run = self.movers_run();
        let e = self.energy_sum(run);
        self.kept_energy = Some(e);
        e
    }

    /// The first dynamic body (world index, in [`World::kinetic_energy`]'s order) at which
    /// that sum stops being finite, if it does: every velocity can be finite while `m v²`
    /// overflows (a velocity past 1e154, or two bodies near `f64::MAX` each). `total` is
    /// [`World::kinetic_energy`] now (the step's reported sum, or summed again).
    #[must_use]
    pub(crate) fn kinetic_energy_overflow(&self, total: f64) -> Option<usize> {
        // Once a running sum is not finite, adding finite or infinite terms never makes it
        // finite again: a finite total means no prefix overflowed (the common answer, in
        // one pass without the per-body test).
        if total.is_finite() {
            return None;
        }
        let mut sum = 0.0;
        self.energies()
            .find(|&(_, e)| {
                sum += e;
                !sum.is_finite()
            })
            .map(|(i, _)| i)
    }

    /// Each dynamic body's world index and kinetic energy, in the order the sum adds them.
    fn energies(&self) -> impl Iterator<Item = (usize, f64)> + '_ {
        // Sliced to their exact lengths: the columns of one index share one bounds check.
        let n = self.kind.len();
        let (kind, row) = (&self.kind[..n], &self.row[..n]);
        let m = self.rows.mass.len();
        let (mass, velocity) = (&self.rows.mass[..m], &self.rows.velocity[..m]);
        self.movers
            .iter()
            .map(|&i| i as usize)
            .filter(move |&i| kind[i] == BodyKind::Dynamic)
            .map(move |i| {
                let r = row[i] as usize;
                (i, energy(mass[r], velocity[r]))
            })
    }

    /// The heap bytes the world holds: every column's capacity, the shape and name tables,
    /// the rows and the id allocator. An honest count of what it keeps, not of what the
    /// allocator adds around it.
    #[must_use]
    pub fn heap_bytes(&self) -> usize {
        fn cap<T>(v: &Vec<T>) -> usize {
            v.capacity() * size_of::<T>()
        }
        let compound_parts: usize = (0..self.shapes_len())
            .filter_map(|id| self.shapes.try_get(id))
            .map(|(s, _)| match s {
                Shape::Compound(c) => size_of_val(c.parts()),
                Shape::Primitive(_) => 0,
            })
            .sum();
        cap(&self.entity)
            + cap(&self.layer)
            + cap(&self.kind)
            + cap(&self.position)
            + cap(&self.angle)
            + cap(&self.shape_id)
            + cap(&self.row)
            + self.shapes.heap_bytes()
            + compound_parts
            + self.names.heap_bytes(|k| k.len())
            + self.rows.heap_bytes()
            + cap(&self.movers)
            + cap(&self.active)
            + cap(&self.non_boxes)
            + cap(&self.key)
            + self.ids.heap_bytes()
    }
}

/// Whether the sum of `xs` in four lanes is finite: false when one is not finite (or, rarely,
/// when finite values overflow a lane's sum).
fn lanes_finite(xs: &[f64]) -> bool {
    let mut acc = [0.0f64; 4];
    let chunks = xs.chunks_exact(4);
    let rest: f64 = chunks.remainder().iter().sum();
    for c in chunks {
        for (a, x) in acc.iter_mut().zip(c) {
            *a += x;
        }
    }
    ((acc[0] + acc[1]) + (acc[2] + acc[3]) + rest).is_finite()
}

/// [`lanes_finite`] over both coordinates of `xs`.
fn pairs_finite(xs: &[Vec2]) -> bool {
    let mut acc = [0.0f64; 4];
    let chunks = xs.chunks_exact(2);
    let rest = chunks.remainder().iter().fold(0.0, |s, v| s + (v.x + v.y));
    for c in chunks {
        acc[0] += c[0].x;
        acc[1] += c[0].y;
        acc[2] += c[1].x;
        acc[3] += c[1].y;
    }
    ((acc[0] + acc[1]) + (acc[2] + acc[3]) + rest).is_finite()
}

/// A body's kinetic energy of translation, `m v² / 2`, as [`World::kinetic_energy`] adds it.
#[inline]
pub(super) fn energy(mass: f64, velocity: Vec2) -> f64 {
    0.5 * mass * velocity.length_squared()
}

#[cfg(test)]
mod tests {
    use ricochet_geom::{Shape, Vec2};

    use super::World;
    use crate::def::{BodyDef, BodyKind};

    /// Worlds of four to eight moving bodies and a static one (every remainder of the lanes
    /// is read). Each of the six values a moving body has, made a NaN or an infinity, in
    /// each body in turn, is seen; a world of finite values is finite.
    #[test]
    fn a_non_finite_value_in_any_column_of_any_body_is_seen() {
        for n in 5..=9 {
            let mut w = World::new();
            for k in 0..n {
                w.spawn(&BodyDef {
                    kind: if k == 3 {
                        BodyKind::Static
                    } else {
                        BodyKind::Dynamic
                    },
                    shape: Shape::circle(1.0).unwrap(),
                    position: Vec2::new(f64::from(k) * 3.0, 0.0),
                    velocity: Vec2::new(1.0, -1.0),
                    ..BodyDef::default()
                });
            }
            assert!(w.moving_state_finite());
            let movers: Vec<usize> = w.movers().iter().map(|&i| i as usize).collect();
            assert_eq!(movers.len(), n as usize - 1);
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                for &i in &movers {
                    let r = w.row[i] as usize;
                    for field in 0..6 {
                        let mut v = w.clone();
                        match field {
                            0 => v.position[i].x = bad,
                            1 => v.position[i].y = bad,
                            2 => v.angle[i] = bad,
                            3 => v.rows.velocity[r].x = bad,
                            4 => v.rows.velocity[r].y = bad,
                            _ => v.rows.angular_velocity[r] = bad,
                        }
                        let what = format!("{n} bodies, body {i}, value {field}: {bad}");
                        assert!(!v.moving_state_finite(), "{what}");
                    }
                }
            }
        }
    }
}
