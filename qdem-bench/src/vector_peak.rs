//! The machine's vector floating-point peak, measured in the process: the peer against which
//! `qdem bench` sets the kernel's arithmetic, as the triad is the peer of its memory traffic.
//!
//! Sixteen independent chains of multiply-adds a ← a·b + c on registers of the width the
//! tetrahedron kernel runs with ([`LaneSet::detected`]: 8 lanes with AVX-512, 4 with AVX2, one
//! without either), each multiply-add counted as two operations, on every thread of a pool.
//! Sixteen chains cover the latency of two FMA ports (4 cycles each), so the loop issues one
//! multiply-add per port and cycle: the most the cores can do at the clock they run at.

use crate::throughput::on_threads;
use qdem_core::continuum::tet_lanes::LaneSet;
use std::time::Instant;

/// Multiply-adds per chain per timed run.
const ROUNDS: usize = 1 << 22;

/// Peak floating-point operations per second on `threads` threads (best of 5), with the
/// kernel's lane set.
pub fn vector_peak_flops(threads: usize) -> f64 {
    use rayon::prelude::*;
    let set = LaneSet::detected();
    let workers = if threads == 0 {
        rayon::current_num_threads()
    } else {
        threads
    };
    on_threads(threads, || {
        let mut best = f64::INFINITY;
        for _ in 0..5 {
            let start = Instant::now();
            let sum: f64 = (0..workers)
                .into_par_iter()
                .map(|w| chains(set, 1.0 + w as f64 * 1e-9))
                .sum();
            best = best.min(start.elapsed().as_secs_f64());
            assert!(sum.is_finite());
        }
        (workers * ROUNDS * 16 * 2 * set.width()) as f64 / best
    })
}

/// The sixteen chains on one thread; returns their sum (so that the work is kept).
fn chains(set: LaneSet, seed: f64) -> f64 {
    match set {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: `detected` chooses a set only when the CPU has its features.
        LaneSet::Avx512 => unsafe { x86::avx512(seed) },
        #[cfg(target_arch = "x86_64")]
        // SAFETY: as above.
        LaneSet::Avx2 => unsafe { x86::avx2(seed) },
        _ => scalar(seed),
    }
}

fn scalar(seed: f64) -> f64 {
    let mut a = [seed; 16];
    let (b, c) = (
        std::hint::black_box(0.999_999_9),
        std::hint::black_box(1e-7),
    );
    for _ in 0..ROUNDS {
        for a in a.iter_mut() {
            *a = *a * b + c;
        }
    }
    a.iter().sum()
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::ROUNDS;
    use std::arch::x86_64::*;

    #[target_feature(enable = "avx512f,fma")]
    pub(super) unsafe fn avx512(seed: f64) -> f64 {
        let mut a = [_mm512_set1_pd(seed); 16];
        let b = _mm512_set1_pd(std::hint::black_box(0.999_999_9));
        let c = _mm512_set1_pd(std::hint::black_box(1e-7));
        for _ in 0..ROUNDS {
            for a in a.iter_mut() {
                *a = _mm512_fmadd_pd(*a, b, c);
            }
        }
        a.iter().map(|&v| _mm512_reduce_add_pd(v)).sum()
    }

    #[target_feature(enable = "avx2,fma")]
    pub(super) unsafe fn avx2(seed: f64) -> f64 {
        let mut a = [_mm256_set1_pd(seed); 16];
        let b = _mm256_set1_pd(std::hint::black_box(0.999_999_9));
        let c = _mm256_set1_pd(std::hint::black_box(1e-7));
        for _ in 0..ROUNDS {
            for a in a.iter_mut() {
                *a = _mm256_fmadd_pd(*a, b, c);
            }
        }
        let mut lanes = [0.0; 4];
        let mut sum = 0.0;
        for v in a {
            _mm256_storeu_pd(lanes.as_mut_ptr(), v);
            sum += lanes.iter().sum::<f64>();
        }
        sum
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_lane_set_keeps_its_chains_finite_and_equal() {
        // The chains converge to the fixed point c / (1 − b) = 1 whatever the width.
        let set = LaneSet::detected();
        let got = chains(set, 1.0) / (16 * set.width()) as f64;
        assert!((got - 1.0).abs() < 1e-9, "{got}");
    }
}
