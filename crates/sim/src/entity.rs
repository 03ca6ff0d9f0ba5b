//! Generational entity ids, like Box2D's `b2BodyId` and rapier's `RigidBodyHandle`.

use std::collections::BTreeSet;

/// A body's id: a slot index and the generation of that slot. A destroyed body's slot is
/// reused by a later spawn with the next generation, so a stale id never finds the new body.
/// Ordered by index, then generation: the order of the world's columns and of contact pairs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Entity {
    /// Slot index; what logs call the body's `id`.
    pub index: u32,
    /// How many times the slot was used before.
    pub generation: u32,
}

/// `index:generation`, as logs write it (`5:1` is the second body in slot 5).
impl std::fmt::Display for Entity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}", self.index, self.generation)
    }
}

/// Hands out entity ids: the lowest free slot first, so ids stay small and the choice is
/// deterministic.
#[derive(Clone, Debug, Default)]
pub struct EntityAllocator {
    generations: Vec<u32>,
    free: BTreeSet<u32>,
}

impl EntityAllocator {
    /// Each slot's generation (a live body's, or the one a freed slot hands out next).
    pub(crate) fn generations(&self) -> &[u32] {
        &self.generations
    }

    /// The allocator whose slots have these generations, every slot not in `live` free (as
    /// every slot is that is not a live body's).
    /// `live` is ascending.
    pub(crate) fn from_parts(generations: Vec<u32>, live: impl Iterator<Item = u32>) -> Self {
        let mut live = live.peekable();
        let free = (0..generations.len() as u32)
            .filter(|&i| {
                let is_live = live.peek() == Some(&i);
                if is_live {
                    live.next();
                }
                !is_live
            })
            .collect();
        EntityAllocator { generations, free }
    }

    /// A new id.
    pub fn allocate(&mut self) -> Entity {
        if let Some(index) = self.free.pop_first() {
            let generation = self.generations[index as usize];
            return Entity { index, generation };
        }
        let index = u32::try_from(self.generations.len()).expect("fewer than 2^32 bodies");
        self.generations.push(0);
        Entity {
            index,
            generation: 0,
        }
    }

    /// Makes room for `additional` more ids.
    pub fn reserve(&mut self, additional: usize) {
        self.generations.reserve_exact(additional);
    }

    /// Heap bytes held (a B-tree entry of the free set counted at its key's size plus a
    /// pointer's).
    #[must_use]
    pub fn heap_bytes(&self) -> usize {
        self.generations.capacity() * 4 + self.free.len() * 12
    }

    /// Frees `entity`'s slot for reuse with the next generation.
    pub fn free(&mut self, entity: Entity) {
        let g = &mut self.generations[entity.index as usize];
        if *g == entity.generation {
            *g = g.wrapping_add(1);
            self.free.insert(entity.index);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_freed_slot_comes_back_with_a_new_generation() {
        let mut ids = EntityAllocator::default();
        let a = ids.allocate();
        let b = ids.allocate();
        ids.free(a);
        let c = ids.allocate();
        assert_eq!((c.index, c.generation), (a.index, 1));
        assert_ne!(c, a);
        assert_eq!(ids.allocate().index, b.index + 1);
    }
}
