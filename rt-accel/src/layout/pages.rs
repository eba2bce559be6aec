//! Large memory pages for a BVH's large arrays.
//!
//! A million-triangle BVH spans about 50 MB (terrain: 10.5 MB of nodes,
//! 42 MB of triangle packets). An incoherent ray fetches a node or leaf
//! from a different 4 KiB page at every level, so besides the cache miss
//! it misses the TLB (a second-level TLB covers a few MB of 4 KiB pages)
//! and waits for a page walk too. Backed by 2 MiB pages, the same arrays
//! need 27 TLB entries. Linux gives anonymous memory 2 MiB pages
//! (transparent huge pages) only in ranges the program advises with
//! `madvise(MADV_HUGEPAGE)` under its common `madvise` setting; Embree
//! advises its BVH memory this way.
//!
//! Incoherent rays gain; coherent ones, which revisit the same few pages,
//! do not change. The advice is only a hint: where the kernel does not take it (another setting, another OS,
//! no `std`), the arrays are ordinary memory and nothing else changes.

use alloc::vec::Vec;

/// Page size of the advised ranges.
#[cfg(all(feature = "std", target_os = "linux"))]
const LARGE_PAGE: usize = 2 << 20;

/// A copy of `src` in memory advised for large pages (where [`advise`]
/// does anything): the allocation is advised before it is first written,
/// so its pages are faulted in large.
pub(crate) fn large_copy<T: bytemuck::Pod>(src: &[T]) -> Vec<T> {
    let mut v = advised(src.len());
    v.extend_from_slice(src);
    v
}

/// `len` zeroed values in memory advised for large pages.
pub(crate) fn large_zeroed<T: bytemuck::Pod>(len: usize) -> Vec<T> {
    let mut v = advised(len);
    v.resize(len, T::zeroed());
    v
}

/// An empty vector with room for `len` values, advised before use.
fn advised<T>(len: usize) -> Vec<T> {
    let v = Vec::<T>::with_capacity(len);
    advise(v.as_ptr().cast::<u8>(), v.capacity() * size_of::<T>());
    v
}

/// Advises the whole 2 MiB pages inside `len` bytes from `ptr` (an
/// allocation this process owns, not yet written) for transparent huge
/// pages, and drops whatever pages back them now. Memory smaller than one
/// aligned large page is left alone.
#[cfg(all(feature = "std", target_os = "linux"))]
fn advise(ptr: *const u8, len: usize) {
    let addr = ptr.addr();
    let start = addr.next_multiple_of(LARGE_PAGE);
    let end = addr.saturating_add(len) / LARGE_PAGE * LARGE_PAGE;
    if end > start {
        let range = ptr.with_addr(start).cast_mut().cast();
        // SAFETY: `start..end` lies inside the caller's allocation.
        // `MADV_HUGEPAGE` changes no contents and no protection, only how
        // the kernel backs the range; its result is ignored because it is
        // a hint (it fails where THP is compiled out or disabled).
        let _ = unsafe { libc::madvise(range, end - start, libc::MADV_HUGEPAGE) };
        // Memory an allocator hands out may have been written before
        // (freed and reused, as glibc's heap is below its mmap threshold)
        // and so be backed by 4 KiB pages already, which the advice leaves
        // in place. Dropped, the first write faults in 2 MiB pages. Found in
        // `rt-report traversal`: the icosphere's 12 MB of nodes, allocated
        // after the terrain's arrays were freed, sat on 4 KiB pages, and its
        // incoherent rays ran at 0.87–0.89× Embree where a fresh process
        // ran them at 0.96×.
        // SAFETY: as above; the range is unwritten (every caller advises
        // before its first write), so reading it back as zeros, what
        // `MADV_DONTNEED` makes of private anonymous memory, loses nothing.
        let _ = unsafe { libc::madvise(range, end - start, libc::MADV_DONTNEED) };
    }
}

/// Without `std` on Linux there is nobody to ask: plain memory.
#[cfg(not(all(feature = "std", target_os = "linux")))]
fn advise(_ptr: *const u8, _len: usize) {}

#[cfg(all(test, feature = "std", target_os = "linux"))]
mod tests {
    use super::*;

    /// The flags of the mapping holding `addr`, from `/proc/self/smaps`.
    fn vm_flags(addr: usize) -> Option<alloc::string::String> {
        let smaps = std::fs::read_to_string("/proc/self/smaps").ok()?;
        let mut inside = false;
        for line in smaps.lines() {
            if let Some((range, _)) = line.split_once(' ')
                && let Some((lo, hi)) = range.split_once('-')
                && let (Ok(lo), Ok(hi)) =
                    (usize::from_str_radix(lo, 16), usize::from_str_radix(hi, 16))
            {
                inside = (lo..hi).contains(&addr);
            } else if inside && let Some(flags) = line.strip_prefix("VmFlags:") {
                return Some(flags.into());
            }
        }
        None
    }

    #[test]
    fn large_arrays_are_advised() {
        // 6 MiB: holds at least two whole aligned 2 MiB pages.
        let src = alloc::vec![7u32; 6 << 18];
        let big = large_copy(&src);
        assert_eq!(big, src);
        let inside = big.as_ptr().addr().next_multiple_of(LARGE_PAGE);
        let flags = vm_flags(inside).expect("the array's mapping is listed");
        assert!(flags.split_whitespace().any(|f| f == "hg"), "not advised: {flags}");
        // Copies of small arrays are plain copies.
        assert_eq!(large_copy(&[1u64, 2, 3]), [1, 2, 3]);
        assert!(large_copy::<u8>(&[]).is_empty());
        let zeros = large_zeroed::<u32>(6 << 18);
        assert!(zeros.len() == 6 << 18 && zeros.iter().all(|&x| x == 0));
        let inside = zeros.as_ptr().addr().next_multiple_of(LARGE_PAGE);
        assert!(vm_flags(inside).is_some_and(|f| f.split_whitespace().any(|f| f == "hg")));
    }
}
