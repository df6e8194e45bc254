//! A body's velocity Verlet step inside its block pass ([`crate::step::fused`]): paper 000
//! Eqs. 1–11 with the integration of §2.4, in three parallel passes over the body's particles:
//!
//! 1. the particles interior to no block (shared by blocks, or used by no tetrahedron): the
//!    drift x += ∆t (v + ½∆t a), v += ½∆t a;
//! 2. each block: its nodes' positions (and velocities) copied in once; its interior nodes
//!    (those of no other block) drifted in the copy and their positions written back; the
//!    tetrahedra's forces summed per node in the copy's cache, as the separate pass does; each
//!    interior node's force f = 0 + its sum (+ m g of a deferred field), a = f/m and the
//!    second half kick v += ½∆t a, written once; the shared nodes' sums to the block sums;
//! 3. the particles of pass 1: the force as the sum of their block sums in ascending block
//!    order (Eq. 11), then a and the kick as in pass 2.
//!
//! Each particle's arithmetic is the stepper's sweeps' (the same functions of
//! [`crate::step::fused`], in the same order) and each block's tetrahedra are the separate
//! pass's, so a fused step is bit-identical to the separate passes for any thread count. What
//! it saves is traffic: an interior particle's x, v, a and force cross memory once a step
//! instead of in a drift sweep, the block's copy, the block sums, the per-particle sums and a
//! kick sweep (the model: `qdem_bench::throughput::BenchResult::bytes_per_tet_step`).

use super::{for_blocks, Scratch, TetBody, PARTICLE_CHUNK};
use crate::step::fused::{accelerate, add_field, drift_component, FusedKick, FusedStep, Motion};
use crate::step::state::Dofs;
use crate::Vec3;
use rayon::prelude::*;
use std::ops::Range;

/// The state's arrays during a fused step, reached through pointers because the blocks write
/// them in parallel: each particle is written by one task only (a block writes its interior
/// particles, which no other block reads; passes 1 and 3 write the others, one task each), and
/// pass 2 reads the other particles' x and v, which nothing writes during it.
#[derive(Clone, Copy)]
struct Arrays {
    x: *mut Vec3,
    v: *mut Vec3,
    a: *mut Vec3,
    f: *mut Vec3,
    m: *const f64,
    fixed: *const Dofs,
}

// SAFETY: the pointers are used only as the type describes: each element written by one task,
// and no element read while another task writes it.
unsafe impl Send for Arrays {}
// SAFETY: as above.
unsafe impl Sync for Arrays {}

impl Arrays {
    /// The arrays of `motion`, checked to hold every particle of `particles`.
    fn of(motion: &mut Motion<'_>, particles: &Range<usize>) -> Arrays {
        let len = motion.position.len();
        let lengths = [
            motion.velocity.len(),
            motion.acceleration.len(),
            motion.force.len(),
            motion.mass.len(),
            motion.fixed.len(),
        ];
        assert!(
            particles.end <= len && lengths.iter().all(|&l| l == len),
            "a fused step over particles {particles:?} of {len}, {lengths:?}"
        );
        Arrays {
            x: motion.position.as_mut_ptr(),
            v: motion.velocity.as_mut_ptr(),
            a: motion.acceleration.as_mut_ptr(),
            f: motion.force.as_mut_ptr(),
            m: motion.mass.as_ptr(),
            fixed: motion.fixed.as_ptr(),
        }
    }

    /// The drift of particle `n`.
    ///
    /// # Safety
    /// `n` is in bounds and no other task reads or writes particle `n` meanwhile.
    #[inline(always)]
    unsafe fn drift(self, n: usize, dt: f64) {
        let (x, v, a) = (&mut *self.x.add(n), &mut *self.v.add(n), &*self.a.add(n));
        for c in 0..3 {
            drift_component(&mut x[c], &mut v[c], a[c], dt, 0.5 * dt);
        }
    }

    /// Particle `n`'s force sum f = 0 + `sum` with the field, its acceleration and its velocity
    /// `v` after the kick, written; whether the acceleration is finite.
    ///
    /// # Safety
    /// `n` is in bounds and no other task reads or writes particle `n` meanwhile.
    #[inline(always)]
    unsafe fn finish(self, n: usize, sum: Vec3, v: Vec3, kick: FusedKick) -> bool {
        let mut force = Vec3::zeros();
        force += sum;
        let mut f: [f64; 3] = force.into();
        let m = *self.m.add(n);
        if let Some(g) = kick.field {
            add_field(&mut f, m, &g);
        }
        let (mut a, mut v): ([f64; 3], [f64; 3]) = ([0.0; 3], v.into());
        let finite = accelerate(
            &f,
            &mut a,
            &mut v,
            m,
            *self.fixed.add(n),
            Some(0.5 * kick.dt),
        );
        *self.f.add(n) = f.into();
        *self.a.add(n) = a.into();
        *self.v.add(n) = v.into();
        finite
    }
}

impl FusedStep for TetBody {
    /// From the first particle a tetrahedron uses to the last.
    fn particles(&self) -> Range<usize> {
        let b = &self.blocks;
        b.first..b.first + b.entry_start.len() - 1
    }

    fn step_fused(&mut self, mut motion: Motion<'_>, kick: FusedKick) -> usize {
        let arrays = Arrays::of(&mut motion, &self.particles());
        match self.material.is_elastic() {
            true => self.fused_pass::<false>(arrays, kick),
            false => self.fused_pass::<true>(arrays, kick),
        }
    }
}

impl TetBody {
    /// The three passes of the module; the first particle with a non-finite acceleration.
    fn fused_pass<const VISCOUS: bool>(&mut self, arrays: Arrays, kick: FusedKick) -> usize {
        self.drift_outside(arrays, kick.dt);
        self.scratch.fit(rayon::current_num_threads());
        let mut sums = std::mem::take(&mut self.sums);
        let this = &*self;
        let [inverted, bad] = for_blocks(
            &mut sums,
            0..self.blocks.len(),
            &self.blocks.node_start,
            &|b, out| {
                let mut scratch = this.scratch.for_this_thread();
                this.fused_block::<VISCOUS>(b, arrays, out, &mut scratch, kick)
            },
        );
        self.sums = sums;
        self.inverted = (inverted != usize::MAX).then_some(inverted);
        bad.min(self.finish_outside(arrays, kick))
    }

    /// Pass 1: the drift of the particles interior to no block.
    fn drift_outside(&self, arrays: Arrays, dt: f64) {
        let outside = &self.blocks.owners.outside;
        outside
            .par_iter()
            .with_min_len(PARTICLE_CHUNK)
            // SAFETY: `Arrays::of` checked the bounds; each particle is listed once.
            .for_each(|&n| unsafe { arrays.drift(n as usize, dt) });
    }

    /// Pass 2 for block `b` (its shared nodes' sums into `out`); returns the body's index of
    /// its first inverted tetrahedron and its first interior particle with a non-finite
    /// acceleration (`usize::MAX` where none).
    fn fused_block<const VISCOUS: bool>(
        &self,
        b: usize,
        arrays: Arrays,
        out: &mut [Vec3],
        scratch: &mut Scratch,
        kick: FusedKick,
    ) -> [usize; 2] {
        let blocks = &self.blocks;
        let nodes = &blocks.nodes[blocks.node_start[b] as usize..blocks.node_start[b + 1] as usize];
        let interior = blocks.owners.interior(b);
        // SAFETY (all reads and writes below): the nodes are in bounds (`Arrays::of`); a
        // block's interior particles are its own, and the others are not written in this pass.
        let Scratch { x, v, f } = scratch;
        x.clear();
        x.extend(nodes.iter().map(|&n| unsafe { *arrays.x.add(n as usize) }));
        if VISCOUS {
            v.clear();
            v.extend(nodes.iter().map(|&n| unsafe { *arrays.v.add(n as usize) }));
        } else if v.len() < nodes.len() {
            // The elastic path reads only the interior nodes' entries, written below.
            v.resize(nodes.len(), Vec3::zeros());
        }
        for &l in interior {
            let (l, n) = (l as usize, nodes[l as usize] as usize);
            if !VISCOUS {
                v[l] = unsafe { *arrays.v.add(n) };
            }
            let a = unsafe { *arrays.a.add(n) };
            for c in 0..3 {
                drift_component(&mut x[l][c], &mut v[l][c], a[c], kick.dt, 0.5 * kick.dt);
            }
            unsafe { *arrays.x.add(n) = x[l] };
        }
        f.resize(nodes.len(), Vec3::zeros());
        let inverted = self.forces_of_block::<VISCOUS>(b, x, &v[..nodes.len()], f);
        for &l in blocks.owners.shared(b) {
            out[l as usize] = f[l as usize];
        }
        let mut bad = usize::MAX;
        for &l in interior {
            let (l, n) = (l as usize, nodes[l as usize] as usize);
            let mut sum = Vec3::zeros();
            sum += f[l];
            if !unsafe { arrays.finish(n, sum, v[l], kick) } {
                bad = bad.min(n);
            }
        }
        [inverted, bad]
    }

    /// Pass 3: the particles interior to no block, their force the sum of their block sums in
    /// ascending block order; the first with a non-finite acceleration.
    fn finish_outside(&self, arrays: Arrays, kick: FusedKick) -> usize {
        let blocks = &self.blocks;
        let (starts, entries, sums) = (&blocks.entry_start, &blocks.entries, &self.sums);
        blocks
            .owners
            .outside
            .par_iter()
            .with_min_len(PARTICLE_CHUNK)
            .map(|&n| {
                let (n, i) = (n as usize, n as usize - blocks.first);
                let mut sum = Vec3::zeros();
                for &entry in &entries[starts[i] as usize..starts[i + 1] as usize] {
                    sum += sums[entry as usize];
                }
                // SAFETY: in bounds (`Arrays::of`); each particle is listed once.
                let finite = unsafe { arrays.finish(n, sum, *arrays.v.add(n), kick) };
                if finite {
                    usize::MAX
                } else {
                    n
                }
            })
            .min()
            .unwrap_or(usize::MAX)
    }
}
