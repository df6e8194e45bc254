//! Newmark-β stepping, explicit and implicit (paper 001 §3, Eqs. 13–16, 19–20, 22–27).
//!
//! With x_n, v_n, a_n at t_n, Eqs. 13–14 (equivalently Eqs. 24–25) read
//!
//!   x_{n+1} = x̃ + β∆t² a_{n+1},   x̃ = x_n + ∆t v_n + (½ − β)∆t² a_n,
//!   v_{n+1} = ṽ + γ∆t a_{n+1},    ṽ = v_n + (1 − γ)∆t a_n,
//!
//! and the equation of motion Eq. 15 is M a_{n+1} = f(t_{n+1}, x_{n+1}, v_{n+1}), f the total
//! force of the models (external minus internal minus viscous), M the lumped mass. [`predict`]
//! forms the predictor (x̃, ṽ), [`correct`] adds the β and γ terms once a_{n+1} is known.
//!
//! - **β = 0** (explicit; γ = ½ is central difference): x_{n+1} = x̃ needs no solve and
//!   a_{n+1} = M⁻¹ f(t_{n+1}, x̃, ṽ), the viscous force seeing the predicted velocity ṽ. For
//!   γ = ½, ṽ is the half-step velocity and the scheme is [`crate::Verlet`], operation for
//!   operation; it is stable for ∆t ≤ [`crate::stable_step()`].
//! - **β > 0** (implicit): the incremental internal-force form of Eqs. 19–20,
//!   f(x̃ + β∆t² a, ṽ + γ∆t a) ≈ f(x̃, ṽ) − (β∆t² K + γ∆t C) a, turns Eq. 15 into Eq. 26,
//!
//!   (M + γ∆t C + β∆t² K) a_{n+1} = f(t_{n+1}, x̃, ṽ),
//!
//!   whose right-hand side is Eq. 26's f_n − K a_n − C b_n (a_n = x̃ − x_n, b_n = ṽ of Eq. 22)
//!   with the internal force evaluated by the models themselves at the predicted state, so a
//!   force that is not K·u (the geometrically non-linear QDEM kernel, contacts) is handled. One
//!   linear solve is one Newton iteration from the predictor: exact for a linear force, and
//!   otherwise in error by the neglected non-linearity of the step's increment (of the order of
//!   the strain times the increment for the QDEM kernel), which small-strain runs can ignore.
//!   Equilibria (a = v = 0) are exactly those of the models' non-linear force, whatever the
//!   tangent. Average acceleration (β = ¼, γ = ½) is unconditionally stable and conserves
//!   energy for linear systems.
//!
//! Constraints (Eqs. 23, 27) are eliminated: fixed DOFs are left out of the system
//! ([`FreeDofs`]) and keep zero velocity and acceleration. The effective matrix is factorised by
//! [`SparseCholesky`]: with [`TangentUpdate::Fixed`] once, at [`Stepper::initialize`] (exact for
//! a linear small-strain run; each step then costs one force evaluation and two triangular
//! solves); with [`TangentUpdate::EveryStep`] K and C are reassembled at every predicted state
//! and refactorised, reusing the symbolic analysis. The fixity is read when factorising.

use crate::error::CoreError;
use crate::model::Model;
use crate::sparse::{
    assemble, explain_failure, Entry, FactorStats, FreeDofs, Scales, SparseCholesky, Tangent,
};
use crate::state::State;
use crate::stepper::{
    check_finite, check_masses, compute_accelerations, refuse_rigid, sum_forces, Stepper,
    PARTICLE_CHUNK,
};
use crate::Vec3;
use rayon::prelude::*;

/// When the implicit stepper refactorises its effective matrix.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TangentUpdate {
    /// Once, with K and C at the initial state: the tangent is fixed (linear small strain).
    #[default]
    Fixed,
    /// Every step, with K and C at the predicted state (large displacements or rotations).
    EveryStep,
}

/// The Newmark-β family with a fixed step: explicit for β = 0, implicit for β > 0.
#[derive(Debug)]
pub struct Newmark {
    beta: f64,
    gamma: f64,
    dt: f64,
    update: TangentUpdate,
    force: Vec<Vec3>,
    torque: Vec<Vec3>,
    system: ImplicitSystem,
}

/// Buffers of the implicit solve of Eq. 26.
#[derive(Debug, Default)]
struct ImplicitSystem {
    tangent: Tangent,
    entries: Vec<Entry>,
    dofs: Option<FreeDofs>,
    cholesky: SparseCholesky,
    rhs: Vec<f64>,
}

impl Newmark {
    /// A Newmark stepper with parameters β, γ and step `dt` (s); refused outside the range of
    /// paper 001 Eq. 16, 0 ≤ γ ≤ 1, 0 ≤ 2β ≤ 1.
    pub fn new(beta: f64, gamma: f64, dt: f64) -> Result<Newmark, CoreError> {
        if !((0.0..=1.0).contains(&gamma) && (0.0..=0.5).contains(&beta)) {
            return Err(CoreError::NewmarkParameters { beta, gamma });
        }
        Ok(Newmark {
            beta,
            gamma,
            dt,
            update: TangentUpdate::Fixed,
            force: Vec::new(),
            torque: Vec::new(),
            system: ImplicitSystem::default(),
        })
    }

    /// Explicit central difference, β = 0, γ = ½.
    pub fn central_difference(dt: f64) -> Newmark {
        Newmark::new(0.0, 0.5, dt).expect("valid parameters")
    }

    /// Implicit average (constant) acceleration, β = ¼, γ = ½.
    pub fn average_acceleration(dt: f64) -> Newmark {
        Newmark::new(0.25, 0.5, dt).expect("valid parameters")
    }

    /// The same stepper refactorising as `update` says (default [`TangentUpdate::Fixed`]).
    pub fn with_tangent_update(mut self, update: TangentUpdate) -> Newmark {
        self.update = update;
        self
    }

    /// Whether a step solves a linear system (β > 0).
    pub fn is_implicit(&self) -> bool {
        self.beta > 0.0
    }

    /// The force buffer of the last evaluation (N per particle).
    pub fn forces(&self) -> &[Vec3] {
        &self.force
    }

    /// Assembles M + γ∆t C + β∆t² K (Eq. 26) at `state` and factorises it. With positive
    /// masses (checked at [`Stepper::initialize`]) the matrix is positive definite even for a
    /// body free to move rigidly, so free bodies are not refused; a failed factorisation is
    /// explained by [`explain_failure`].
    fn refactor(&mut self, state: &State, models: &[Box<dyn Model>]) -> Result<(), CoreError> {
        let scales = Scales {
            mass: 1.0,
            damping: self.gamma * self.dt,
            stiffness: self.beta * self.dt * self.dt,
        };
        let system = &mut self.system;
        collect_tangent(state, models, &mut system.tangent)?;
        let dofs = FreeDofs::new(&state.fixed);
        let matrix = assemble(
            &system.tangent,
            &state.mass,
            &dofs,
            scales,
            &mut system.entries,
        )?;
        if let Err(error) = system.cholesky.factorize(matrix.as_ref(), "effective") {
            let pivot = system.cholesky.failed_pivot();
            return Err(explain_failure(
                error,
                pivot,
                &dofs,
                state,
                models,
                &system.tangent,
            ));
        }
        system.dofs = Some(dofs);
        Ok(())
    }

    /// Solves Eq. 26 for a_{n+1} with the right-hand side f(t_{n+1}, x̃, ṽ) at the predicted
    /// state, writing it into `state.acceleration` (zero in fixed directions).
    fn solve_accelerations(
        &mut self,
        state: &mut State,
        models: &mut [Box<dyn Model>],
    ) -> Result<(), CoreError> {
        sum_forces(state, models, &mut self.force, &mut self.torque);
        let system = &mut self.system;
        let dofs = system.dofs.as_ref().expect("factorised before stepping");
        system.rhs.resize(dofs.len(), 0.0);
        dofs.gather(&self.force, &mut system.rhs);
        system.cholesky.solve_in_place(&mut system.rhs);
        dofs.scatter(&system.rhs, &mut state.acceleration);
        check_finite(state)
    }
}

/// Collects the tangent of every model into `tangent`; fails on a model without one.
pub(crate) fn collect_tangent(
    state: &State,
    models: &[Box<dyn Model>],
    tangent: &mut Tangent,
) -> Result<(), CoreError> {
    tangent.clear();
    match models.iter().find(|m| !m.add_tangent(state, tangent)) {
        Some(model) => Err(CoreError::NoTangent {
            model: model.name().to_string(),
        }),
        None => Ok(()),
    }
}

/// The predictor of Eqs. 13–14 (the a_n, b_n of Eq. 22): x ← x + ∆t (v + (½ − β)∆t a),
/// v ← v + (1 − γ)∆t a, t ← t + ∆t.
pub fn predict(state: &mut State, dt: f64, beta: f64, gamma: f64) {
    let (cx, cv) = ((0.5 - beta) * dt, (1.0 - gamma) * dt);
    state
        .position
        .par_iter_mut()
        .zip(state.velocity.par_iter_mut())
        .zip(state.acceleration.par_iter())
        .with_min_len(PARTICLE_CHUNK)
        .for_each(|((x, v), a)| {
            *x += dt * (*v + cx * a);
            *v += cv * a;
        });
    state.time += dt;
}

/// The corrector of Eqs. 24–25 with the new acceleration: x ← x + β∆t² a, v ← v + γ∆t a.
pub fn correct(state: &mut State, dt: f64, beta: f64, gamma: f64) {
    let (cx, cv) = (beta * dt * dt, gamma * dt);
    state
        .position
        .par_iter_mut()
        .zip(state.velocity.par_iter_mut())
        .zip(state.acceleration.par_iter())
        .with_min_len(PARTICLE_CHUNK)
        .for_each(|((x, v), a)| {
            *x += cx * a;
            *v += cv * a;
        });
}

impl Stepper for Newmark {
    fn name(&self) -> &str {
        if self.is_implicit() {
            "newmark-implicit"
        } else {
            "newmark-explicit"
        }
    }

    fn dt(&self) -> f64 {
        self.dt
    }

    fn factor_stats(&self) -> Option<&FactorStats> {
        self.system
            .cholesky
            .is_factored()
            .then(|| self.system.cholesky.stats())
    }

    fn initialize(
        &mut self,
        state: &mut State,
        models: &mut [Box<dyn Model>],
    ) -> Result<(), CoreError> {
        refuse_rigid(state, "newmark")?;
        check_masses(state)?;
        compute_accelerations(state, models, &mut self.force, &mut self.torque)?;
        if self.is_implicit() {
            self.refactor(state, models)?;
        }
        Ok(())
    }

    fn step(&mut self, state: &mut State, models: &mut [Box<dyn Model>]) -> Result<(), CoreError> {
        let (dt, beta, gamma) = (self.dt, self.beta, self.gamma);
        predict(state, dt, beta, gamma);
        if self.is_implicit() {
            if self.update == TangentUpdate::EveryStep || !self.system.cholesky.is_factored() {
                self.refactor(state, models)?;
            }
            self.solve_accelerations(state, models)?;
        } else {
            compute_accelerations(state, models, &mut self.force, &mut self.torque)?;
        }
        correct(state, dt, beta, gamma);
        Ok(())
    }
}
