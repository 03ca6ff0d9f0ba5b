//! How [`PackedWorld`](super::PackedWorld) writes its runs of scenery (see `packed.rs`):
//! a run is consecutive ids at `start + step * k`; [`RunCoder`] writes each as a few LEB128
//! numbers, [`RunReader`] reads them back.

use ricochet_geom::Vec2;

use crate::def::{BodyKind, LayerId};

/// Scenery bodies with consecutive ids `index..index + count`, the `k`-th at
/// `start + step * k`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Run {
    pub(super) index: u32,
    pub(super) count: u32,
    pub(super) start: Vec2,
    /// Its place in `kinds`.
    pub(super) kind: u32,
}

/// What the bodies of a run share, bit for bit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct RunKind {
    pub(super) generation: u32,
    pub(super) layer: LayerId,
    pub(super) kind: BodyKind,
    /// The look: shape and name.
    pub(super) shape_id: u32,
    pub(super) angle: u64,
    pub(super) step: (u64, u64),
}

/// The `k`-th position of a run: the formula of
/// [`World::spawn_tiles`](crate::world::World::spawn_tiles).
pub(super) fn at(start: Vec2, step: Vec2, k: u32) -> Vec2 {
    start + step * f64::from(k)
}

/// Whether two positions are the same bits.
pub(super) fn same(a: Vec2, b: Vec2) -> bool {
    a.x.to_bits() == b.x.to_bits() && a.y.to_bits() == b.y.to_bits()
}

/// Writes runs as bytes, each as LEB128 numbers: the distance of its first id from the end
/// of the run before, its length, its kind, and `m + 1` when its start is the previous
/// run's start plus `m` steps of its kind (the same kind, bit for bit), else 0 and the
/// start's 16 bytes.
#[derive(Default)]
pub(super) struct RunCoder {
    pub(super) bytes: Vec<u8>,
    pub(super) last: Option<Run>,
}

impl RunCoder {
    pub(super) fn push(&mut self, r: Run, kinds: &[RunKind]) {
        let end = self.last.map_or(0, |l| l.index + l.count);
        self.var(u64::from(r.index - end));
        self.var(u64::from(r.count));
        self.var(u64::from(r.kind));
        match self.last.and_then(|l| steps_between(l, r, kinds)) {
            Some(m) => self.var(u64::from(m) + 1),
            None => {
                self.var(0);
                self.bytes
                    .extend_from_slice(&r.start.x.to_bits().to_le_bytes());
                self.bytes
                    .extend_from_slice(&r.start.y.to_bits().to_le_bytes());
            }
        }
        self.last = Some(r);
    }

    fn var(&mut self, mut x: u64) {
        while x >= 0x80 {
            self.bytes.push((x as u8) | 0x80);
            x >>= 7;
        }
        self.bytes.push(x as u8);
    }
}

/// The `m` for which `b`'s start is exactly `a`'s plus `m` steps, when `a` and `b` are runs
/// of one kind.
pub(super) fn steps_between(a: Run, b: Run, kinds: &[RunKind]) -> Option<u32> {
    if a.kind != b.kind {
        return None;
    }
    let step = kinds[a.kind as usize].step();
    let d = b.start - a.start;
    // The larger component of the step gives the count; the check below is bit for bit.
    let m = if step.x.abs() >= step.y.abs() {
        d.x / step.x
    } else {
        d.y / step.y
    };
    let m = m.round();
    if !(0.0..=f64::from(u32::MAX)).contains(&m) {
        return None;
    }
    let m = m as u32;
    same(at(a.start, step, m), b.start).then_some(m)
}

/// Reads what [`RunCoder`] wrote (bytes it wrote itself: never malformed).
pub(super) struct RunReader<'a> {
    pub(super) bytes: &'a [u8],
    pub(super) kinds: &'a [RunKind],
    pub(super) last: Option<Run>,
}

impl RunReader<'_> {
    fn var(&mut self) -> u64 {
        let mut x = 0u64;
        for shift in (0..64).step_by(7) {
            let Some((&b, rest)) = self.bytes.split_first() else {
                break;
            };
            self.bytes = rest;
            x |= u64::from(b & 0x7f) << shift;
            if b < 0x80 {
                break;
            }
        }
        x
    }

    fn bits(&mut self) -> f64 {
        let (b, rest) = self.bytes.split_at(8);
        self.bytes = rest;
        f64::from_bits(u64::from_le_bytes(b.try_into().expect("8 bytes")))
    }
}

impl Iterator for RunReader<'_> {
    type Item = Run;

    fn next(&mut self) -> Option<Run> {
        if self.bytes.is_empty() {
            return None;
        }
        let end = self.last.map_or(0, |l| l.index + l.count);
        let index = end + self.var() as u32;
        let count = self.var() as u32;
        let kind = self.var() as u32;
        let start = match (self.var(), self.last) {
            (0, _) | (_, None) => Vec2::new(self.bits(), self.bits()),
            (m, Some(l)) => at(l.start, self.kinds[kind as usize].step(), (m - 1) as u32),
        };
        let r = Run {
            index,
            count,
            start,
            kind,
        };
        self.last = Some(r);
        Some(r)
    }
}

impl RunKind {
    pub(super) fn step(&self) -> Vec2 {
        Vec2::new(f64::from_bits(self.step.0), f64::from_bits(self.step.1))
    }
}
