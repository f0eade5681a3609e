//! The traversal stack the BVH and the kd-tree walk with: a fixed array
//! whose slots are written before they are read, so nothing is cleared per
//! ray and a ray pays only for the entries it pushes, however deep the
//! tree (measured: docs/performance-log.md, eight-wide BVH).

use std::mem::MaybeUninit;

/// A stack of at most `N` entries. Pushing beyond `N` panics (the walks
/// size `N` from the tree's depth, so it never happens).
pub(super) struct Stack<T, const N: usize> {
    entries: [MaybeUninit<T>; N],
    len: usize,
}

impl<T: Copy, const N: usize> Stack<T, N> {
    /// An empty stack.
    #[inline(always)]
    pub fn new() -> Self {
        Self {
            entries: [const { MaybeUninit::uninit() }; N],
            len: 0,
        }
    }

    /// How many entries it holds.
    #[inline(always)]
    pub fn len(&self) -> usize {
        self.len
    }

    /// Adds `entry` on top.
    #[inline(always)]
    pub fn push(&mut self, entry: T) {
        self.entries[self.len].write(entry);
        self.len += 1;
    }

    /// Adds `entry` on top if `keep`, without a branch: the slot above the
    /// top is written either way, so the stack needs room for it.
    #[inline(always)]
    pub fn push_if(&mut self, entry: T, keep: bool) {
        self.entries[self.len].write(entry);
        self.len += usize::from(keep);
    }

    /// Removes the top entry.
    #[inline(always)]
    pub fn pop(&mut self) -> Option<T> {
        self.len = self.len.checked_sub(1)?;
        // SAFETY: every slot below `len` has been written (by `push`,
        // `push_if` or `insert_above`, each before raising `len`), and
        // entries are `Copy`.
        Some(unsafe { self.entries[self.len].assume_init() })
    }

    /// Adds `entry` among the entries above position `floor`, below every
    /// one for which `goes_under(&entry, &other)` holds in a row from the
    /// top: with entries above `floor` pushed this way, those for which it
    /// holds stay on top of it. Sorting in place: building the entries in a
    /// separate array and copying them over stalled on store forwarding
    /// (see docs/performance-log.md, eight-wide BVH).
    #[inline(always)]
    pub fn insert_above(&mut self, floor: usize, entry: T, goes_under: impl Fn(&T, &T) -> bool) {
        let mut j = self.len;
        // SAFETY: `j - 1 < len`, a written slot.
        while j > floor && goes_under(&entry, &unsafe { self.entries[j - 1].assume_init() }) {
            self.entries[j] = self.entries[j - 1];
            j -= 1;
        }
        self.entries[j].write(entry);
        self.len += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entries_come_back_last_in_first_out() {
        let mut stack = Stack::<u32, 4>::new();
        assert_eq!(stack.pop(), None);
        stack.push(1);
        stack.push(2);
        assert_eq!(
            (stack.len(), stack.pop(), stack.pop(), stack.pop()),
            (2, Some(2), Some(1), None)
        );
    }

    #[test]
    fn pushing_if_keeps_only_the_entries_asked_for() {
        let mut stack = Stack::<u32, 4>::new();
        for (x, keep) in [(1, true), (2, false), (3, true), (4, false)] {
            stack.push_if(x, keep);
        }
        let order: Vec<u32> = std::iter::from_fn(|| stack.pop()).collect();
        assert_eq!(order, [3, 1]);
    }

    #[test]
    fn inserting_above_a_floor_sorts_only_what_lies_above_it() {
        let mut stack = Stack::<u32, 8>::new();
        stack.push(1);
        let floor = stack.len();
        for x in [5, 9, 2, 7] {
            // Larger values go under, so the smallest ends on top.
            stack.insert_above(floor, x, |new, other| other < new);
        }
        let order: Vec<u32> = std::iter::from_fn(|| stack.pop()).collect();
        assert_eq!(order, [2, 5, 7, 9, 1]);
    }

    #[test]
    #[should_panic]
    fn pushing_beyond_the_capacity_panics_instead_of_writing_past_it() {
        let mut stack = Stack::<u32, 1>::new();
        stack.push(1);
        stack.push(2);
    }
}
