//! Transparent huge pages for the large arrays of a run: the `qdem` binary's allocator.
//!
//! At 10⁶ tetrahedra the kernel's arrays (the tetrahedron packs, 80 MB; positions, velocities,
//! forces and block sums, 4–6 MB each) span tens of thousands of 4 KiB pages, and the blocks
//! gather their nodes' positions from all over them, so a step misses the TLB often (more
//! dearly in a virtual machine, where a miss walks two page tables). Where the kernel's
//! transparent huge pages are enabled only on request (`/sys/kernel/mm/transparent_hugepage/
//! enabled` = `madvise`, a common default), [`HugePages`] requests them
//! (`madvise(MADV_HUGEPAGE)`) for every allocation of at least [`HUGE_PAGE`] bytes, over the
//! whole 2 MiB pages inside it, before anything is written there: one 2 MiB page then maps
//! what 512 small ones did. Smaller allocations, and every byte's value, are the system
//! allocator's: results do not change.
//!
//! `QDEM_HUGE_PAGES=0` in the environment turns the request off (to compare both in one
//! binary); where the kernel has no transparent huge pages the request fails harmlessly.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicU8, Ordering};

/// The size of a huge page on x86-64 and of the smallest allocation advised to use them.
pub const HUGE_PAGE: usize = 2 << 20;

/// The system allocator, asking for transparent huge pages over large allocations.
///
/// ```
/// use qdem_cli::huge_pages::{HugePages, HUGE_PAGE};
/// use std::alloc::{GlobalAlloc, Layout};
///
/// let layout = Layout::from_size_align(4 * HUGE_PAGE, 64).unwrap();
/// unsafe {
///     let p = HugePages.alloc_zeroed(layout);
///     assert!(!p.is_null() && *p.add(3 * HUGE_PAGE) == 0);
///     HugePages.dealloc(p, layout);
/// }
/// ```
#[derive(Clone, Copy, Debug, Default)]
pub struct HugePages;

// SAFETY: every call is forwarded to `System` with the same arguments; `advise` only gives
// the kernel a hint about pages inside the block just returned.
unsafe impl GlobalAlloc for HugePages {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's contract, passed on.
        let p = unsafe { System.alloc(layout) };
        advise(p, layout.size());
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's contract, passed on.
        let p = unsafe { System.alloc_zeroed(layout) };
        advise(p, layout.size());
        p
    }

    unsafe fn dealloc(&self, p: *mut u8, layout: Layout) {
        // SAFETY: the caller's contract, passed on.
        unsafe { System.dealloc(p, layout) }
    }

    unsafe fn realloc(&self, p: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: the caller's contract, passed on.
        let q = unsafe { System.realloc(p, layout, new_size) };
        advise(q, new_size);
        q
    }
}

/// Asks for huge pages over the whole 2 MiB pages of the `size` bytes at `p`, when the block
/// holds at least one and the request is on.
fn advise(p: *mut u8, size: usize) {
    if p.is_null() || size < HUGE_PAGE || !enabled() {
        return;
    }
    let start = (p as usize).next_multiple_of(HUGE_PAGE);
    let end = (p as usize + size) / HUGE_PAGE * HUGE_PAGE;
    if end > start {
        // SAFETY: [start, end) lies inside the block just allocated; the advice changes no
        // byte of it and its failure (no huge pages in this kernel) leaves it as it was.
        unsafe {
            libc::madvise(start as *mut libc::c_void, end - start, libc::MADV_HUGEPAGE);
        }
    }
}

/// Whether the request is on: unless `QDEM_HUGE_PAGES` is `0`, read once (with `getenv`,
/// which does not allocate, as an allocator must not).
fn enabled() -> bool {
    /// 0: not read yet, 1: on, 2: off.
    static STATE: AtomicU8 = AtomicU8::new(0);
    match STATE.load(Ordering::Relaxed) {
        1 => true,
        2 => false,
        _ => {
            // SAFETY: a NUL-terminated name; the result is read before any other call.
            let off = unsafe {
                let value = libc::getenv(c"QDEM_HUGE_PAGES".as_ptr());
                !value.is_null() && *value == b'0' as libc::c_char && *value.add(1) == 0
            };
            STATE.store(if off { 2 } else { 1 }, Ordering::Relaxed);
            !off
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The huge pages backing the mapping that holds `address`, from /proc/self/smaps, in
    /// bytes; `None` where the file or the field is missing.
    fn huge_bytes_at(address: usize) -> Option<usize> {
        let smaps = std::fs::read_to_string("/proc/self/smaps").ok()?;
        let mut inside = false;
        for line in smaps.lines() {
            let first = line.split_whitespace().next().unwrap_or("");
            if let Some((lo, hi)) = first.split_once('-') {
                if let (Ok(lo), Ok(hi)) =
                    (usize::from_str_radix(lo, 16), usize::from_str_radix(hi, 16))
                {
                    inside = (lo..hi).contains(&address);
                    continue;
                }
            }
            if inside && line.starts_with("AnonHugePages:") {
                let kb: usize = line.split_whitespace().nth(1)?.parse().ok()?;
                return Some(kb * 1024);
            }
        }
        None
    }

    /// Where the kernel grants huge pages on request, an array of 32 MiB written through
    /// [`HugePages`] lies mostly on them (all but the partial 2 MiB pages at its ends, and
    /// whatever the kernel could not find free at once); through the system allocator alone
    /// on none. Where the kernel offers none on request the test has nothing to check.
    #[test]
    fn a_large_array_lies_on_huge_pages() {
        let mode = std::fs::read_to_string("/sys/kernel/mm/transparent_hugepage/enabled");
        if !mode.is_ok_and(|m| m.contains("[madvise]")) {
            eprintln!("transparent huge pages are not on request here: nothing to check");
            return;
        }
        let size = 16 * HUGE_PAGE;
        let layout = Layout::from_size_align(size, 64).unwrap();
        let touched = |allocator: &dyn Fn(Layout) -> *mut u8| {
            let p = allocator(layout);
            assert!(!p.is_null());
            // SAFETY: `p` holds `size` bytes.
            unsafe { std::ptr::write_bytes(p, 1, size) };
            let huge = huge_bytes_at(p as usize + size / 2).expect("smaps");
            // SAFETY: allocated above with `layout` by the system allocator underneath.
            unsafe { System.dealloc(p, layout) };
            huge
        };
        // SAFETY: a non-zero size.
        let plain = touched(&|l| unsafe { System.alloc(l) });
        let advised = touched(&|l| unsafe { HugePages.alloc(l) });
        assert_eq!(plain, 0, "no huge pages unasked");
        assert!(
            advised >= size / 2,
            "{advised} of {size} bytes on huge pages"
        );
    }
}
