//! Values many bodies share, stored once: the world's shape table ([`ShapeTable`]) and name
//! table ([`Interned`]). A body holds a `u32` id; a value lives while some body uses it and
//! its id is then reused.
//!
//! Ids are private to the world and never reach an output, so which id a value gets does
//! not matter for determinism (it is a function of the spawn and removal history anyway).

use std::collections::{BTreeMap, BTreeSet};
use std::sync::atomic::{AtomicU64, Ordering};

use ricochet_geom::{Bounds, MAX_POLYGON_VERTICES, Primitive, Shape, Vec2};

/// Values stored once, looked up by a key that is equal exactly when the values are.
#[derive(Clone, Debug)]
pub(crate) struct Interned<K: Ord, V> {
    /// Each id's key and value (`None` once no body uses it).
    entries: Vec<Option<(K, V)>>,
    /// How many bodies use each id.
    users: Vec<u32>,
    /// Ids no body uses, to reuse.
    free: Vec<u32>,
    /// The id of each key in use.
    ids: BTreeMap<K, u32>,
}

impl<K: Ord, V> Default for Interned<K, V> {
    fn default() -> Self {
        Interned {
            entries: Vec::new(),
            users: Vec::new(),
            free: Vec::new(),
            ids: BTreeMap::new(),
        }
    }
}

impl<K: Ord + Clone, V> Interned<K, V> {
    /// The id of `key`'s value, one more user counted; `value` makes it when it is new.
    pub(crate) fn acquire<Q>(&mut self, key: &Q, value: impl FnOnce() -> V) -> u32
    where
        K: std::borrow::Borrow<Q>,
        Q: Ord + ToOwned<Owned = K> + ?Sized,
    {
        if let Some(&id) = self.ids.get(key) {
            self.users[id as usize] += 1;
            return id;
        }
        let entry = Some((key.to_owned(), value()));
        let id = match self.free.pop() {
            Some(id) => {
                self.entries[id as usize] = entry;
                self.users[id as usize] = 1;
                id
            }
            None => {
                self.entries.push(entry);
                self.users.push(1);
                u32::try_from(self.entries.len() - 1).expect("fewer than 2^32 distinct values")
            }
        };
        self.ids.insert(key.to_owned(), id);
        id
    }

    /// One user of `id` fewer; the value is dropped with its last user.
    pub(crate) fn release(&mut self, id: u32) {
        let users = &mut self.users[id as usize];
        *users -= 1;
        if *users == 0
            && let Some((key, _)) = self.entries[id as usize].take()
        {
            self.ids.remove(&key);
            self.free.push(id);
        }
    }

    /// The key of an id in use.
    #[inline]
    pub(crate) fn key(&self, id: u32) -> &K {
        &self.entries[id as usize].as_ref().expect("an id in use").0
    }

    /// The id of `key`'s value, if a body uses it.
    pub(crate) fn id<Q>(&self, key: &Q) -> Option<u32>
    where
        K: std::borrow::Borrow<Q>,
        Q: Ord + ?Sized,
    {
        self.ids.get(key).copied()
    }

    /// Heap bytes held, counting `key_bytes` for each key's own heap.
    pub(crate) fn heap_bytes(&self, key_bytes: impl Fn(&K) -> usize) -> usize {
        let keys: usize = self.ids.keys().map(&key_bytes).sum::<usize>() * 2;
        self.entries.capacity() * size_of::<Option<(K, V)>>()
            + self.users.capacity() * 4
            + self.free.capacity() * 4
            // A B-tree node holds up to 11 keys and values; count each entry at full size.
            + self.ids.len() * (size_of::<K>() + 4 + 8)
            + keys
    }
}

/// The shapes of the world, one copy each with each name it goes with, each with its bounds
/// at angle 0 relative to the body (scenery's bounds). An id is a shape and a name id
/// together (a body's *look*): a million tiles hold one `u32` a body for both, not two.
/// Two shapes share an id only when they are the same bit for bit
/// (`-0.0` and `0.0` are different shapes here; `==` would call them equal): they are found
/// by a hash of those bits ([`shape_key`]), and a candidate's bits are compared in full. The
/// bits are not kept: a scene of 100,000 different asteroids keeps each shape once and 16
/// bytes of index, not a second copy of its numbers.
#[derive(Clone, Debug, Default)]
pub(crate) struct ShapeTable {
    /// Each id's shape and bounds (`None` once no body uses it).
    entries: Vec<Option<(Shape, Bounds)>>,
    /// Each id's name id (in the world's name table).
    names: Vec<u32>,
    /// Each id's [`shape_class`]: the narrow phase groups its pairs by it, reading a byte
    /// a body instead of the shape.
    classes: Vec<u8>,
    /// Each id's [`Shape::reach`]: the narrow phase rules out a pair too far apart for it
    /// without reading either shape.
    reaches: Vec<f64>,
    /// How many bodies use each id.
    users: Vec<u32>,
    /// Ids no body uses, to reuse.
    free: Vec<u32>,
    /// `(hash of the shape's bits and name id, id)` of every id in use.
    ids: BTreeSet<(u64, u32)>,
    /// A candidate's bits, while comparing.
    scratch: Vec<u64>,
    /// Each id's serial: a number given to each value the table makes, never given twice in
    /// the process (a clone of the table keeps its serials: it holds the same values). A past
    /// frame's shapes (`history.rs`) are kept by it: an id's serial changes exactly when the
    /// id is given another shape.
    serials: Vec<u64>,
    /// The serial of the last value this table made (0: none yet).
    last_serial: u64,
}

/// The next serial of [`ShapeTable::serial`], process-wide: a table built anew (a restore
/// rebuilds the world) never repeats an earlier table's serial. Serials never reach an
/// output, so which one a value gets does not matter for determinism.
static NEXT_SERIAL: AtomicU64 = AtomicU64::new(1);

/// A number never handed out before in this process (never 0): the serials of the shape
/// table and of the world's layout ([`crate::World`]'s, `history.rs`).
pub(crate) fn next_serial() -> u64 {
    NEXT_SERIAL.fetch_add(1, Ordering::Relaxed)
}

impl ShapeTable {
    /// The id of the shape whose bits are `key` ([`shape_key`]) with name id `name`, one
    /// more user counted; `value` makes it (with its bounds) when it is new.
    pub(crate) fn acquire(
        &mut self,
        key: &[u64],
        name: u32,
        value: impl FnOnce() -> (Shape, Bounds),
    ) -> u32 {
        let hash = fnv1a(key, name);
        for &(_, id) in self.ids.range((hash, 0)..=(hash, u32::MAX)) {
            if self.names[id as usize] != name {
                continue;
            }
            let (shape, _) = self.entries[id as usize].as_ref().expect("an id in use");
            shape_key(shape, &mut self.scratch);
            if self.scratch.as_slice() == key {
                self.users[id as usize] += 1;
                return id;
            }
        }
        let entry = value();
        let (class, reach) = (shape_class(&entry.0), entry.0.reach());
        let entry = Some(entry);
        let serial = next_serial();
        self.last_serial = serial;
        let id = match self.free.pop() {
            Some(id) => {
                self.entries[id as usize] = entry;
                self.names[id as usize] = name;
                self.classes[id as usize] = class;
                self.reaches[id as usize] = reach;
                self.users[id as usize] = 1;
                self.serials[id as usize] = serial;
                id
            }
            None => {
                self.entries.push(entry);
                self.names.push(name);
                self.classes.push(class);
                self.reaches.push(reach);
                self.users.push(1);
                self.serials.push(serial);
                u32::try_from(self.entries.len() - 1).expect("fewer than 2^32 distinct shapes")
            }
        };
        self.ids.insert((hash, id));
        id
    }

    /// The name id of an id.
    #[inline]
    pub(crate) fn name(&self, id: u32) -> u32 {
        self.names[id as usize]
    }

    /// The [`shape_class`] of an id in use.
    #[inline]
    pub(crate) fn class(&self, id: u32) -> u8 {
        self.classes[id as usize]
    }

    /// The [`Shape::reach`] of an id.
    #[inline]
    pub(crate) fn reach(&self, id: u32) -> f64 {
        self.reaches[id as usize]
    }

    /// One user of `id` fewer; the shape is dropped with its last user.
    pub(crate) fn release(&mut self, id: u32) {
        let users = &mut self.users[id as usize];
        *users -= 1;
        if *users == 0
            && let Some((shape, _)) = self.entries[id as usize].take()
        {
            shape_key(&shape, &mut self.scratch);
            let hash = fnv1a(&self.scratch, self.names[id as usize]);
            self.ids.remove(&(hash, id));
            self.free.push(id);
        }
    }

    /// The shape and bounds of an id in use.
    #[inline]
    pub(crate) fn get(&self, id: u32) -> &(Shape, Bounds) {
        self.entries[id as usize].as_ref().expect("an id in use")
    }

    /// Asks for the first cache line of `id`'s entry, and its reach, without reading them
    /// (`prefetch.rs`).
    #[inline]
    pub(crate) fn prefetch(&self, id: u32) {
        if let Some(entry) = self.entries.get(id as usize) {
            crate::prefetch::line_of(entry);
            crate::prefetch::line_of(&self.reaches[id as usize]);
        }
    }

    /// The shape and bounds of `id`, if it is in use.
    pub(crate) fn try_get(&self, id: u32) -> Option<&(Shape, Bounds)> {
        self.entries.get(id as usize)?.as_ref()
    }

    /// The serial of `id`'s shape (see the field): the same while the id holds that shape.
    #[inline]
    pub(crate) fn serial(&self, id: u32) -> u64 {
        self.serials[id as usize]
    }

    /// The serial of the last shape this table made: unchanged while no id was given a new
    /// shape.
    pub(crate) fn last_serial(&self) -> u64 {
        self.last_serial
    }

    /// How many ids have been handed out (some may be free now).
    pub(crate) fn len(&self) -> u32 {
        self.entries.len() as u32
    }

    /// Heap bytes held (a compound's parts not included).
    pub(crate) fn heap_bytes(&self) -> usize {
        self.entries.capacity() * size_of::<Option<(Shape, Bounds)>>()
            + self.names.capacity() * 4
            + self.classes.capacity()
            + self.reaches.capacity() * size_of::<f64>()
            + self.users.capacity() * 4
            + self.free.capacity() * 4
            + self.serials.capacity() * 8
            // A B-tree node holds up to 11 keys; count each entry at a full node's share.
            + self.ids.len() * (size_of::<(u64, u32)>() + 8)
            + self.scratch.capacity() * 8
    }
}

/// How many values [`shape_class`] gives.
pub(crate) const SHAPE_CLASSES: u8 = 12;

/// Which code of the narrow phase a shape takes: its one primitive's kind, a polygon's by
/// its vertex count (3 to 8: the loops over them run as many times), or a compound's.
pub(crate) fn shape_class(shape: &Shape) -> u8 {
    const _: () = assert!(MAX_POLYGON_VERTICES == 8, "a class for each polygon size");
    match shape.primitives() {
        [Primitive::Circle(_)] => 0,
        [Primitive::Aabb(_)] => 1,
        [Primitive::Obb(_)] => 2,
        [Primitive::Capsule(_)] => 3,
        [Primitive::Segment(_)] => 4,
        // 5 to 10.
        [Primitive::Polygon(p)] => 2 + p.vertices().len().clamp(3, 8) as u8,
        _ => SHAPE_CLASSES - 1,
    }
}

/// A 64-bit FNV-1a hash of `key`'s words and `name`: fixed, so the table's layout is a
/// function of the shapes and names alone (it never reaches an output anyway).
fn fnv1a(key: &[u64], name: u32) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325_u64;
    for &w in key.iter().chain([&u64::from(name)]) {
        for b in w.to_le_bytes() {
            h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
        }
    }
    h
}

/// The bits that define `shape` into `out` (cleared first): per primitive its kind and
/// fields, in order.
pub(crate) fn shape_key(shape: &Shape, out: &mut Vec<u64>) {
    out.clear();
    for p in shape.primitives() {
        match p {
            Primitive::Circle(c) => out.extend([0.0, c.center.x, c.center.y, c.radius].map(bits)),
            Primitive::Aabb(b) => out.extend(
                [
                    1.0,
                    b.center.x,
                    b.center.y,
                    b.half_extents.x,
                    b.half_extents.y,
                ]
                .map(bits),
            ),
            Primitive::Obb(b) => out.extend(
                [
                    2.0,
                    b.center.x,
                    b.center.y,
                    b.half_extents.x,
                    b.half_extents.y,
                    b.angle,
                ]
                .map(bits),
            ),
            Primitive::Capsule(c) => {
                out.extend([3.0, c.a.x, c.a.y, c.b.x, c.b.y, c.radius].map(bits));
            }
            Primitive::Segment(g) => {
                out.extend([5.0, g.a.x, g.a.y, g.b.x, g.b.y].map(bits));
                // A missing ghost is NaN: no point has NaN coordinates.
                for v in [g.prev, g.next] {
                    let v = v.unwrap_or(Vec2::NAN);
                    out.extend([v.x, v.y].map(bits));
                }
            }
            Primitive::Polygon(poly) => {
                out.push(bits(4.0));
                out.push(poly.vertices().len() as u64);
                // The normals follow from the vertices.
                for v in poly.vertices() {
                    out.extend([bits(v.x), bits(v.y)]);
                }
            }
        }
    }
    // A single primitive and a compound of that one primitive are different shapes.
    if matches!(shape, Shape::Compound(_)) {
        out.push(u64::MAX);
    }
}

fn bits(x: impl Into<f64>) -> u64 {
    x.into().to_bits()
}

/// The body names of the world, one copy each.
pub(crate) type NameTable = Interned<String, ()>;

#[cfg(test)]
mod tests {
    use ricochet_geom::Vec2;

    use super::*;

    #[test]
    fn equal_shapes_share_an_id_and_a_freed_id_is_reused() {
        let mut t = ShapeTable::default();
        let mut key = Vec::new();
        let mut id = |t: &mut ShapeTable, s: &Shape| {
            shape_key(s, &mut key);
            t.acquire(key.as_slice(), 0, || {
                (s.clone(), s.bounds(&ricochet_geom::Pose::default()))
            })
        };
        let tile = Shape::aabb(Vec2::splat(0.5)).unwrap();
        let a = id(&mut t, &tile);
        assert_eq!(id(&mut t, &tile.clone()), a);
        let ball = Shape::circle(0.5).unwrap();
        let b = id(&mut t, &ball);
        assert_ne!(a, b);
        // Equal by `==`, different bits: not shared.
        let signed = Shape::capsule(Vec2::new(-0.0, 0.0), Vec2::new(1.0, 0.0), 0.5).unwrap();
        let unsigned = Shape::capsule(Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), 0.5).unwrap();
        assert_eq!(signed, unsigned);
        assert_ne!(id(&mut t, &signed), id(&mut t, &unsigned));
        t.release(b);
        assert_eq!(t.get(a).0, tile);
        let c = id(&mut t, &Shape::circle(2.0).unwrap());
        assert_eq!(c, b, "the freed id is reused");
        t.release(a);
        assert_eq!(t.get(a).0, tile, "one user left");
        // The same shape with another name: another id, that name's.
        shape_key(&tile, &mut key);
        let bounds = tile.bounds(&ricochet_geom::Pose::default());
        let named = t.acquire(key.as_slice(), 7, || (tile.clone(), bounds));
        assert_ne!(named, a);
        assert_eq!((&t.get(named).0, t.name(named), t.name(a)), (&tile, 7, 0));
        let again = t.acquire(key.as_slice(), 7, || unreachable!("the id is in use"));
        assert_eq!(again, named);
    }
}
