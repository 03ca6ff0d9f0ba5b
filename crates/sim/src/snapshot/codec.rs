//! The snapshot's byte encoding: little-endian fixed-width numbers, a length before every
//! list and string, a tag before every enum, LEB128 for counts that are usually small. One
//! writer ([`Sink`]) writes both the snapshot's bytes and what [`crate::Simulation::checksum`]
//! hashes, so the two cover the same fields by construction; the [`Reader`] returns an error
//! at the first byte missing or out of range.

use ricochet_geom::{Aabb, Capsule, Circle, Obb, Polygon};
use ricochet_geom::{Pose, Primitive, Shape, Vec2};

use super::SnapshotError;
use crate::action::Action;
use crate::def::{Controller, Split};
use crate::entity::Entity;
use crate::world::Inputs;

/// Where encoded state goes: bytes, or a hash of them.
pub(crate) trait Sink {
    /// Appends raw bytes.
    fn put(&mut self, bytes: &[u8]);

    fn u8(&mut self, x: u8) {
        self.put(&[x]);
    }
    fn bool(&mut self, x: bool) {
        self.u8(u8::from(x));
    }
    fn u32(&mut self, x: u32) {
        self.put(&x.to_le_bytes());
    }
    fn u64(&mut self, x: u64) {
        self.put(&x.to_le_bytes());
    }
    fn u128(&mut self, x: u128) {
        self.put(&x.to_le_bytes());
    }
    /// LEB128: 7 bits a byte, low first (a run of 10,000 bodies is 2 bytes).
    fn var(&mut self, mut x: u64) {
        let mut b = [0u8; 10];
        let mut n = 0;
        while x >= 0x80 {
            b[n] = (x as u8) | 0x80;
            x >>= 7;
            n += 1;
        }
        b[n] = x as u8;
        self.put(&b[..=n]);
    }
    /// A float's bits: `-0.0` and NaN payloads are kept.
    fn f64(&mut self, x: f64) {
        self.u64(x.to_bits());
    }
    fn vec2(&mut self, v: Vec2) {
        self.f64(v.x);
        self.f64(v.y);
    }
    fn len(&mut self, n: usize) {
        self.u32(u32::try_from(n).unwrap_or(u32::MAX));
    }
    fn str(&mut self, s: &str) {
        self.len(s.len());
        self.put(s.as_bytes());
    }
    fn entity(&mut self, e: Entity) {
        self.u32(e.index);
        self.u32(e.generation);
    }
    fn opt_entity(&mut self, e: Option<Entity>) {
        self.bool(e.is_some());
        if let Some(e) = e {
            self.entity(e);
        }
    }
    fn pose(&mut self, p: Pose) {
        self.vec2(p.position);
        self.f64(p.angle);
    }
    fn inputs(&mut self, i: &Inputs) {
        // One byte: bit 0 the engine, bit 1 dropping through one-way platforms (so a
        // snapshot without a `drop` is the same bytes as before it existed).
        self.u8(u8::from(i.thrust) | (u8::from(i.drop) << 1));
        self.f64(i.turn);
        self.f64(i.run);
    }
    fn shape(&mut self, s: &Shape) {
        match s {
            Shape::Primitive(p) => {
                self.u8(0);
                self.primitive(p);
            }
            Shape::Compound(_) => {
                self.u8(1);
                self.len(s.primitives().len());
                for p in s.primitives() {
                    self.primitive(p);
                }
            }
        }
    }
    fn primitive(&mut self, p: &Primitive) {
        match p {
            Primitive::Circle(c) => {
                self.u8(0);
                self.vec2(c.center);
                self.f64(c.radius);
            }
            Primitive::Aabb(b) => {
                self.u8(1);
                self.vec2(b.center);
                self.vec2(b.half_extents);
            }
            Primitive::Obb(b) => {
                self.u8(2);
                self.vec2(b.center);
                self.vec2(b.half_extents);
                self.f64(b.angle);
            }
            Primitive::Capsule(c) => {
                self.u8(3);
                self.vec2(c.a);
                self.vec2(c.b);
                self.f64(c.radius);
            }
            Primitive::Polygon(g) => {
                self.u8(4);
                self.len(g.vertices().len());
                for v in g.vertices() {
                    self.vec2(*v);
                }
            }
            Primitive::Segment(g) => {
                self.u8(5);
                self.vec2(g.a);
                self.vec2(g.b);
                for ghost in [g.prev, g.next] {
                    match ghost {
                        None => self.u8(0),
                        Some(v) => {
                            self.u8(1);
                            self.vec2(v);
                        }
                    }
                }
            }
        }
    }
    fn controller(&mut self, c: Option<&Controller>) {
        match c {
            None => self.u8(0),
            Some(Controller::Ship {
                thrust,
                turn_rate,
                bullet,
                bullet_speed,
                muzzle,
            }) => {
                self.u8(1);
                self.f64(*thrust);
                self.f64(*turn_rate);
                self.str(bullet);
                self.f64(*bullet_speed);
                self.f64(*muzzle);
            }
            Some(Controller::Runner {
                run_speed,
                jump_speed,
            }) => {
                self.u8(2);
                self.f64(*run_speed);
                self.f64(*jump_speed);
            }
            Some(Controller::Walker { speed }) => {
                self.u8(3);
                self.f64(*speed);
            }
        }
    }
    fn splits(&mut self, s: &[Split]) {
        self.len(s.len());
        for c in s {
            self.str(&c.template);
            self.vec2(c.offset);
            self.vec2(c.velocity);
        }
    }
    fn action(&mut self, a: &Action) {
        match a {
            Action::Destroy => self.u8(0),
            Action::SetVelocity(v) => {
                self.u8(1);
                self.vec2(*v);
            }
            Action::ApplyImpulse(v) => {
                self.u8(2);
                self.vec2(*v);
            }
            Action::SetForce(v) => {
                self.u8(3);
                self.vec2(*v);
            }
            Action::Thrust(b) => {
                self.u8(4);
                self.bool(*b);
            }
            Action::Turn(x) => {
                self.u8(5);
                self.f64(*x);
            }
            Action::Fire => self.u8(6),
            Action::Move(x) => {
                self.u8(7);
                self.f64(*x);
            }
            Action::Jump => self.u8(8),
            Action::Drop => self.u8(9),
        }
    }
}

impl Sink for Vec<u8> {
    fn put(&mut self, bytes: &[u8]) {
        self.extend_from_slice(bytes);
    }
}

/// The hash of the snapshot's bytes, of its scene and of [`crate::Simulation::checksum`]'s
/// encoding: XXH3-64 (a kept, specified hash, the same on every platform) with a fixed seed.
pub(crate) fn hash(bytes: &[u8]) -> u64 {
    xxhash_rust::xxh3::xxh3_64_with_seed(bytes, SEED)
}

/// [`hash`] of everything written, for what is too large to gather first (a whole level).
pub(crate) struct Hasher(xxhash_rust::xxh3::Xxh3);

impl Default for Hasher {
    fn default() -> Self {
        Hasher(xxhash_rust::xxh3::Xxh3::with_seed(SEED))
    }
}

impl Hasher {
    pub(crate) fn finish(&self) -> u64 {
        self.0.digest()
    }
}

impl Sink for Hasher {
    fn put(&mut self, bytes: &[u8]) {
        self.0.update(bytes);
    }
}

/// "RCSN" and the format's first version: any fixed value would do, this one is ours.
const SEED: u64 = 0x5243_534e_0000_0002;

/// Reads what a [`Sink`] wrote, from a slice.
pub(crate) struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

fn bad(what: &str) -> SnapshotError {
    SnapshotError::malformed(what)
}

impl<'a> Reader<'a> {
    pub(crate) fn new(bytes: &'a [u8]) -> Reader<'a> {
        Reader { bytes, at: 0 }
    }

    /// Whether every byte was read.
    pub(crate) fn is_done(&self) -> bool {
        self.at == self.bytes.len()
    }

    fn take(&mut self, n: usize) -> Result<&'a [u8], SnapshotError> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len());
        let Some(end) = end else {
            return Err(SnapshotError::Truncated {
                needed: self.at as u64 + n as u64,
                found: self.bytes.len() as u64,
            });
        };
        let s = &self.bytes[self.at..end];
        self.at = end;
        Ok(s)
    }

    fn array<const N: usize>(&mut self) -> Result<[u8; N], SnapshotError> {
        let mut a = [0; N];
        a.copy_from_slice(self.take(N)?);
        Ok(a)
    }

    pub(crate) fn u8(&mut self) -> Result<u8, SnapshotError> {
        Ok(self.take(1)?[0])
    }
    pub(crate) fn bool(&mut self) -> Result<bool, SnapshotError> {
        match self.u8()? {
            0 => Ok(false),
            1 => Ok(true),
            _ => Err(bad("a flag other than 0 or 1")),
        }
    }
    pub(crate) fn u32(&mut self) -> Result<u32, SnapshotError> {
        Ok(u32::from_le_bytes(self.array()?))
    }
    pub(crate) fn u64(&mut self) -> Result<u64, SnapshotError> {
        Ok(u64::from_le_bytes(self.array()?))
    }
    pub(crate) fn u128(&mut self) -> Result<u128, SnapshotError> {
        Ok(u128::from_le_bytes(self.array()?))
    }
    pub(crate) fn var(&mut self) -> Result<u64, SnapshotError> {
        let mut x = 0u64;
        for shift in (0..64).step_by(7) {
            let b = self.u8()?;
            x |= u64::from(b & 0x7f) << shift;
            if b < 0x80 {
                return Ok(x);
            }
        }
        Err(bad("a count longer than 64 bits"))
    }
    pub(crate) fn f64(&mut self) -> Result<f64, SnapshotError> {
        Ok(f64::from_bits(self.u64()?))
    }
    pub(crate) fn vec2(&mut self) -> Result<Vec2, SnapshotError> {
        Ok(Vec2::new(self.f64()?, self.f64()?))
    }
    /// A list's length, checked against the bytes left (each item at least `min` bytes), so
    /// a damaged length never reserves gigabytes.
    pub(crate) fn len(&mut self, min: usize) -> Result<usize, SnapshotError> {
        let n = self.u32()? as usize;
        let left = self.bytes.len() - self.at;
        if n.saturating_mul(min.max(1)) > left {
            return Err(SnapshotError::Truncated {
                needed: self.at as u64 + n as u64 * min.max(1) as u64,
                found: self.bytes.len() as u64,
            });
        }
        Ok(n)
    }
    pub(crate) fn str(&mut self) -> Result<String, SnapshotError> {
        let n = self.len(1)?;
        String::from_utf8(self.take(n)?.to_vec()).map_err(|_| bad("a string that is not UTF-8"))
    }
    pub(crate) fn entity(&mut self) -> Result<Entity, SnapshotError> {
        Ok(Entity {
            index: self.u32()?,
            generation: self.u32()?,
        })
    }
    pub(crate) fn opt_entity(&mut self) -> Result<Option<Entity>, SnapshotError> {
        Ok(if self.bool()? {
            Some(self.entity()?)
        } else {
            None
        })
    }
    pub(crate) fn pose(&mut self) -> Result<Pose, SnapshotError> {
        Ok(Pose::new(self.vec2()?, self.f64()?))
    }
    pub(crate) fn inputs(&mut self) -> Result<Inputs, SnapshotError> {
        let flags = self.u8()?;
        if flags > 3 {
            return Err(bad("the input flags"));
        }
        Ok(Inputs {
            thrust: flags & 1 != 0,
            turn: self.f64()?,
            run: self.f64()?,
            drop: flags & 2 != 0,
        })
    }
    pub(crate) fn shape(&mut self) -> Result<Shape, SnapshotError> {
        match self.u8()? {
            0 => Ok(Shape::Primitive(self.primitive()?)),
            1 => {
                let n = self.len(17)?;
                let parts = (0..n)
                    .map(|_| self.primitive())
                    .collect::<Result<Vec<_>, _>>()?;
                Shape::compound(parts).map_err(|e| bad(&format!("shape: {e}")))
            }
            _ => Err(bad("a shape tag")),
        }
    }
    pub(crate) fn primitive(&mut self) -> Result<Primitive, SnapshotError> {
        Ok(match self.u8()? {
            0 => Primitive::Circle(Circle {
                center: self.vec2()?,
                radius: self.f64()?,
            }),
            1 => Primitive::Aabb(Aabb {
                center: self.vec2()?,
                half_extents: self.vec2()?,
            }),
            2 => Primitive::Obb(Obb {
                center: self.vec2()?,
                half_extents: self.vec2()?,
                angle: self.f64()?,
            }),
            3 => Primitive::Capsule(Capsule {
                a: self.vec2()?,
                b: self.vec2()?,
                radius: self.f64()?,
            }),
            4 => {
                let n = self.len(16)?;
                let v = (0..n).map(|_| self.vec2()).collect::<Result<Vec<_>, _>>()?;
                Primitive::Polygon(Polygon::new(&v).map_err(|e| bad(&format!("polygon: {e}")))?)
            }
            5 => {
                let (a, b) = (self.vec2()?, self.vec2()?);
                let mut ghost = || -> Result<Option<Vec2>, SnapshotError> {
                    Ok(match self.u8()? {
                        0 => None,
                        1 => Some(self.vec2()?),
                        _ => return Err(bad("a ghost point tag")),
                    })
                };
                let (prev, next) = (ghost()?, ghost()?);
                // Validated as a one-segment chain: finite, of some length.
                let one = Shape::chain(&[a, b], prev, next)
                    .map_err(|e| bad(&format!("chain segment: {e}")))?;
                one.primitives()[0]
            }
            _ => return Err(bad("a primitive tag")),
        })
    }
    pub(crate) fn controller(&mut self) -> Result<Option<Controller>, SnapshotError> {
        Ok(match self.u8()? {
            0 => None,
            1 => Some(Controller::Ship {
                thrust: self.f64()?,
                turn_rate: self.f64()?,
                bullet: self.str()?,
                bullet_speed: self.f64()?,
                muzzle: self.f64()?,
            }),
            2 => Some(Controller::Runner {
                run_speed: self.f64()?,
                jump_speed: self.f64()?,
            }),
            3 => Some(Controller::Walker { speed: self.f64()? }),
            _ => return Err(bad("a controller tag")),
        })
    }
    pub(crate) fn splits(&mut self) -> Result<Vec<Split>, SnapshotError> {
        let n = self.len(36)?;
        (0..n)
            .map(|_| {
                Ok(Split {
                    template: self.str()?,
                    offset: self.vec2()?,
                    velocity: self.vec2()?,
                })
            })
            .collect()
    }
    pub(crate) fn action(&mut self) -> Result<Action, SnapshotError> {
        Ok(match self.u8()? {
            0 => Action::Destroy,
            1 => Action::SetVelocity(self.vec2()?),
            2 => Action::ApplyImpulse(self.vec2()?),
            3 => Action::SetForce(self.vec2()?),
            4 => Action::Thrust(self.bool()?),
            5 => Action::Turn(self.f64()?),
            6 => Action::Fire,
            7 => Action::Move(self.f64()?),
            8 => Action::Jump,
            9 => Action::Drop,
            _ => return Err(bad("an action tag")),
        })
    }
}
