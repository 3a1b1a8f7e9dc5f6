//! The traversal stack: a fixed-capacity LIFO on the call stack whose storage is
//! left uninitialised, so starting a query costs no memset (a zeroed array of a
//! few kilobytes per ray or packet was a measurable share of a small scene's
//! traversal time).

use std::mem::MaybeUninit;

use crate::accel::bvh::build_sah::MAX_DEPTH;

/// Slots of a single-ray traversal's stack (12-byte entries: 3 KiB). The
/// collapse into wide nodes keeps every root-to-leaf path within it (see
/// [`pending_budget`](crate::accel::bvh::wide::pending_budget)). Kept small on
/// purpose: a stack frame past one 4 KiB page gets probed on every call, which
/// cost a third of the single-ray time on a 1,000-triangle scene.
pub const WIDE_STACK_SLOTS: usize = 256;

/// Entries a packet traversal of the binary tree can hold at once: one far
/// child per level; plus the spare slot.
pub const BINARY_STACK_SLOTS: usize = MAX_DEPTH + 2;

/// A LIFO of up to `N − 1` `Copy` entries in `N` slots (the last is a spare,
/// which [`TraversalStack::push_if`] may write without keeping). `N · size_of::<T>()` + 8 bytes.
/// `N` is sized to the tree traversed: a needlessly large stack costs stack
/// probes and cold cache lines on every query.
pub struct TraversalStack<T: Copy, const N: usize> {
    entries: [MaybeUninit<T>; N],
    len: usize,
}

impl<T: Copy, const N: usize> TraversalStack<T, N> {
    /// An empty stack (nothing is written).
    #[inline(always)]
    pub fn new() -> Self {
        Self {
            entries: [const { MaybeUninit::uninit() }; N],
            len: 0,
        }
    }

    /// Push `entry`. Panics past `N − 1` entries (the last slot is the spare),
    /// which no tree the builder makes can reach with the capacities above.
    #[inline(always)]
    pub fn push(&mut self, entry: T) {
        self.push_if(entry, true);
    }

    /// Push `entry` if `keep`. The entry is written either way, so the choice
    /// costs no branch (traversal pushes a far child only when there is one).
    #[inline(always)]
    pub fn push_if(&mut self, entry: T, keep: bool) {
        assert!(self.len + usize::from(keep) < N, "traversal stack overflow");
        self.entries[self.len] = MaybeUninit::new(entry);
        self.len += usize::from(keep);
    }

    /// Pop the last entry pushed.
    #[inline(always)]
    pub fn pop(&mut self) -> Option<T> {
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        // SAFETY: entries below `len` were all written by `push`.
        Some(unsafe { self.entries[self.len].assume_init() })
    }

    /// Number of entries.
    #[inline(always)]
    pub fn len(&self) -> usize {
        self.len
    }

    /// True when empty.
    #[inline(always)]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The entries, bottom first.
    #[inline(always)]
    pub fn as_mut_slice(&mut self) -> &mut [T] {
        // SAFETY: entries below `len` were all written by `push`, and
        // `MaybeUninit<T>` has the layout of `T`.
        unsafe { std::slice::from_raw_parts_mut(self.entries.as_mut_ptr().cast::<T>(), self.len) }
    }
}

impl<T: Copy, const N: usize> Default for TraversalStack<T, N> {
    fn default() -> Self {
        Self::new()
    }
}

/// The slots of a stack whose length its user keeps, for the single-ray walk
/// ([`traverse_single`](super::traverse_single)), which keeps it in a local
/// beside the child it visits next. A length stored next to slots indexed at
/// run time stays in memory (the compiler cannot tell it from the slots), and
/// was loaded and stored at every push and pop; a local lives in a register.
/// `N` is a power of two, so an index is kept in bounds by a mask rather than
/// a compare and branch: a length past `N − 1` (which no tree the builder
/// makes can reach, see [`pending_budget`](super::wide::pending_budget)) wraps
/// around, fails the debug assertion in tests, and never touches memory
/// outside the slots. `N · size_of::<T>()` bytes.
pub struct StackSlots<T: Copy, const N: usize> {
    entries: [MaybeUninit<T>; N],
}

impl<T: Copy, const N: usize> StackSlots<T, N> {
    /// No entries (nothing is written).
    #[inline(always)]
    pub fn new() -> Self {
        const { assert!(N.is_power_of_two()) };
        Self {
            entries: [const { MaybeUninit::uninit() }; N],
        }
    }

    /// Write `entry` above the `len` entries held, and return the length
    /// after pushing it if `keep` (the entry is written either way, so the
    /// choice costs no branch).
    #[inline(always)]
    pub fn push_if(&mut self, len: usize, entry: T, keep: bool) -> usize {
        debug_assert!(len + usize::from(keep) < N, "traversal stack overflow");
        self.entries[len % N] = MaybeUninit::new(entry);
        len + usize::from(keep)
    }

    /// The top of the `len` entries held, and the length without it; None
    /// when `len` is 0.
    #[inline(always)]
    pub fn pop(&self, len: usize) -> Option<(T, usize)> {
        let len = len.checked_sub(1)?;
        // SAFETY: every push (or put) writes the slot it indexes before the
        // length passes it, so each slot below a length (modulo N) has been written.
        Some((unsafe { self.entries[len % N].assume_init() }, len))
    }

    /// Write `entry` into position `at` (counted from the bottom), as part of
    /// a run the caller pushes out of order and then holds whole.
    #[inline(always)]
    pub fn put(&mut self, at: usize, entry: T) {
        debug_assert!(at + 1 < N, "traversal stack overflow");
        self.entries[at % N] = MaybeUninit::new(entry);
    }
}

impl<T: Copy, const N: usize> Default for StackSlots<T, N> {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pops_in_reverse_order_of_pushes() {
        const N: usize = 10;
        let mut s = TraversalStack::<(u32, f32), N>::new();
        assert!(s.is_empty() && s.pop().is_none());
        for k in 0..N as u32 - 1 {
            s.push((k, k as f32));
        }
        s.push_if((99, 99.0), false);
        assert_eq!(s.len(), N - 1);
        s.as_mut_slice().swap(0, 1);
        for k in (2..N as u32 - 1).rev() {
            assert_eq!(s.pop(), Some((k, k as f32)));
        }
        assert_eq!(s.pop(), Some((0, 0.0)));
        assert_eq!(s.pop(), Some((1, 1.0)));
        assert!(s.pop().is_none());
    }

    #[test]
    fn slots_pop_in_reverse_order_of_pushes() {
        const N: usize = 8;
        let mut s = StackSlots::<(u32, f32), N>::new();
        assert!(s.pop(0).is_none());
        let mut len = 0;
        for k in 0..N as u32 - 1 {
            len = s.push_if(len, (k, k as f32), true);
        }
        assert_eq!(s.push_if(len, (99, 99.0), false), N - 1);
        // Two entries rewritten in place, as a ranked run is written.
        s.put(0, (1, 1.0));
        s.put(1, (0, 0.0));
        for k in (2..N as u32 - 1).rev() {
            let (entry, rest) = s.pop(len).unwrap();
            assert_eq!((entry, rest), ((k, k as f32), k as usize));
            len = rest;
        }
        assert_eq!(s.pop(len), Some(((0, 0.0), 1)));
        assert_eq!(s.pop(1), Some(((1, 1.0), 0)));
    }

    #[test]
    #[cfg(debug_assertions)]
    #[should_panic(expected = "traversal stack overflow")]
    fn slots_past_capacity_fail_the_debug_assertion() {
        let mut s = StackSlots::<u8, 4>::new();
        let mut len = 0;
        for _ in 0..4 {
            len = s.push_if(len, 0, true);
        }
    }

    #[test]
    #[cfg(debug_assertions)]
    #[should_panic(expected = "traversal stack overflow")]
    fn a_ranked_run_past_capacity_fails_the_debug_assertion() {
        let mut s = StackSlots::<u8, 4>::new();
        // Positions 0..3 leave the spare slot free; position 3 would take it.
        for at in (0..4).rev() {
            s.put(at, 0);
        }
    }

    #[test]
    #[should_panic]
    fn pushing_past_capacity_panics() {
        let mut s = TraversalStack::<u8, WIDE_STACK_SLOTS>::new();
        for _ in 0..WIDE_STACK_SLOTS {
            s.push(0);
        }
    }
}
