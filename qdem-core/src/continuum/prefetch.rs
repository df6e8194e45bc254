//! Software prefetch for the block pass: a hint that asks the cache for lines the pass will
//! read soon (the packs a few ahead of the one computed, the positions of the nodes a block
//! copies in a little further on), so that their misses overlap the arithmetic.
//!
//! A prefetch moves no value: the sums are the same bits with it and without. It is on
//! unless the environment sets `QDEM_PREFETCH=0` (read once per process, as
//! `QDEM_KERNEL_LANES` is; other values leave it on), so that one binary can be timed both
//! ways (docs/BENCHMARKS.md: on the quiet 2-core Intel Xeon it gained 10-15% at 10^6
//! tetrahedra and at 5,700 stones, median of the alternated pairs). On x86-64 the hint is `prefetcht0`
//! (`_mm_prefetch` with `_MM_HINT_T0`); elsewhere it does nothing.

use std::sync::OnceLock;

/// Packs ahead of the one computed whose lines the lane pass prefetches: 4 packs of 640 B,
/// 32 tetrahedra or about half a microsecond of one core's work ahead, far enough to cover a
/// miss to memory and near enough to stay in L1 until it is read.
pub(crate) const PACKS_AHEAD: usize = 4;

/// Nodes ahead of the one copied whose position (and velocity) the block's copy prefetches.
pub(crate) const NODES_AHEAD: usize = 16;

/// Whether the block pass prefetches: unless `QDEM_PREFETCH=0` in the environment, read once.
///
/// ```
/// // On unless the environment turns it off.
/// let on = std::env::var("QDEM_PREFETCH").as_deref() != Ok("0");
/// assert_eq!(qdem_core::continuum::prefetch::enabled(), on);
/// ```
pub fn enabled() -> bool {
    static ON: OnceLock<bool> = OnceLock::new();
    *ON.get_or_init(|| std::env::var("QDEM_PREFETCH").as_deref() != Ok("0"))
}

/// Asks for the cache lines of `value` (all of them, for a value longer than one line).
#[inline(always)]
pub(crate) fn lines<T>(value: &T) {
    let start = (value as *const T).cast::<u8>();
    for offset in (0..std::mem::size_of::<T>()).step_by(64) {
        // The address stays inside `value`.
        line(start.wrapping_add(offset));
    }
}

/// Asks for the cache line holding `at` (never dereferenced).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn line(at: *const u8) {
    use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
    // SAFETY: a prefetch is a hint that never faults, whatever the address; SSE is part of
    // x86-64.
    unsafe { _mm_prefetch::<_MM_HINT_T0>(at.cast::<i8>()) }
}

/// No hint on other architectures.
#[cfg(not(target_arch = "x86_64"))]
#[inline(always)]
fn line(_at: *const u8) {}
