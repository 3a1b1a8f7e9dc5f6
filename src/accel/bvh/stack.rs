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
    #[should_panic]
    fn pushing_past_capacity_panics() {
        let mut s = TraversalStack::<u8, WIDE_STACK_SLOTS>::new();
        for _ in 0..WIDE_STACK_SLOTS {
            s.push(0);
        }
    }
}
