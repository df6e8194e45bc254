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
//!   γ = ½, ṽ is the half-step velocity and the scheme is [`crate::solvers::Verlet`], operation for
//!   operation; it is stable for ∆t ≤ [`crate::step::stepper::stable_step()`].
//! - **β > 0** (implicit): Eq. 26 linearises the force at the step's start,
//!   f(x_{n+1}, v_{n+1}) ≈ f(x_n, v_n) − K (x_{n+1} − x_n) − C (v_{n+1} − v_n), and reads
//!
//!   (M + γ∆t C + β∆t² K) a_{n+1} = f(t_{n+1}, x_n, v_n) − K (x̃ − x_n) − C (ṽ − v_n)
//!
//!   (its f_n − K a_n − C b_n with a_n = x̃ − x_n, b_n = ṽ of Eq. 22, the damping of f_n
//!   included in f). It is solved as one Newton iteration from the held state: positions x_n
//!   with a⁰ = −(x̃ − x_n)/(β∆t²), velocities v_n and the damping's share of the
//!   jump to v⁰ = ṽ + γ∆t a⁰ added as −C (v⁰ − v_n); (M + γ∆t C + β∆t² K) δa = f − M a⁰ −
//!   C (v⁰ − v_n) gives a_{n+1} = a⁰ + δa. The models give f at a state the body has actually
//!   been in, so a force that is not K·u + C·v (the geometrically non-linear QDEM kernel,
//!   contacts that open, Coulomb caps, dashpots that act one way) is evaluated where it makes
//!   sense. This is exact for a linear force; otherwise it errs by the non-linearity over the
//!   step's own increment. Linearising at the predictor (x̃, ṽ) instead, the same for a linear
//!   force, breaks down when ∆t is far above the stable explicit step: for a mode with
//!   ω∆t ≫ 1 the predictor's ¼∆t² a_n moves it by (ω∆t)²/4 times its amplitude, and the held
//!   velocity v⁰ is −v_n for β = ¼, γ = ½ (tests `implicit_step_linearises_*`; the bonded
//!   beam at ∆t = 5 ms came apart within two steps of its first break). Equilibria (a = v = 0)
//!   are exactly those of the models' non-linear force, whatever the tangent. Average
//!   acceleration (β = ¼, γ = ½) is unconditionally stable and conserves energy for linear
//!   systems.
//!
//! Constraints (Eqs. 23, 27) are eliminated: fixed DOFs are left out of the system
//! (`sparse::FreeDofs`) and keep zero velocity and acceleration. The effective matrix is factorised by
//! `sparse::SparseCholesky`: with [`TangentUpdate::Fixed`] once, at [`Stepper::initialize`] (exact for
//! a linear small-strain run; each step then costs one force evaluation and two triangular
//! solves); with [`TangentUpdate::EveryStep`] K and C are reassembled at every step's start
//! and refactorised, reusing the symbolic analysis. The fixity is read when factorising.
//!
//! When a model's events change the tangent (bonds break, contacts open or close,
//! [`crate::step::StepEvents::commit_step`]), the matrix is reassembled and, by default
//! ([`EventSolve::Refactorize`]), refactorised. With [`EventSolve::Preconditioned`] (issue 26)
//! it is solved instead by conjugate gradients preconditioned with the kept factor of the same
//! step length (`conjugate_gradient`: k events change the matrix by a rank of at most 3k, so
//! a few events cost a few iterations); only when the iterations pass [`MAX_ITERATIONS`], or
//! the kept factor's answer is far off (stiff contacts added), is the matrix refactorised, and
//! the new factor kept in turn. Both answer the same system, to [`ITERATION_TOLERANCE`].

use crate::checkpoint::{CheckpointError, Decoder, Encoder};
use crate::error::CoreError;
use crate::solvers::conjugate_gradient::{self, Scratch};
use crate::solvers::sparse::{
    copy_matrix, explain_failure, restore_matrix, save_matrix, Assembler, DampingRows, FreeDofs,
    Scales, SparseCholesky, Tangent,
};
use crate::step::local_particles::ParticleRuns;
use crate::step::model::Model;
use crate::step::seam::Seam;
use crate::step::solve_report::{SolveReport, StepCounts};
use crate::step::stages::{Stage, StageTimes};
use crate::step::state::State;
use crate::step::step_settings::EventSolve;
use crate::step::stepper::{
    check_finite, check_masses, compute_accelerations_timed, refuse_rigid, Stepper, PARTICLE_CHUNK,
};
use crate::Vec3;
use faer::sparse::SparseColMat;
use rayon::prelude::*;

/// When the implicit stepper refactorises its effective matrix.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TangentUpdate {
    /// With K and C at the initial state, and again only when a model's events change its
    /// tangent ([`crate::step::StepEvents::commit_step`]: bonds broken, contacts made or lost).
    #[default]
    Fixed,
    /// Every step, with K and C at the step's start (large displacements or rotations).
    EveryStep,
}

/// The most conjugate-gradient iterations on a kept factor before refactorising. On the
/// 0.025 m benchmark beam with a bound of 12, 37 solves converged, 36 of them in 2–8
/// iterations, 9 were still far off after 12 (and 73 far off at the start); the iterations
/// then cost more wall time than the factorisations they saved, and with 6 about as much
/// (docs/bbm.md).
pub const MAX_ITERATIONS: usize = 6;

/// The relative error, in the energy norm of the kept factor, at which the iterations stop:
/// far below the error of the step's linearisation (Eq. 26 is one Newton iteration), so that
/// the crack phase follows the refactorising solver's to rounding of the bond stresses.
pub const ITERATION_TOLERANCE: f64 = 1e-10;

/// Retakes a sub-step at most this many times before accepting it: once, as paper 001 §4
/// recalculates "the last calculated step" once with ∆t·√α (Eq. 30).
const MAX_RETAKES: usize = 1;
/// Redoes a sub-step at most this many times when a trial met new contacts (implicit).
const MAX_REDOS: usize = 8;
/// The shortest sub-step of the adaptive control, as a fraction of ∆t: a crack that runs
/// bond after bond would otherwise be resolved one bond per (refactorised) sub-step.
const MIN_FRACTION: f64 = 1.0 / 16.0;

/// The Newmark-β family: explicit for β = 0, implicit for β > 0, optionally adaptive.
///
/// ```
/// use qdem_core::step::stepper::stable_step;
/// use qdem_core::{continuum::Material, continuum::TetBody, loads::NodalLoad, loads::TimeFunction};
/// use qdem_core::{solvers::Newmark, solvers::StaticSolver, step::Dofs, step::Model};
/// use qdem_core::{step::State, step::Stepper, Vec3};
///
/// // One viscous tetrahedron with three vertices clamped and a load on the fourth.
/// let build = || {
///     let nodes = vec![Vec3::zeros(), Vec3::x(), Vec3::y(), Vec3::z()];
///     let mut material = Material::elastic(1000.0, 1e6, 0.25);
///     material.shear_viscosity = 1e4;
///     material.bulk_viscosity = 1e4;
///     let body = TetBody::new("tet", &nodes, vec![[0, 1, 2, 3]], material).unwrap();
///     let mut state = State::at_rest(nodes);
///     body.lump_mass(&mut state.mass);
///     for i in 0..3 {
///         state.fix(i, Dofs::ALL);
///     }
///     let push = Vec3::new(0.0, 0.0, -1e3);
///     let load = NodalLoad::new("push", vec![3], push, TimeFunction::constant(1.0));
///     let models: Vec<Box<dyn Model>> = vec![Box::new(body), Box::new(load)];
///     (state, models)
/// };
///
/// // The static answer, K u = f.
/// let (mut state, mut models) = build();
/// StaticSolver::new().solve(&mut state, &mut models, 0.0)?;
/// let expected = state.displacement(3);
///
/// // Implicit average acceleration, with a step a hundred times the explicit bound, comes
/// // to rest there (up to the QDEM kernel's geometric non-linearity, of the order of the
/// // strain, here 5e-3).
/// let (mut state, mut models) = build();
/// let (bound, _) = stable_step(&state, &models).unwrap();
/// let mut newmark = Newmark::average_acceleration(100.0 * bound);
/// assert!(newmark.is_implicit());
/// newmark.initialize(&mut state, &mut models)?;
/// for _ in 0..200 {
///     newmark.step(&mut state, &mut models)?;
/// }
/// let settled = state.displacement(3);
/// assert!((settled - expected).norm() < 1e-2 * expected.norm());
/// # Ok::<(), qdem_core::error::CoreError>(())
/// ```
#[derive(Debug)]
pub struct Newmark {
    beta: f64,
    gamma: f64,
    dt: f64,
    update: TangentUpdate,
    events: EventSolve,
    adaptive: bool,
    force: Vec<Vec3>,
    torque: Vec<Vec3>,
    system: ImplicitSystem,
    saved: Option<Box<State>>,
    counts: StepCounts,
}

/// Buffers of the implicit solve of Eq. 26: one factorisation for the nominal step and one
/// for the last shorter sub-step of the adaptive control, so that a retake does not discard
/// the factorisation the following steps reuse.
#[derive(Debug, Default)]
struct ImplicitSystem {
    tangent: Tangent,
    tangent_current: bool,
    assembler: Assembler,
    /// The step the assembler's matrix is of, with the current tangent.
    assembled: Option<f64>,
    iterations: Scratch,
    dofs: Option<FreeDofs>,
    factors: Factors,
    rhs: Vec<f64>,
    /// v⁰ − v_n of the held state, translations then rotations ([`hold`]).
    velocity_change: (Vec<Vec3>, Vec<Vec3>),
    /// The tangent's damping by rows, for C (v⁰ − v_n).
    damping: DampingRows,
}

/// The factorisation for the nominal step and the one for the last shorter sub-step.
#[derive(Debug, Default)]
struct Factors {
    nominal: Factor,
    substep: Factor,
}

impl Factors {
    /// The nominal factorisation, or the sub-step one.
    fn get(&mut self, nominal: bool) -> &mut Factor {
        if nominal {
            &mut self.nominal
        } else {
            &mut self.substep
        }
    }
}

impl ImplicitSystem {
    /// Marks the tangent out of date (a model's tangent changed), and both factorisations:
    /// dropped to refactorise, or kept as preconditioners.
    fn invalidate(&mut self, events: EventSolve) {
        self.tangent_current = false;
        self.assembled = None;
        for factor in [&mut self.factors.nominal, &mut self.factors.substep] {
            factor.stale = true;
            if events == EventSolve::Refactorize {
                factor.step = None;
            }
        }
    }
}

/// A factorisation of M + γh C + β h² K for one step h, and the matrix it factorised (kept
/// for checkpoints: a resumed run factorises the same matrix again).
#[derive(Debug, Default)]
struct Factor {
    cholesky: SparseCholesky,
    step: Option<f64>,
    /// The tangent changed since the factorisation: the factor is a preconditioner.
    stale: bool,
    matrix: Option<SparseColMat<usize, f64>>,
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
            events: EventSolve::Preconditioned,
            adaptive: false,
            force: Vec::new(),
            torque: Vec::new(),
            system: ImplicitSystem::default(),
            saved: None,
            counts: StepCounts::default(),
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

    /// The same stepper solving after events as `events` says (default
    /// [`EventSolve::Preconditioned`]).
    pub fn with_event_solve(mut self, events: EventSolve) -> Newmark {
        self.events = events;
        self
    }

    /// The same stepper with the adaptive control of paper 001 Eqs. 29–30: a step that a
    /// model's [`crate::step::StepEvents::check_step`] rejects is retaken once from its start with ∆t·√α (but
    /// not shorter than ∆t/16), and the remainder of the nominal step follows as further
    /// sub-steps, each checked the same way (so outputs stay on the nominal grid). Off by
    /// default.
    pub fn with_adaptive(mut self, adaptive: bool) -> Newmark {
        self.adaptive = adaptive;
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

    /// Retakes, sub-steps and event steps so far.
    pub fn counts(&self) -> StepCounts {
        self.counts
    }

    /// Assembles M + γh C + β h² K (Eq. 26) for the step `h` and factorises it into the
    /// nominal or the sub-step factor, collecting the tangent at `state` first unless it is
    /// current. With positive masses (checked at [`Stepper::initialize`]) the matrix is
    /// positive definite even for a body free to move rigidly, so free bodies are not refused;
    /// a failed factorisation is explained by [`explain_failure`].
    fn refactor(
        &mut self,
        state: &State,
        models: &[Box<dyn Model>],
        h: f64,
    ) -> Result<(), CoreError> {
        if self.update == TangentUpdate::EveryStep {
            self.system.tangent_current = false;
        }
        self.assemble(state, models, h)?;
        self.factorize_assembled(state, models, h)
    }

    /// Collects the tangent at `state` unless it is current, and assembles M + γh C + β h² K
    /// for the step `h` unless the assembler holds it.
    fn assemble(
        &mut self,
        state: &State,
        models: &[Box<dyn Model>],
        h: f64,
    ) -> Result<(), CoreError> {
        let system = &mut self.system;
        if !system.tangent_current {
            collect_tangent(state, models, &mut system.tangent)?;
            system.tangent_current = true;
            system.assembled = None;
            system.damping.build(&system.tangent, state.dofs());
        }
        if system.assembled == Some(h) {
            return Ok(());
        }
        let scales = Scales {
            mass: 1.0,
            damping: self.gamma * h,
            stiffness: self.beta * h * h,
        };
        let dofs = FreeDofs::of(state);
        system.assembler.assemble(
            &dofs.local_tangent(&system.tangent),
            &state.node_mass(),
            &dofs,
            scales,
        )?;
        system.assembled = Some(h);
        system.dofs = Some(dofs);
        Ok(())
    }

    /// Factorises the assembled matrix of the step `h` into the nominal or the sub-step factor.
    fn factorize_assembled(
        &mut self,
        state: &State,
        models: &[Box<dyn Model>],
        h: f64,
    ) -> Result<(), CoreError> {
        let system = &mut self.system;
        let matrix = system.assembler.matrix().expect("assembled before");
        let factor = system.factors.get(h == self.dt);
        factor.step = None;
        if let Err(error) = factor.cholesky.factorize(matrix, "effective") {
            let pivot = factor.cholesky.failed_pivot();
            let dofs = system.dofs.as_ref().expect("assembled before");
            return Err(explain_failure(
                error,
                pivot,
                dofs,
                state,
                models,
                &dofs.local_tangent(&system.tangent),
            ));
        }
        factor.step = Some(h);
        factor.stale = false;
        factor.matrix = Some(copy_matrix(matrix.0));
        self.counts.factorizations += 1;
        Ok(())
    }

    /// Prepares the solve of a step of length `h`: refactorises unless a factor of `h` is
    /// kept; with a kept factor of an older tangent, collects and assembles the current
    /// matrix for [`Self::solve`] (or refactorises, with [`EventSolve::Refactorize`]).
    fn prepare_solve(
        &mut self,
        state: &State,
        models: &[Box<dyn Model>],
        h: f64,
    ) -> Result<(), CoreError> {
        let factor = self.system.factors.get(h == self.dt);
        let kept = factor.step == Some(h) && self.update == TangentUpdate::Fixed;
        match (kept, factor.stale) {
            (true, false) => Ok(()),
            (true, true) if self.events == EventSolve::Preconditioned => {
                self.assemble(state, models, h)
            }
            _ => self.refactor(state, models, h),
        }
    }

    /// Overwrites `system.rhs` with the solution for the step `h` ([`Self::prepare_solve`]
    /// first): the kept factor's two triangular solves, or conjugate gradients on it when the
    /// tangent changed since, refactorising when they pass [`MAX_ITERATIONS`].
    fn solve(&mut self, state: &State, models: &[Box<dyn Model>], h: f64) -> Result<(), CoreError> {
        self.counts.solves += 1;
        let system = &mut self.system;
        let factor = system.factors.get(h == self.dt);
        if !factor.stale {
            factor.cholesky.solve_in_place(&mut system.rhs);
            return Ok(());
        }
        let matrix = system.assembler.matrix().expect("assembled before").0;
        let outcome = conjugate_gradient::solve(
            matrix,
            &mut factor.cholesky,
            &mut system.rhs,
            &mut system.iterations,
            ITERATION_TOLERANCE,
            MAX_ITERATIONS,
        );
        let iterations = outcome.unwrap_or_else(|n| n);
        self.counts.iterations += iterations as u64;
        if outcome.is_ok() {
            self.counts.iterative_solves += 1;
            return Ok(());
        }
        system.rhs.copy_from_slice(system.iterations.rhs());
        self.factorize_assembled(state, models, h)?;
        let system = &mut self.system;
        let factor = system.factors.get(h == self.dt);
        factor.cholesky.solve_in_place(&mut system.rhs);
        Ok(())
    }

    /// Collects the models' tangent at `state` and factorises the effective matrix of the
    /// nominal step again: what the next step does after an event changed the tangent (a bond
    /// broke, a contact opened). Implicit steppers only.
    pub fn refactorize(
        &mut self,
        state: &State,
        models: &[Box<dyn Model>],
    ) -> Result<(), CoreError> {
        self.system.invalidate(EventSolve::Refactorize);
        self.refactor(state, models, self.dt)
    }

    /// One implicit step of length `h` (Eq. 26, linearised at the step's start): prepares the
    /// matrix of `h` with the tangent at x_n ([`Self::prepare_solve`]), holds the positions
    /// at x_n with the acceleration a⁰ that keeps them there ([`hold`]), evaluates the models'
    /// force f(t_{n+1}, x_n, v_n), solves (M + γhC + βh²K) δa = f − M a⁰ − C (v⁰ − v_n) and
    /// moves by δa ([`apply_increment`]).
    fn implicit_step(
        &mut self,
        state: &mut State,
        models: &mut [Box<dyn Model>],
        h: f64,
        (stages, seam): (&mut StageTimes, &mut dyn Seam),
    ) -> Result<(), CoreError> {
        self.prepare_solve(state, models, h)?;
        stages.mark(Stage::Solve);
        let (beta, gamma) = (self.beta, self.gamma);
        let mut change = std::mem::take(&mut self.system.velocity_change);
        change.0.resize(state.len(), Vec3::zeros());
        change.1.resize(state.spin.len(), Vec3::zeros());
        hold(state, h, beta, gamma, (&mut change.0, &mut change.1));
        stages.mark(Stage::Predict);
        seam.sum_forces(state, models, &mut self.force, &mut self.torque, stages);
        let rigid = state.rigid.len();
        let moments = &mut self.torque[rigid..];
        subtract_inertia(state, &mut self.force, moments);
        let held = (&change.0[..], &change.1[..]);
        let system = &mut self.system;
        system
            .damping
            .subtract_times(held, (&mut self.force, moments));
        let dofs = system.dofs.as_ref().expect("factorised before stepping");
        system.rhs.resize(dofs.len(), 0.0);
        dofs.gather_nodes((&self.force, moments), &mut system.rhs);
        let solved = self.solve(state, models, h);
        let system = &self.system;
        let dofs = system.dofs.as_ref().expect("factorised before stepping");
        let moments = &mut self.torque[rigid..];
        dofs.scatter_nodes(&system.rhs, (&mut self.force, moments));
        stages.mark(Stage::Solve);
        let held = (&change.0[..], &change.1[..]);
        apply_increment(state, (&self.force, moments), held, h, beta, gamma);
        self.system.velocity_change = change;
        solved?;
        let finite = check_finite(state);
        stages.mark(Stage::Integrate);
        finite
    }

    /// One Newmark step of length `h` from the current state, without events.
    fn advance(
        &mut self,
        state: &mut State,
        models: &mut [Box<dyn Model>],
        h: f64,
        (stages, seam): (&mut StageTimes, &mut dyn Seam),
    ) -> Result<(), CoreError> {
        if self.is_implicit() {
            return self.implicit_step(state, models, h, (stages, seam));
        }
        let (beta, gamma) = (self.beta, self.gamma);
        predict(state, h, beta, gamma);
        stages.mark(Stage::Predict);
        let (force, torque) = (&mut self.force, &mut self.torque);
        compute_accelerations_timed(state, models, force, torque, stages, seam)?;
        correct(state, h, beta, gamma);
        stages.mark(Stage::Integrate);
        Ok(())
    }

    /// Advances by at most `span`: a full step, or with adaptive control a shorter one after
    /// retakes (Eqs. 29–30); then lets the models commit their events. Returns the step taken.
    /// Each trial is completed through `exchange` with an agreement, since its events are
    /// read before the step ends.
    fn advance_adaptively(
        &mut self,
        state: &mut State,
        models: &mut [Box<dyn Model>],
        span: f64,
        stages: &mut StageTimes,
        seam: &mut dyn Seam,
    ) -> Result<f64, CoreError> {
        let mut h = span;
        if self.adaptive || self.is_implicit() {
            match &mut self.saved {
                Some(saved) => saved.copy_motion_from(state),
                None => self.saved = Some(Box::new(state.clone())),
            }
        }
        let forces_here = !self.is_implicit();
        let (mut retakes, mut redos) = (0, 0);
        stages.mark(Stage::Events);
        loop {
            let advanced = self.advance(state, models, h, (&mut *stages, &mut *seam));
            seam.complete(state, stages, advanced, true)?;
            let alpha = models
                .iter_mut()
                .filter_map(|m| m.events()?.check_step(state, forces_here))
                .min_by(f64::total_cmp);
            let stale = models
                .iter_mut()
                .any(|m| m.events().is_some_and(|e| e.tangent_stale()));
            let Some(saved) = &self.saved else { break };
            if stale && redos < MAX_REDOS {
                // Redo with the contacts the trial met in the matrix (an active-set pass).
                state.copy_motion_from(saved);
                self.system.invalidate(self.events);
                self.counts.redos += 1;
                redos += 1;
                continue;
            }
            match alpha {
                Some(alpha)
                    if self.adaptive && retakes < MAX_RETAKES && h > MIN_FRACTION * self.dt =>
                {
                    state.copy_motion_from(saved);
                    h = (h * alpha.clamp(0.0, 1.0).sqrt()).max(MIN_FRACTION * self.dt);
                    self.counts.retakes += 1;
                    retakes += 1;
                }
                _ => break,
            }
        }
        let changed = models.iter_mut().fold(false, |changed, m| {
            m.events().is_some_and(|e| e.commit_step(state)) | changed
        });
        self.counts.substeps += 1;
        if changed {
            self.counts.event_steps += 1;
            self.system.invalidate(self.events);
        }
        stages.mark(Stage::Events);
        Ok(h)
    }
}

/// Collects the tangent of every model into `tangent`; fails on a model without one.
pub(crate) fn collect_tangent(
    state: &State,
    models: &[Box<dyn Model>],
    tangent: &mut Tangent,
) -> Result<(), CoreError> {
    tangent.clear();
    for model in models {
        let Some(linear) = model.linearized() else {
            return Err(CoreError::NoTangent {
                model: model.name().to_string(),
            });
        };
        linear.add_tangent(state, tangent);
    }
    Ok(())
}

/// The predictor of Eqs. 13–14 (the a_n, b_n of Eq. 22): x ← x + ∆t (v + (½ − β)∆t a),
/// v ← v + (1 − γ)∆t a, t ← t + ∆t; the same for the particles' rotations.
pub fn predict(state: &mut State, dt: f64, beta: f64, gamma: f64) {
    predict_in(state, dt, beta, gamma, None);
}

/// [`predict`] of `only`'s particles (translations and rotations), or of every particle.
pub(crate) fn predict_in(
    state: &mut State,
    dt: f64,
    beta: f64,
    gamma: f64,
    only: Option<&ParticleRuns>,
) {
    let (cx, cv) = ((0.5 - beta) * dt, (1.0 - gamma) * dt);
    let update = |((x, v), a): ((&mut Vec3, &mut Vec3), &Vec3)| {
        *x += dt * (*v + cx * a);
        *v += cv * a;
    };
    match only {
        None => for_each_dof(state, update),
        Some(runs) => for_each_dof_in(state, runs, update),
    }
    state.time += dt;
}

/// The corrector of Eqs. 24–25 with the new acceleration: x ← x + β∆t² a, v ← v + γ∆t a,
/// and the same for the particles' rotations.
pub fn correct(state: &mut State, dt: f64, beta: f64, gamma: f64) {
    let (cx, cv) = (beta * dt * dt, gamma * dt);
    let update = |((x, v), a): ((&mut Vec3, &mut Vec3), &Vec3)| {
        *x += cx * a;
        *v += cv * a;
    };
    for_each_dof(state, update);
}

/// The start of an implicit step (Eq. 26 linearised at x_n, v_n): the acceleration
/// a⁰ = −(x̃ − x_n)/(β∆t²) = −(v_n + (½ − β)∆t a_n)/(β∆t) that leaves the positions at x_n,
/// and into `change` the v⁰ − v_n = (1 − γ)∆t a_n + γ∆t a⁰ that goes with it (−2v_n for
/// β = ¼, γ = ½); the velocities stay v_n, t ← t + ∆t; rotations likewise.
fn hold(state: &mut State, dt: f64, beta: f64, gamma: f64, change: (&mut [Vec3], &mut [Vec3])) {
    let (ca, cv) = ((0.5 - beta) * dt, (1.0 - gamma) * dt);
    let update = |((v, a), dv): ((&Vec3, &mut Vec3), &mut Vec3)| {
        let held = -(*v + ca * *a) / (beta * dt);
        *dv = cv * *a + gamma * dt * held;
        *a = held;
    };
    for ((_, v, a), dv) in dof_sets(state).into_iter().zip([change.0, change.1]) {
        v.par_iter()
            .zip(a.par_iter_mut())
            .zip(dv.par_iter_mut())
            .with_min_len(PARTICLE_CHUNK)
            .for_each(update);
    }
    state.time += dt;
}

/// The residual of Eq. 15 at the held state: force ← f − M a⁰, moment ← m − J α⁰.
fn subtract_inertia(state: &State, force: &mut [Vec3], moment: &mut [Vec3]) {
    let residual = |((f, a), m): ((&mut Vec3, &Vec3), &f64)| *f -= *m * a;
    let sets = [
        (force, &state.acceleration, &state.mass),
        (moment, &state.spin.acceleration, &state.spin.inertia),
    ];
    for (f, a, m) in sets {
        f.par_iter_mut()
            .zip(a.par_iter())
            .zip(m.par_iter())
            .with_min_len(PARTICLE_CHUNK)
            .for_each(residual);
    }
}

/// Adds the solved increment δa to the held state: x ← x + β∆t² δa, v ← v + (v⁰ − v_n) + γ∆t δa,
/// a ← a + δa, translations and rotations.
fn apply_increment(
    state: &mut State,
    increment: (&[Vec3], &[Vec3]),
    change: (&[Vec3], &[Vec3]),
    dt: f64,
    beta: f64,
    gamma: f64,
) {
    let (cx, cv) = (beta * dt * dt, gamma * dt);
    type Dof<'a> = (((&'a mut Vec3, &'a mut Vec3), &'a mut Vec3), &'a Vec3);
    let update = |((((x, v), a), d), dv): (Dof<'_>, &Vec3)| {
        *x += cx * d;
        *v += dv + cv * d;
        *a += d;
    };
    let extra = [(increment.0, change.0), (increment.1, change.1)];
    for ((x, v, a), (d, dv)) in dof_sets(state).into_iter().zip(extra) {
        x.par_iter_mut()
            .zip(v.par_iter_mut())
            .zip(a.par_iter_mut())
            .zip(d.par_iter())
            .zip(dv.par_iter())
            .with_min_len(PARTICLE_CHUNK)
            .for_each(update);
    }
}

/// Applies `update` to every (position, velocity, acceleration) triple, translations and
/// rotations, in parallel.
fn for_each_dof<F>(state: &mut State, update: F)
where
    F: Fn(((&mut Vec3, &mut Vec3), &Vec3)) + Sync + Send + Copy,
{
    for (x, v, a) in dof_sets(state) {
        x.par_iter_mut()
            .zip(v.par_iter_mut())
            .zip(a.par_iter())
            .with_min_len(PARTICLE_CHUNK)
            .for_each(update);
    }
}

/// [`for_each_dof`] over `runs`' particles only, a range to a thread at a time.
fn for_each_dof_in<F>(state: &mut State, runs: &ParticleRuns, update: F)
where
    F: Fn(((&mut Vec3, &mut Vec3), &Vec3)) + Sync + Send + Copy,
{
    for (x, v, a) in dof_sets(state) {
        if x.is_empty() {
            continue;
        }
        let a: &[Vec3] = a;
        runs.split(x)
            .into_par_iter()
            .zip(runs.split(v))
            .zip(runs.batches())
            .for_each(|((x, v), ranges)| {
                for ((x, v), r) in x.into_iter().zip(v).zip(ranges) {
                    x.iter_mut()
                        .zip(v.iter_mut())
                        .zip(&a[r.clone()])
                        .for_each(update);
                }
            });
    }
}

/// The (position, velocity, acceleration) arrays of the translations, then of the particles'
/// rotations.
type DofSet<'a> = (&'a mut [Vec3], &'a mut [Vec3], &'a mut [Vec3]);

/// The two sets of generalised DOFs of `state`: translations, then rotations.
fn dof_sets(state: &mut State) -> [DofSet<'_>; 2] {
    let spin = &mut state.spin;
    [
        (
            &mut state.position,
            &mut state.velocity,
            &mut state.acceleration,
        ),
        (&mut spin.angle, &mut spin.velocity, &mut spin.acceleration),
    ]
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

    fn report(&self) -> SolveReport {
        let cholesky = &self.system.factors.nominal.cholesky;
        SolveReport {
            counts: self.counts,
            factor: cholesky.is_factored().then(|| cholesky.stats().clone()),
        }
    }

    fn forces(&self) -> &[Vec3] {
        &self.force
    }

    fn forces_mut(&mut self) -> &mut [Vec3] {
        &mut self.force
    }

    /// The counts and, for the implicit stepper, the tangent, the assembler's pattern and, for
    /// each kept factorisation, its step, whether it is a preconditioner and the matrix it
    /// factorised, so that a resumed run factorises the same matrices again.
    fn save(&self, out: &mut Encoder) -> Result<(), CheckpointError> {
        out.tag("newmark");
        self.counts.to_array().into_iter().for_each(|n| out.u64(n));
        if self.is_implicit() {
            let system = &self.system;
            out.bool(system.tangent_current);
            system.tangent.save(out);
            system.assembler.save(out);
            for factor in [&system.factors.nominal, &system.factors.substep] {
                out.option_f64(factor.step);
                out.bool(factor.stale);
                if let (Some(_), Some(matrix)) = (factor.step, &factor.matrix) {
                    save_matrix(matrix.as_ref(), out);
                }
            }
        }
        Ok(())
    }

    fn resume(
        &mut self,
        state: &mut State,
        _models: &mut [Box<dyn Model>],
        input: &mut Decoder<'_>,
    ) -> Result<(), CoreError> {
        refuse_rigid(state, "newmark")?;
        check_masses(state)?;
        input.tag("newmark")?;
        let mut counts = [0; StepCounts::LEN];
        for n in &mut counts {
            *n = input.u64("the step counts")?;
        }
        if self.is_implicit() {
            self.system.tangent_current = input.bool("the tangent flag")?;
            let dofs = state.dofs();
            self.system.tangent.restore(input, dofs)?;
            self.system.damping.build(&self.system.tangent, dofs);
            self.system.assembler.restore(input)?;
            self.system.assembled = None;
            self.system.dofs = Some(FreeDofs::of(state));
            for nominal in [true, false] {
                let step = input.option_f64("a factorised step")?;
                let stale = input.bool("a factor's staleness")?;
                let factor = self.system.factors.get(nominal);
                factor.step = None;
                factor.stale = stale;
                if step.is_some() {
                    let matrix = restore_matrix(input)?;
                    factor
                        .cholesky
                        .factorize((matrix.as_ref(), 0.0), "effective")?;
                    factor.matrix = Some(matrix);
                    factor.step = step;
                }
            }
        }
        self.counts = StepCounts::from_array(counts);
        Ok(())
    }

    fn initialize_in(
        &mut self,
        state: &mut State,
        models: &mut [Box<dyn Model>],
        seam: &mut dyn Seam,
    ) -> Result<(), CoreError> {
        refuse_rigid(state, "newmark")?;
        check_masses(state)?;
        let (force, torque) = (&mut self.force, &mut self.torque);
        let stages = &mut StageTimes::off();
        compute_accelerations_timed(state, models, force, torque, stages, seam)?;
        if self.is_implicit() {
            self.refactor(state, models, self.dt)?;
        }
        Ok(())
    }

    /// Advances by ∆t; with adaptive control possibly in several sub-steps, the last ending
    /// exactly at t + ∆t, each completed through `exchange` before its events are checked
    /// and before the next one predicts from it.
    fn step_timed(
        &mut self,
        state: &mut State,
        models: &mut [Box<dyn Model>],
        stages: &mut StageTimes,
        seam: &mut dyn Seam,
    ) -> Result<(), CoreError> {
        let end = state.time + self.dt;
        let mut remaining = self.dt;
        while remaining > 1e-9 * self.dt {
            remaining -= self.advance_adaptively(state, models, remaining, stages, seam)?;
        }
        state.time = end;
        Ok(())
    }
}
