//! How a run steps, in two types for the two moments of one decision: what the scene asks for
//! ([`StepRequest`]: the [`Scheme`], a step or none, the safety factor on the stable bound,
//! local damping, adaptivity, the event solve) and what the run does, resolved once against
//! the models' stable bounds ([`StepSettings`]: the request kept whole, with the step it
//! resolved to and the bound it was chosen under). They stay apart because a request may
//! leave the step open and says how to fill it (an automatic explicit step, an implicit
//! fallback, the end to fit), while everything after the resolution (the stepper, the models
//! at [`Model::prepare`](crate::step::model::Model::prepare), the outputs) reads a decided
//! step; the settings hold the request rather than copies of its fields. [`Scheme`] is the
//! integration method, a part of both, and [`EventSolve`] a part of the scheme's request.
//!
//! The step rule: an explicit scheme (Verlet, Newmark with β = 0) takes `safety` times the
//! rigorous stable bound of [`crate::step::stepper::stable_step`] when no step is requested, and refuses a
//! requested step above the bound; an implicit or static scheme takes the requested step, or
//! the fallback the request names. An automatic step is shrunk so that a whole number of steps
//! reaches the request's `fit_to` time.

use crate::error::CoreError;
use crate::step::model::Model;
use crate::step::state::State;
use crate::step::stepper::{choose_step, stable_step};

/// The time-integration scheme.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Scheme {
    /// Explicit velocity Verlet (paper 000 §2.4).
    Verlet,
    /// Newmark-β (paper 001 §3): explicit for β = 0, implicit for β > 0.
    Newmark {
        /// β.
        beta: f64,
        /// γ.
        gamma: f64,
    },
    /// Linear static solves at a sequence of load levels.
    Static,
}

impl Scheme {
    /// Whether a step solves a linear system (implicit Newmark, static).
    pub fn is_implicit(&self) -> bool {
        match *self {
            Scheme::Verlet => false,
            Scheme::Newmark { beta, .. } => beta > 0.0,
            Scheme::Static => true,
        }
    }
}

/// How the implicit stepper solves a step whose matrix changed since its factorisation
/// (a model's events changed the tangent).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum EventSolve {
    /// Refactorises the matrix at every change: the faster on the benchmark beam
    /// (docs/bbm.md), and the default.
    #[default]
    Refactorize,
    /// Conjugate gradients preconditioned by the kept factor of the same step length;
    /// refactorises when they take more than a few iterations (the Newmark stepper's
    /// `MAX_ITERATIONS`).
    Preconditioned,
}

/// A run's stepping as the scene asks for it, before the step is resolved.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepRequest {
    /// The scheme.
    pub scheme: Scheme,
    /// The requested step (s); `None` for automatic.
    pub dt: Option<f64>,
    /// An automatic explicit step is this fraction of the stable bound.
    pub safety: f64,
    /// Local non-viscous damping fraction of the Verlet stepper (0: none).
    pub local_damping: f64,
    /// Adaptive Newmark steps (retakes at events, paper 001 Eqs. 29–30).
    pub adaptive: bool,
    /// How an implicit Newmark step solves after events changed the tangent.
    pub event_solve: EventSolve,
    /// The step of an implicit or static scheme when none is requested; `None` makes a
    /// missing step an error.
    pub implicit_default: Option<f64>,
    /// An automatic step is shrunk so that a whole number of steps reaches this time (the end
    /// of the run), and a static run's last load level is solved at exactly this time;
    /// `None` keeps the step as it is.
    pub fit_to: Option<f64>,
}

/// A run's stepping, resolved: the request, the step it resolved to and the stable bound it
/// was chosen under. What the stepper is built from and what the models learn
/// ([`Model::prepare`]).
#[derive(Clone, Debug, PartialEq)]
pub struct StepSettings {
    /// What the scene asked for: the scheme and its options, and the end of the run
    /// ([`StepRequest::fit_to`]) where a static run's last load level lands exactly.
    pub request: StepRequest,
    /// The step (s).
    pub dt: f64,
    /// The rigorous explicit stable bound at the start (s; infinite when no model bounds it)
    /// and the model that sets it.
    pub stable_dt: (f64, String),
}

impl StepSettings {
    /// Resolves `request` against the models' stable bounds at `state` (see the module docs
    /// for the rule). Fails on a requested explicit step above the bound, or on a missing
    /// step that nothing bounds.
    pub fn resolve(
        request: &StepRequest,
        state: &State,
        models: &[Box<dyn Model>],
    ) -> Result<StepSettings, CoreError> {
        let stable_dt = stable_step(state, models).unwrap_or((f64::INFINITY, String::new()));
        let explicit = !request.scheme.is_implicit();
        let dt = match (explicit, request.dt, request.implicit_default) {
            (true, requested, _) => choose_step(state, models, requested, request.safety)?,
            (false, Some(dt), _) => dt,
            (false, None, Some(dt)) => dt,
            (false, None, None) => return Err(CoreError::ImplicitNeedsStep),
        };
        let dt = match (request.dt, request.fit_to) {
            (None, Some(end)) => end / (end / dt).ceil(),
            _ => dt,
        };
        Ok(StepSettings {
            request: *request,
            dt,
            stable_dt,
        })
    }

    /// Whether a step solves a linear system with the models' tangents (implicit Newmark,
    /// static).
    pub fn is_implicit(&self) -> bool {
        self.request.scheme.is_implicit()
    }

    /// Number of steps to reach `t_end` (the last one may end slightly past it for a fixed
    /// step).
    pub fn steps_to(&self, t_end: f64) -> u64 {
        (t_end / self.dt - 1e-9).ceil().max(0.0) as u64
    }
}
