//! Mailboxing (Amanatides and Woo 1987): a primitive that straddles several
//! cells is met again in each of them, and testing it twice for one ray is
//! wasted work. A small direct-mapped cache of the ids tested last, kept on
//! the stack, catches nearly all repeats without allocating per ray; a
//! collision only evicts an id, so the worst case is a repeated test, never a
//! missed one.

/// Slots in the cache (a power of two).
const SLOTS: usize = 64;

/// The ids of recently tested primitives, one per slot, chosen by the id's
/// low bits.
#[derive(Clone, Debug)]
pub(crate) struct Mailbox {
    ids: [u32; SLOTS],
}

impl Mailbox {
    /// A cache that has seen nothing. Each slot starts with a value whose low
    /// bits point at another slot, so no id can match it.
    pub(crate) fn new() -> Self {
        Self {
            ids: std::array::from_fn(|slot| slot as u32 ^ 1),
        }
    }

    /// Records `id` as tested: false when it was the last id recorded in its
    /// slot (tested already), true when it must be tested now.
    #[inline]
    pub(crate) fn first_visit(&mut self, id: u32) -> bool {
        let slot = &mut self.ids[id as usize % SLOTS];
        if *slot == id {
            false
        } else {
            *slot = id;
            true
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn repeats_are_caught_and_collisions_only_evict() {
        let mut m = Mailbox::new();
        assert!((0..SLOTS as u32).all(|id| m.first_visit(id)));
        assert!((0..SLOTS as u32).all(|id| !m.first_visit(id)));
        assert!(m.first_visit(SLOTS as u32));
        assert!(m.first_visit(0));
        assert!(m.first_visit(u32::MAX) && !m.first_visit(u32::MAX));
        let mut fresh = Mailbox::new();
        assert!((0..1000).all(|id| fresh.first_visit(id * 7 + 1)));
    }
}
