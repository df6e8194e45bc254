//! The per-particle work of a velocity Verlet step (paper 000 §2.4) as two sweeps over the
//! particles, translations and rotations together, each one parallel region:
//!
//! - [`drift`]: the first half kick and the drift, v_{n+½} = v_n + ½∆t a_n and
//!   x_{n+1} = x_n + ∆t v_{n+½} (computed as x += ∆t (v + ½∆t a), v += ½∆t a: Newmark's
//!   predictor with β = 0, γ = ½, bit for bit), ω and θ likewise, and the zeroing of the
//!   force and moment sums the models then add into;
//! - [`kick`]: after the forces, a uniform field's force m g deferred from the models
//!   ([`crate::step::Model::uniform_acceleration`]), local damping
//!   ([`crate::solvers::local_damping`]), a = f/m (zero in fixed directions and on members of
//!   rigid bodies, which follow their body), the second half kick v += ½∆t a and the check
//!   that every acceleration is finite; θ̈ = M/J and ω likewise.
//!
//! Each particle's arithmetic is that of the separate passes it replaces, in the same order,
//! so a step is bit-identical to theirs; and it involves no other particle, so the result does
//! not depend on how the particles are cut among the threads. A sweep splits into at most one
//! task per thread, each of at least [`SWEEP_TASK`] particles: at 10⁴ particles two threads
//! each take half. With a [`Team`] installed ([`crate::step::team`]) a sweep is one phase of
//! the team, in tasks of at least [`TEAM_TASK`] particles, in place of a rayon region.

use crate::solvers::local_damping::damp;
use crate::step::local_particles::ParticleRuns;
use crate::step::rigid_body::RigidBodies;
use crate::step::state::Dofs;
use crate::step::team::{self, Team};
use crate::Vec3;
use rayon::prelude::*;
use std::ops::Range;

/// The fewest particles a sweep hands to a thread of its own: below twice this a sweep runs
/// on the calling thread alone. A sweep costs 2–5 ns a particle and waking a worker about
/// 10–20 µs on the 2-core benchmark machine (qdem-bench's `fork_join` measures both), so a
/// task of 4,096 particles is about what its wake-up costs.
pub(crate) const SWEEP_TASK: usize = 4096;

/// The fewest particles a sweep hands to a thread of a [`Team`]: a phase posted to a worker
/// that is spinning costs about a microsecond (two cache lines crossing the cores), a few
/// hundred particles' work.
pub(crate) const TEAM_TASK: usize = 1024;

/// One set of generalised degrees of freedom of some particles (their translations, or their
/// rotations): positions, rates, accelerations, the force sums and the inertia.
pub(crate) struct DofArrays<'a> {
    /// x (or θ).
    pub x: &'a mut [Vec3],
    /// v (or ω).
    pub v: &'a mut [Vec3],
    /// a (or θ̈).
    pub a: &'a mut [Vec3],
    /// The force (or moment) sums.
    pub load: &'a mut [Vec3],
    /// m (or J).
    pub inertia: &'a [f64],
    /// The fixed directions (or axes).
    pub fixed: &'a [Dofs],
}

impl<'a> DofArrays<'a> {
    /// The particles before `mid`, and those from `mid` on.
    fn split_at(self, mid: usize) -> (DofArrays<'a>, DofArrays<'a>) {
        let (x0, x1) = self.x.split_at_mut(mid);
        let (v0, v1) = self.v.split_at_mut(mid);
        let (a0, a1) = self.a.split_at_mut(mid);
        let (f0, f1) = self.load.split_at_mut(mid);
        let (m0, m1) = self.inertia.split_at(mid);
        let (d0, d1) = self.fixed.split_at(mid);
        let part = |x, v, a, load, inertia, fixed| DofArrays {
            x,
            v,
            a,
            load,
            inertia,
            fixed,
        };
        (part(x0, v0, a0, f0, m0, d0), part(x1, v1, a1, f1, m1, d1))
    }
}

/// The translations of some particles, with their rotations when the particles rotate.
pub(crate) struct Particles<'a> {
    /// The translations.
    pub translation: DofArrays<'a>,
    /// The rotations (`None` when no particle rotates).
    pub rotation: Option<DofArrays<'a>>,
}

impl<'a> Particles<'a> {
    fn split_at(self, mid: usize) -> (Particles<'a>, Particles<'a>) {
        let (t0, t1) = self.translation.split_at(mid);
        let (r0, r1) = match self.rotation {
            Some(r) => {
                let (r0, r1) = r.split_at(mid);
                (Some(r0), Some(r1))
            }
            None => (None, None),
        };
        (
            Particles {
                translation: t0,
                rotation: r0,
            },
            Particles {
                translation: t1,
                rotation: r1,
            },
        )
    }

    /// The pieces of `ranges` (ascending, disjoint), in order.
    fn cut(mut self, ranges: &[Range<usize>]) -> Vec<(usize, Particles<'a>)> {
        let mut at = 0;
        let mut pieces = Vec::with_capacity(ranges.len());
        for r in ranges {
            let (_, rest) = self.split_at(r.start - at);
            let (piece, rest) = rest.split_at(r.len());
            pieces.push((r.start, piece));
            self = rest;
            at = r.end;
        }
        pieces
    }
}

/// The particles a sweep covers: every one, or a decomposed run's share
/// ([`crate::step::seam::Seam::stepped`], [`crate::step::seam::Seam::computed`]).
pub(crate) fn cover(count: usize, only: Option<&ParticleRuns>) -> Vec<Range<usize>> {
    match only {
        None => std::iter::once(0..count).collect(),
        Some(runs) => runs.pieces().to_vec(),
    }
}

/// `ranges` (ascending) cut into tasks of about equal size, at most one per thread of
/// `threads` and none shorter than `least` unless there is only one: a function of the
/// particles and the thread count alone.
fn tasks(ranges: &[Range<usize>], threads: usize, least: usize) -> Vec<Vec<Range<usize>>> {
    let total: usize = ranges.iter().map(Range::len).sum();
    let count = (total / least).clamp(1, threads.max(1));
    let size = total.div_ceil(count).max(1);
    let mut out = vec![Vec::new()];
    let mut room = size;
    for r in ranges {
        let mut r = r.clone();
        while !r.is_empty() {
            if room == 0 {
                out.push(Vec::new());
                room = size;
            }
            let take = room.min(r.len());
            out.last_mut()
                .expect("a task")
                .push(r.start..r.start + take);
            r.start += take;
            room -= take;
        }
    }
    out
}

/// Runs `work` on every piece of `particles` within `ranges` (each piece with the index of its
/// first particle), in tasks on the threads ([`tasks`]): a phase of the current [`Team`], or
/// a rayon region without one; returns the element-wise minimum of the results
/// (`(usize::MAX, usize::MAX)` with nothing to do).
fn sweep<W>(particles: Particles<'_>, ranges: &[Range<usize>], work: W) -> (usize, usize)
where
    W: Fn(usize, Particles<'_>) -> (usize, usize) + Sync,
{
    team::with_current(|team| sweep_on(team, particles, ranges, work))
}

/// [`sweep`] on `team`, or on rayon's threads without one.
fn sweep_on<W>(
    team: Option<&Team>,
    particles: Particles<'_>,
    ranges: &[Range<usize>],
    work: W,
) -> (usize, usize)
where
    W: Fn(usize, Particles<'_>) -> (usize, usize) + Sync,
{
    let plan = match team {
        Some(team) => tasks(ranges, team.size(), TEAM_TASK),
        None => tasks(ranges, rayon::current_num_threads(), SWEEP_TASK),
    };
    let flat: Vec<Range<usize>> = plan.iter().flatten().cloned().collect();
    let mut pieces = particles.cut(&flat).into_iter();
    let run_task = |task: Vec<(usize, Particles<'_>)>| {
        task.into_iter()
            .map(|(start, p)| work(start, p))
            .fold((usize::MAX, usize::MAX), min2)
    };
    let mut grouped: Vec<Vec<(usize, Particles<'_>)>> = plan
        .iter()
        .map(|t| pieces.by_ref().take(t.len()).collect())
        .collect();
    if grouped.len() == 1 {
        return run_task(grouped.pop().expect("one task"));
    }
    if let Some(team) = team {
        let results = team.run(grouped, run_task);
        return results.into_iter().fold((usize::MAX, usize::MAX), min2);
    }
    team::note_rayon_region();
    grouped
        .into_par_iter()
        .map(run_task)
        .reduce(|| (usize::MAX, usize::MAX), min2)
}

fn min2(a: (usize, usize), b: (usize, usize)) -> (usize, usize) {
    (a.0.min(b.0), a.1.min(b.1))
}

/// The first half kick and the drift of `particles` within `ranges`, x += ∆t (v + ½∆t a),
/// v += ½∆t a; with `zero`, the force and moment sums of those particles set to zero.
pub(crate) fn drift(particles: Particles<'_>, ranges: &[Range<usize>], dt: f64, zero: bool) {
    let half = 0.5 * dt;
    sweep(particles, ranges, |_, p| {
        drift_dofs(p.translation, dt, half, zero);
        if let Some(r) = p.rotation {
            drift_dofs(r, dt, half, zero);
        }
        (usize::MAX, usize::MAX)
    });
}

#[inline]
fn drift_dofs(d: DofArrays<'_>, dt: f64, half: f64, zero: bool) {
    // Component by component, so that the loop runs in SIMD lanes.
    let (x, v, a) = (flat_mut(d.x), flat_mut(d.v), flat(d.a));
    for ((x, v), a) in x.iter_mut().zip(v.iter_mut()).zip(a) {
        *x += dt * (*v + half * a);
        *v += half * a;
    }
    if zero {
        d.load.fill(Vec3::zeros());
    }
}

// A `Vec3` is three contiguous `f64`s (nalgebra's `Matrix` is `repr(C)` over a
// `repr(transparent)` array), which the flat views below rely on.
const _: () = assert!(std::mem::size_of::<Vec3>() == 3 * std::mem::size_of::<f64>());
const _: () = assert!(std::mem::align_of::<Vec3>() == std::mem::align_of::<f64>());

/// The components of `v`, x, y, z of each vector in turn.
fn flat(v: &[Vec3]) -> &[f64] {
    // SAFETY: `Vec3` is laid out as `[f64; 3]` (asserted above); the view borrows `v`.
    unsafe { std::slice::from_raw_parts(v.as_ptr().cast::<f64>(), 3 * v.len()) }
}

/// The components of `v`, a triple for each vector.
fn triples_mut(v: &mut [Vec3]) -> &mut [[f64; 3]] {
    // SAFETY: as in `flat`; the view borrows `v` mutably, so it is the only one.
    unsafe { std::slice::from_raw_parts_mut(v.as_mut_ptr().cast::<[f64; 3]>(), v.len()) }
}

/// [`flat`], mutable.
fn flat_mut(v: &mut [Vec3]) -> &mut [f64] {
    // SAFETY: as in `flat`; the view borrows `v` mutably, so it is the only one.
    unsafe { std::slice::from_raw_parts_mut(v.as_mut_ptr().cast::<f64>(), 3 * v.len()) }
}

/// What [`kick`] does besides a = f/m.
#[derive(Clone, Copy, Debug)]
pub(crate) struct KickSettings {
    /// The kick h of v += h a (`None`: the accelerations only).
    pub h: Option<f64>,
    /// A uniform field g whose force m g the models left to the sweep.
    pub field: Option<Vec3>,
    /// The local damping fraction (0: none).
    pub damping: f64,
}

/// The accelerations of `particles` within `ranges` from their force and moment sums
/// (completed by `settings`' field and damping, which they keep), with the kick; members of
/// `rigid`'s bodies get none. Returns the first particle with a non-finite acceleration and
/// the first with a non-finite angular acceleration (`usize::MAX` where none).
pub(crate) fn kick(
    particles: Particles<'_>,
    ranges: &[Range<usize>],
    rigid: &RigidBodies,
    settings: KickSettings,
) -> (usize, usize) {
    sweep(particles, ranges, |start, p| {
        let members = !rigid.is_empty();
        let bad = kick_dofs(p.translation, start, settings, |i| {
            members && rigid.body_of_member(i).is_some()
        });
        let spin = KickSettings {
            field: None,
            ..settings
        };
        let bad_spin = p
            .rotation
            .map_or(usize::MAX, |r| kick_dofs(r, start, spin, |_| false));
        (bad, bad_spin)
    })
}

/// [`kick`] of one piece of one set of DOFs, whose first particle is `start`.
#[inline]
fn kick_dofs(
    d: DofArrays<'_>,
    start: usize,
    settings: KickSettings,
    follows: impl Fn(usize) -> bool,
) -> usize {
    let completes = settings.field.is_some() || settings.damping > 0.0;
    let mut bad = usize::MAX;
    let (load, a, v) = (triples_mut(d.load), triples_mut(d.a), triples_mut(d.v));
    let particles = load
        .iter_mut()
        .zip(a.iter_mut())
        .zip(v.iter_mut())
        .zip(d.inertia.iter().zip(d.fixed));
    for (k, (((load, a), v), (&m, &fixed))) in particles.enumerate() {
        let mut f = [load[0], load[1], load[2]];
        if completes {
            if let Some(g) = settings.field {
                for c in 0..3 {
                    f[c] += m * g[c];
                }
            }
            if settings.damping > 0.0 {
                damp_components(&mut f, v, settings.damping);
            }
            *load = f;
        }
        if follows(start + k) {
            *a = [0.0; 3];
            continue;
        }
        let mut acc = [f[0] / m, f[1] / m, f[2] / m];
        if fixed != Dofs::NONE {
            for (c, acc) in acc.iter_mut().enumerate() {
                if fixed.contains(c) {
                    *acc = 0.0;
                }
            }
        }
        *a = acc;
        if let Some(h) = settings.h {
            for c in 0..3 {
                v[c] += h * acc[c];
            }
        }
        if bad == usize::MAX && !acc.iter().all(|c| c.is_finite()) {
            bad = start + k;
        }
    }
    bad
}

/// [`damp`] of a force given by its components.
#[inline]
fn damp_components(f: &mut [f64; 3], v: &[f64; 3], alpha: f64) {
    let mut load = Vec3::from(*f);
    damp(&mut load, &Vec3::from(*v), alpha);
    *f = load.into();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tasks_cover_the_ranges_in_order_and_are_never_shorter_than_a_task() {
        let ranges = vec![0..3000, 3500..9000, 9100..20000];
        for (threads, least) in [(1, SWEEP_TASK), (2, SWEEP_TASK), (3, TEAM_TASK)] {
            let plan = tasks(&ranges, threads, least);
            let flat: Vec<usize> = plan.iter().flatten().flat_map(Range::clone).collect();
            let want: Vec<usize> = ranges.iter().flat_map(Range::clone).collect();
            assert_eq!(flat, want);
            assert_eq!(plan.len(), threads);
            assert!(plan
                .iter()
                .all(|t| t.iter().map(Range::len).sum::<usize>() >= least));
            assert_eq!(
                tasks(std::slice::from_ref(&(0..10)), threads, least).len(),
                1
            );
        }
    }
}
