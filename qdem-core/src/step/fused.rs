//! A velocity Verlet step (paper 000 §2.4) that a model takes inside its own force pass for
//! the particles only it acts on:
//!
//! x_{n+1} = x_n + ∆t (v_n + ½∆t a_n), v_{n+½} = v_n + ½∆t a_n (the drift), the force sum
//! f_{n+1} = 0 + the model's force (+ m g of a uniform field the models deferred),
//! a_{n+1} = f_{n+1}/m (zero in fixed directions) and v_{n+1} = v_{n+½} + ½∆t a_{n+1}.
//!
//! The stepper's own sweeps (`qdem-core/src/solvers/verlet_sweeps.rs`) do the same per-particle
//! arithmetic through the functions here ([`drift_component`], [`add_field`],
//! [`accelerate`]), so a particle integrated in a model's pass gets the same bits as in the
//! sweeps. A model offers the step through [`crate::step::Model::fused`]; the stepper takes it
//! only where the model is the only one that adds forces, in a run of one process without
//! rigid bodies, particle rotations or local damping, and integrates every other particle in its
//! sweeps. What this saves is memory traffic: a deformable body's block pass already holds a
//! block's positions (and velocities) in cache, so the particles interior to one block are
//! read and written once a step instead of once per sweep (docs/BENCHMARKS.md, bytes per
//! tet-step).

use crate::step::state::Dofs;
use crate::Vec3;
use std::ops::Range;

/// One component of the drift with the first half kick: x += ∆t (v + ½∆t a), v += ½∆t a
/// (`half` = ½∆t).
///
/// ```
/// use qdem_core::step::fused::drift_component;
///
/// let (mut x, mut v) = (1.0, 2.0);
/// drift_component(&mut x, &mut v, 4.0, 0.5, 0.25);
/// assert_eq!((x, v), (1.0 + 0.5 * (2.0 + 0.25 * 4.0), 3.0));
/// ```
#[inline(always)]
pub fn drift_component(x: &mut f64, v: &mut f64, a: f64, dt: f64, half: f64) {
    *x += dt * (*v + half * a);
    *v += half * a;
}

/// Adds a uniform field's force m g to a particle's force sum `f`.
///
/// ```
/// use qdem_core::{step::fused::add_field, Vec3};
///
/// let mut f = [1.0, 0.0, 0.0];
/// add_field(&mut f, 2.0, &Vec3::new(0.0, 0.0, -9.81));
/// assert_eq!(f, [1.0, 0.0, -19.62]);
/// ```
#[inline(always)]
pub fn add_field(f: &mut [f64; 3], m: f64, g: &Vec3) {
    for c in 0..3 {
        f[c] += m * g[c];
    }
}

/// a = f/m, zero in the `fixed` directions, written into `a`; with `kick` = `Some(h)` the kick
/// v += h a. Returns whether every component of a is finite.
///
/// ```
/// use qdem_core::step::{fused::accelerate, Dofs};
///
/// let (mut a, mut v) = ([0.0; 3], [1.0; 3]);
/// let finite = accelerate(&[2.0, 4.0, 6.0], &mut a, &mut v, 2.0, Dofs::parse("z").unwrap(), Some(0.5));
/// assert!(finite);
/// assert_eq!((a, v), ([1.0, 2.0, 0.0], [1.5, 2.0, 1.0]));
/// ```
#[inline(always)]
pub fn accelerate(
    f: &[f64; 3],
    a: &mut [f64; 3],
    v: &mut [f64; 3],
    m: f64,
    fixed: Dofs,
    kick: Option<f64>,
) -> bool {
    let mut acc = [f[0] / m, f[1] / m, f[2] / m];
    if fixed != Dofs::NONE {
        for (c, acc) in acc.iter_mut().enumerate() {
            if fixed.contains(c) {
                *acc = 0.0;
            }
        }
    }
    *a = acc;
    if let Some(h) = kick {
        for c in 0..3 {
            v[c] += h * acc[c];
        }
    }
    acc.iter().all(|c| c.is_finite())
}

/// The particles' translational motion and force sums, whole, as a fused pass integrates them.
pub struct Motion<'a> {
    /// x.
    pub position: &'a mut [Vec3],
    /// v.
    pub velocity: &'a mut [Vec3],
    /// a.
    pub acceleration: &'a mut [Vec3],
    /// The force sums (what the model adds, plus the field's share).
    pub force: &'a mut [Vec3],
    /// m.
    pub mass: &'a [f64],
    /// The fixed directions.
    pub fixed: &'a [Dofs],
}

/// What a fused pass does besides the model's forces.
#[derive(Clone, Copy, Debug)]
pub struct FusedKick {
    /// The step ∆t (the drift by ∆t, the kicks by ½∆t).
    pub dt: f64,
    /// A uniform field g whose force m g the models left to the integration.
    pub field: Option<Vec3>,
}

/// A model that integrates its particles inside its force pass.
pub trait FusedStep {
    /// The particles the fused pass integrates (a contiguous run; the model must be the only
    /// source of their forces).
    fn particles(&self) -> Range<usize>;

    /// The drift of [`FusedStep::particles`], the model's forces on them at the drifted
    /// state, the field, the accelerations and the second half kick, as the module describes,
    /// into `motion`; the force sums of these particles are written whole (no zeroing needed).
    /// Returns the first of them whose acceleration is not finite (`usize::MAX` if none).
    fn step_fused(&mut self, motion: Motion<'_>, kick: FusedKick) -> usize;
}
