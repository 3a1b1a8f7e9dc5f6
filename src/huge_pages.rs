//! A global allocator that asks Linux for transparent huge pages (2 MiB) on
//! large blocks.
//!
//! A BVH over a million triangles spans about 60 MB. With 4 KiB pages, nearly
//! every node or triangle block an incoherent ray reaches deep in the tree is
//! also a TLB miss, a page walk that a virtual machine pays twice (guest and
//! host tables). Embree advises huge pages for its own memory; binaries that
//! trace large scenes opt in the same way:
//!
//! ```
//! #[global_allocator]
//! static ALLOC: raypack::huge_pages::HugePageAlloc = raypack::huge_pages::HugePageAlloc;
//! # fn main() {}
//! ```
//!
//! Blocks of at least [`ADVISED_BYTES`] are mapped by the allocator itself,
//! aligned to a huge page and advised with `madvise(MADV_HUGEPAGE)` before any
//! page is touched, so the kernel backs them with huge pages from the first
//! fault (blocks from `malloc` may reuse pages already touched, and do not
//! start on a huge page boundary). The advice takes effect where the system's
//! transparent huge page mode is `madvise` or `always` ([`system_mode`] reads
//! it, for reports); it is a hint, which a kernel without the feature ignores.
//! Smaller blocks, and every block on other systems, come from the system
//! allocator.
//!
//! A freed large block stays mapped, up to [`KEPT_HUGE_BYTES`] in all, and the
//! next large block is cut from it: its pages are warm. A fresh huge page is
//! cleared by the kernel at its first touch (2 MiB of stores), and on these
//! VMs it may first come back from the host; a program that builds one large
//! tree after another (`raypack bench`) met fresh pages at every build.
//! glibc keeps small freed blocks alike ([`keep_freed_memory`]), and Embree
//! keeps its memory in pools of its own.

use std::alloc::{GlobalAlloc, Layout, System};

/// Size of a huge page on x86-64 (and of the common AArch64 configuration).
pub const HUGE_PAGE_BYTES: usize = 2 << 20;

/// Blocks this large or larger are mapped on huge pages, rounded up to whole
/// ones (the last, partly used, costs at most one huge page per block).
pub const ADVISED_BYTES: usize = 2 * HUGE_PAGE_BYTES;

/// The system allocator, with large blocks on huge pages.
#[derive(Clone, Copy, Debug, Default)]
pub struct HugePageAlloc;

/// True for the blocks [`HugePageAlloc`] maps itself.
#[inline]
fn is_huge(layout: Layout) -> bool {
    cfg!(target_os = "linux") && layout.size() >= ADVISED_BYTES && layout.align() <= HUGE_PAGE_BYTES
}

// SAFETY: small blocks are System's; large ones are whole private mappings of
// at least the requested size, aligned to a huge page (hence to any alignment
// `is_huge` admits), and unmapped with the same length they were mapped with.
unsafe impl GlobalAlloc for HugePageAlloc {
    #[inline]
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if is_huge(layout) {
            map::map(layout.size())
        } else {
            // SAFETY: the caller's contract is System's.
            unsafe { System.alloc(layout) }
        }
    }

    #[inline]
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if is_huge(layout) {
            map::map_zeroed(layout.size())
        } else {
            // SAFETY: the caller's contract is System's.
            unsafe { System.alloc_zeroed(layout) }
        }
    }

    #[inline]
    unsafe fn dealloc(&self, block: *mut u8, layout: Layout) {
        if is_huge(layout) {
            // SAFETY: `block` was mapped by `map::map` for this size.
            unsafe { map::unmap(block, layout.size()) }
        } else {
            // SAFETY: the caller's contract is System's.
            unsafe { System.dealloc(block, layout) }
        }
    }

    #[inline]
    unsafe fn realloc(&self, block: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: the caller guarantees `new_size` makes a valid layout.
        let new_layout = unsafe { Layout::from_size_align_unchecked(new_size, layout.align()) };
        if !is_huge(layout) && !is_huge(new_layout) {
            // SAFETY: the caller's contract is System's.
            return unsafe { System.realloc(block, layout, new_size) };
        }
        if is_huge(layout) && is_huge(new_layout) {
            let (pages, new_pages) = (
                layout.size().next_multiple_of(HUGE_PAGE_BYTES),
                new_size.next_multiple_of(HUGE_PAGE_BYTES),
            );
            if new_pages == pages {
                // The same whole huge pages hold the new size.
                return block;
            }
            if new_pages < pages {
                // Shrunk: the block keeps its first pages, and the whole
                // pages past them are given back as a block of their own.
                // SAFETY: `[new_pages, pages)` lies in the mapping of `block`
                // (whole huge pages, so a block as `map` makes them), and is
                // no longer the caller's.
                unsafe { map::unmap(block.add(new_pages), pages - new_pages) };
                return block;
            }
        }
        // Into a new block and out of the old: growth by doubling keeps the
        // copies to the final size in all.
        // SAFETY: `new_layout` is valid and non-zero (it is at least as large
        // as one of the two blocks, and `realloc` is never asked for size 0).
        let moved = unsafe { self.alloc(new_layout) };
        if !moved.is_null() {
            // SAFETY: both blocks hold at least the smaller size and do not overlap.
            unsafe {
                std::ptr::copy_nonoverlapping(block, moved, layout.size().min(new_size));
                self.dealloc(block, layout);
            }
        }
        moved
    }
}

/// Freed huge page blocks kept mapped for reuse, in all at most this many
/// bytes ([`HugePageAlloc`]'s module documentation).
pub const KEPT_HUGE_BYTES: usize = 256 << 20;

/// Mapping and unmapping whole huge pages, and keeping freed ones.
#[cfg(target_os = "linux")]
mod map {
    use std::sync::{Mutex, MutexGuard};

    use super::{HUGE_PAGE_BYTES, KEPT_HUGE_BYTES};

    /// Most runs of freed pages kept at once.
    const KEPT_RUNS: usize = 32;

    /// Freed runs of whole huge pages, still mapped: `(start, length)`, length
    /// 0 for an empty slot. 512 bytes.
    struct Kept {
        runs: [(usize, usize); KEPT_RUNS],
    }

    static KEPT: Mutex<Kept> = Mutex::new(Kept {
        runs: [(0, 0); KEPT_RUNS],
    });

    /// The kept runs (nothing in them panics, so a poisoned lock is still sound).
    fn kept() -> MutexGuard<'static, Kept> {
        KEPT.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    impl Kept {
        /// The first `len` bytes of the shortest kept run that holds them, the
        /// rest of the run kept; None if no run is long enough.
        fn take(&mut self, len: usize) -> Option<usize> {
            let slot = (0..KEPT_RUNS)
                .filter(|&i| self.runs[i].1 >= len)
                .min_by_key(|&i| self.runs[i].1)?;
            let (start, run) = self.runs[slot];
            self.runs[slot] = (start + len, run - len);
            Some(start)
        }

        /// Bytes in all the runs.
        fn bytes(&self) -> usize {
            self.runs.iter().map(|&(_, run)| run).sum()
        }

        /// Keep the run `[start, start + len)`; false (nothing kept) if every
        /// slot is taken or the kept bytes would pass [`KEPT_HUGE_BYTES`].
        fn keep(&mut self, start: usize, len: usize) -> bool {
            let Some(slot) = self.runs.iter().position(|&(_, run)| run == 0) else {
                return false;
            };
            if self.bytes() + len > KEPT_HUGE_BYTES {
                return false;
            }
            self.runs[slot] = (start, len);
            true
        }
    }

    /// A block of `bytes` rounded up to whole huge pages, starting on a huge
    /// page boundary and advised for huge pages: cut from a kept run, or
    /// mapped anew; null if the system has no such memory to give.
    pub fn map(bytes: usize) -> *mut u8 {
        let len = bytes.next_multiple_of(HUGE_PAGE_BYTES);
        // (The lock is let go before any system call.)
        let taken = kept().take(len);
        match taken {
            Some(start) => start as *mut u8,
            None => map_new(len),
        }
    }

    /// [`map`], every byte zero.
    pub fn map_zeroed(bytes: usize) -> *mut u8 {
        let len = bytes.next_multiple_of(HUGE_PAGE_BYTES);
        // (The lock is let go before the block is cleared.)
        let taken = kept().take(len);
        match taken {
            Some(start) => {
                // SAFETY: a kept run is mapped, writable and no one else's.
                unsafe { std::ptr::write_bytes(start as *mut u8, 0, len) };
                start as *mut u8
            }
            // Fresh anonymous mappings read as zeros.
            None => map_new(len),
        }
    }

    /// A fresh private anonymous mapping of `len` bytes (whole huge pages),
    /// starting on a huge page boundary and advised for huge pages.
    fn map_new(len: usize) -> *mut u8 {
        // Map one huge page more than needed, then unmap the slack before the
        // first boundary and after the block.
        // SAFETY: a fresh mapping the kernel places; no memory of ours is touched.
        let raw = unsafe {
            libc::mmap(
                std::ptr::null_mut(),
                len + HUGE_PAGE_BYTES,
                libc::PROT_READ | libc::PROT_WRITE,
                libc::MAP_PRIVATE | libc::MAP_ANONYMOUS,
                -1,
                0,
            )
        };
        if raw == libc::MAP_FAILED {
            return std::ptr::null_mut();
        }
        let start = (raw as usize).next_multiple_of(HUGE_PAGE_BYTES);
        let head = start - raw as usize;
        // SAFETY: both slack ranges lie inside the mapping just made, and the
        // block in between is untouched when it is advised. The advice is a
        // hint: its result is ignored (EINVAL without transparent huge pages).
        unsafe {
            if head > 0 {
                libc::munmap(raw, head);
            }
            if head < HUGE_PAGE_BYTES {
                libc::munmap((start + len) as *mut libc::c_void, HUGE_PAGE_BYTES - head);
            }
            libc::madvise(start as *mut libc::c_void, len, libc::MADV_HUGEPAGE);
        }
        start as *mut u8
    }

    /// Bytes kept now.
    #[cfg(test)]
    pub fn kept_bytes() -> usize {
        kept().bytes()
    }

    /// Give back a block `map` returned for `bytes`: kept for the next
    /// blocks while there is room, else unmapped.
    ///
    /// # Safety
    /// `block` came from `map(bytes)` and is not used again.
    pub unsafe fn unmap(block: *mut u8, bytes: usize) {
        let len = bytes.next_multiple_of(HUGE_PAGE_BYTES);
        let kept_it = kept().keep(block as usize, len);
        if !kept_it {
            // SAFETY: the caller's contract; the length is the one mapped.
            unsafe {
                libc::munmap(block.cast(), len);
            }
        }
    }
}

/// Other systems: `is_huge` is false, so nothing is mapped here.
#[cfg(not(target_os = "linux"))]
mod map {
    pub fn map(_bytes: usize) -> *mut u8 {
        unreachable!("huge page blocks are Linux only")
    }

    pub fn map_zeroed(_bytes: usize) -> *mut u8 {
        unreachable!("huge page blocks are Linux only")
    }

    pub unsafe fn unmap(_block: *mut u8, _bytes: usize) {
        unreachable!("huge page blocks are Linux only")
    }
}

/// Freed memory glibc's allocator keeps at the top of its heap for reuse
/// before it hands any back to the kernel ([`keep_freed_memory`]).
pub const KEPT_BYTES: usize = 256 << 20;

/// Have glibc's allocator keep what it frees for the next allocations instead
/// of handing it back to the kernel; returns whether it took the settings
/// (false on other C libraries and systems, where nothing changes).
///
/// By default glibc gives memory back when the free space at the top of its
/// heap passes a threshold it adjusts as the program runs, and a block it got
/// from `mmap` goes back at once. A program that builds one tree after
/// another (`raypack bench`) then meets fresh pages, each zeroed by the
/// kernel at its first touch, in some builds and not in others, by the luck
/// of where its blocks fell: a bunny's build ran 0.80 ms in one binary and
/// 0.95 ms in another with its tree built in a different order, 176 page
/// faults a build against 2. With the top [`KEPT_BYTES`] kept and blocks
/// below [`ADVISED_BYTES`] (the larger ones are [`HugePageAlloc`]'s own
/// mappings) taken from the heap, the same builds reuse warm pages. Embree
/// keeps its memory in pools of its own.
pub fn keep_freed_memory() -> bool {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        // SAFETY: mallopt only sets the allocator's parameters; the values
        // fit a C int and are within glibc's limits (the mmap threshold at
        // most 32 MiB on 64-bit systems).
        unsafe {
            libc::mallopt(libc::M_MMAP_THRESHOLD, ADVISED_BYTES as libc::c_int) == 1
                && libc::mallopt(libc::M_TRIM_THRESHOLD, KEPT_BYTES as libc::c_int) == 1
        }
    }
    #[cfg(not(all(target_os = "linux", target_env = "gnu")))]
    {
        false
    }
}

/// The system's transparent huge page mode (`always`, `madvise` or `never`),
/// or None where it cannot be read (not Linux, or no such feature).
pub fn system_mode() -> Option<String> {
    let setting = std::fs::read_to_string("/sys/kernel/mm/transparent_hugepage/enabled").ok()?;
    parse_mode(&setting)
}

/// The bracketed word of a sysfs choice list such as `always [madvise] never`.
fn parse_mode(setting: &str) -> Option<String> {
    let (_, rest) = setting.split_once('[')?;
    let (mode, _) = rest.split_once(']')?;
    Some(mode.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glibc_takes_the_settings_that_keep_freed_memory() {
        assert_eq!(
            keep_freed_memory(),
            cfg!(all(target_os = "linux", target_env = "gnu"))
        );
    }

    #[test]
    fn mode_is_the_bracketed_choice() {
        assert_eq!(parse_mode("always [madvise] never\n").as_deref(), Some("madvise"));
        assert_eq!(parse_mode("[always] madvise never").as_deref(), Some("always"));
        assert_eq!(parse_mode("always madvise never"), None);
    }

    #[test]
    fn blocks_of_every_size_round_trip() {
        let alloc = HugePageAlloc;
        // Small, at the threshold, and across it both ways by `realloc`.
        for bytes in [
            1,
            4096,
            ADVISED_BYTES / 2,
            ADVISED_BYTES - 1,
            ADVISED_BYTES,
            ADVISED_BYTES + 12345,
        ] {
            let layout = Layout::from_size_align(bytes, 64).expect("valid layout");
            // SAFETY: layouts of non-zero size; each block is freed with its layout.
            unsafe {
                let block = alloc.alloc_zeroed(layout);
                assert!(!block.is_null());
                if is_huge(layout) {
                    assert_eq!(block as usize % HUGE_PAGE_BYTES, 0, "{bytes} bytes");
                }
                let data = std::slice::from_raw_parts_mut(block, bytes);
                assert!(data.iter().all(|&b| b == 0));
                data.iter_mut().enumerate().for_each(|(i, b)| *b = i as u8);
                let grown = alloc.realloc(block, layout, 2 * bytes);
                assert!(!grown.is_null());
                let kept = std::slice::from_raw_parts(grown, bytes);
                assert!(kept.iter().enumerate().all(|(i, &b)| b == i as u8));
                let grown_layout = Layout::from_size_align(2 * bytes, 64).expect("valid layout");
                let shrunk = alloc.realloc(grown, grown_layout, bytes / 2 + 1);
                assert!(!shrunk.is_null());
                let kept = std::slice::from_raw_parts(shrunk, bytes / 2 + 1);
                assert!(kept.iter().enumerate().all(|(i, &b)| b == i as u8));
                alloc.dealloc(
                    shrunk,
                    Layout::from_size_align(bytes / 2 + 1, 64).expect("valid layout"),
                );
            }
        }
    }

    /// A freed large block is kept mapped and the next one cut from it, its
    /// pages as they were; a zeroed block cut from it reads as zeros. (Sizes
    /// no other test here asks for, since the kept runs are shared.)
    #[cfg(target_os = "linux")]
    #[test]
    fn freed_blocks_are_reused_warm_and_zeroed_on_request() {
        let alloc = HugePageAlloc;
        let layout = Layout::from_size_align(20 * HUGE_PAGE_BYTES + 1, 64).expect("valid layout");
        let smaller = Layout::from_size_align(20 * HUGE_PAGE_BYTES, 64).expect("valid layout");
        // SAFETY: non-zero layouts; each block is written within its size and
        // freed with its layout.
        unsafe {
            let block = alloc.alloc(layout);
            assert!(!block.is_null());
            block.write_bytes(0xa5, layout.size());
            alloc.dealloc(block, layout);
            // The same whole pages, still holding what was written.
            let again = alloc.alloc(smaller);
            assert_eq!(again, block);
            assert!(
                std::slice::from_raw_parts(again, smaller.size())
                    .iter()
                    .all(|&b| b == 0xa5)
            );
            alloc.dealloc(again, smaller);
            let zeroed = alloc.alloc_zeroed(smaller);
            assert!(!zeroed.is_null());
            assert!(
                std::slice::from_raw_parts(zeroed, smaller.size())
                    .iter()
                    .all(|&b| b == 0)
            );
            alloc.dealloc(zeroed, smaller);
        }
    }

    /// Freed blocks past [`KEPT_HUGE_BYTES`] in all are unmapped, not kept.
    #[cfg(target_os = "linux")]
    #[test]
    fn kept_blocks_are_bounded() {
        let alloc = HugePageAlloc;
        let layout =
            Layout::from_size_align(KEPT_HUGE_BYTES / 2 + HUGE_PAGE_BYTES, 64).expect("valid layout");
        // SAFETY: non-zero layouts; each block is freed once with its layout.
        unsafe {
            let blocks = [alloc.alloc(layout), alloc.alloc(layout)];
            assert!(blocks.iter().all(|b| !b.is_null()));
            blocks.iter().for_each(|&b| alloc.dealloc(b, layout));
            assert!(map::kept_bytes() <= KEPT_HUGE_BYTES);
        }
    }

    /// A large block shrunk to fewer whole huge pages stays where it was,
    /// with what it held (no copy); the pages past it are given back.
    #[test]
    fn shrinking_keeps_the_block_in_place() {
        let alloc = HugePageAlloc;
        let layout = Layout::from_size_align(12 * HUGE_PAGE_BYTES + 1, 64).expect("valid layout");
        let shrunk_size = 5 * HUGE_PAGE_BYTES - 7;
        // SAFETY: a non-zero layout; the block is written within its size and
        // freed with its final layout.
        unsafe {
            let block = alloc.alloc(layout);
            assert!(!block.is_null());
            let data = std::slice::from_raw_parts_mut(block, layout.size());
            data.iter_mut()
                .enumerate()
                .for_each(|(i, b)| *b = (i % 251) as u8);
            let shrunk = alloc.realloc(block, layout, shrunk_size);
            assert_eq!(shrunk, block);
            let kept = std::slice::from_raw_parts(shrunk, shrunk_size);
            assert!(kept.iter().enumerate().all(|(i, &b)| b == (i % 251) as u8));
            alloc.dealloc(
                shrunk,
                Layout::from_size_align(shrunk_size, 64).expect("valid layout"),
            );
        }
    }

    #[test]
    fn growth_within_the_last_huge_page_keeps_the_block() {
        let alloc = HugePageAlloc;
        let layout = Layout::from_size_align(ADVISED_BYTES + 12345, 8).expect("valid layout");
        // SAFETY: a non-zero layout; the block is freed with its final layout.
        unsafe {
            let block = alloc.alloc(layout);
            assert!(!block.is_null());
            block.write(7);
            let grown = alloc.realloc(block, layout, ADVISED_BYTES + 54321);
            assert_eq!(grown, block);
            assert_eq!(grown.read(), 7);
            alloc.dealloc(
                grown,
                Layout::from_size_align(ADVISED_BYTES + 54321, 8).expect("valid layout"),
            );
        }
    }
}
