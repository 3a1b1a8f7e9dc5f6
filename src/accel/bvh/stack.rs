//! The traversal stack: a fixed-capacity LIFO on the call stack whose storage is
//! left uninitialised, so starting a query costs no memset (a zeroed array of a
//! few kilobytes per ray or packet was a measurable share of a small scene's
//! traversal time).

use std::mem::MaybeUninit;

use crate::accel::bvh::MAX_DEPTH;

/// Entries any traversal of a tree the builder makes can hold at once: each
/// wide level (at most [`MAX_DEPTH`], since every wide node spans at least one
/// binary level) leaves at most 3 of its 4 children pending, plus the 4 of the
/// node being expanded.
pub const STACK_CAPACITY: usize = 3 * MAX_DEPTH + 4;

/// A LIFO of up to [`STACK_CAPACITY`] `Copy` entries. `STACK_CAPACITY · size_of::<T>()` + 8 bytes.
pub struct TraversalStack<T: Copy> {
    entries: [MaybeUninit<T>; STACK_CAPACITY],
    len: usize,
}

impl<T: Copy> TraversalStack<T> {
    /// An empty stack (nothing is written).
    #[inline(always)]
    pub fn new() -> Self {
        Self {
            entries: [const { MaybeUninit::uninit() }; STACK_CAPACITY],
            len: 0,
        }
    }

    /// Push `entry`. Panics past [`STACK_CAPACITY`], which no tree the builder
    /// makes can reach.
    #[inline(always)]
    pub fn push(&mut self, entry: T) {
        self.entries[self.len] = MaybeUninit::new(entry);
        self.len += 1;
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

impl<T: Copy> Default for TraversalStack<T> {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pops_in_reverse_order_of_pushes() {
        let mut s = TraversalStack::<(u32, f32)>::new();
        assert!(s.is_empty() && s.pop().is_none());
        for k in 0..STACK_CAPACITY as u32 {
            s.push((k, k as f32));
        }
        assert_eq!(s.len(), STACK_CAPACITY);
        s.as_mut_slice().swap(0, 1);
        for k in (2..STACK_CAPACITY as u32).rev() {
            assert_eq!(s.pop(), Some((k, k as f32)));
        }
        assert_eq!(s.pop(), Some((0, 0.0)));
        assert_eq!(s.pop(), Some((1, 1.0)));
        assert!(s.pop().is_none());
    }

    #[test]
    #[should_panic]
    fn pushing_past_capacity_panics() {
        let mut s = TraversalStack::<u8>::new();
        for _ in 0..=STACK_CAPACITY {
            s.push(0);
        }
    }
}
