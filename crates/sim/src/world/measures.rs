//! What the world measures of itself: its digest (the determinism gate's hash), its kinetic
//! energy (and where that sum overflows) and the heap bytes it holds.

use ricochet_geom::{Shape, Vec2};

use super::{NO_ROW, World};
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
    /// finite, in one pass without an early exit or a branch a body; false when one is not,
    /// or (rarely) when they all are but a body's sum of them overflows. The caller looks
    /// value by value for the first that is not finite only when this says false.
    #[must_use]
    pub(crate) fn moving_state_finite(&self) -> bool {
        let n = self.entity.len();
        let (position, angle, row) = (&self.position[..n], &self.angle[..n], &self.row[..n]);
        let m = self.rows.velocity.len();
        let (velocity, spin) = (&self.rows.velocity[..m], &self.rows.angular_velocity[..m]);
        let mut finite = true;
        for &i in &self.movers {
            let i = i as usize;
            let (p, a) = (position[i], angle[i]);
            let (v, w) = match row[i] {
                NO_ROW => (Vec2::ZERO, 0.0),
                r => (velocity[r as usize], spin[r as usize]),
            };
            // A NaN or an infinity among the six makes their sum not finite; six finite
            // values make it finite unless it overflows (a false alarm: the caller's exact
            // test then decides).
            finite &= ((p.x + p.y) + (v.x + v.y) + (a + w)).is_finite();
        }
        finite
    }

    /// Kinetic energy of the dynamic bodies, `sum(m v² / 2)` (translation only).
    #[must_use]
    pub fn kinetic_energy(&self) -> f64 {
        self.energies().map(|(_, e)| e).sum()
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
                (i, 0.5 * mass[r] * velocity[r].length_squared())
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
