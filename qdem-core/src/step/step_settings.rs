//! How a run steps, decided once when it is built: the scheme (Verlet, Newmark-β, static), the
//! step, the safety factor on the stable bound, local damping and adaptivity
//! ([`StepSettings`]); and what the models learn of it ([`Stepping`]).
//!
//! The step rule: an explicit scheme (Verlet, Newmark with β = 0) takes `safety` times the
//! rigorous stable bound of [`crate::step::stepper::stable_step`] when no step is requested, and refuses a
//! requested step above the bound; an implicit or static scheme takes the requested step, or
//! the fallback the request names. An automatic step is shrunk so that a whole number of steps
//! reaches the request's `fit_to` time.

use crate::error::CoreError;
use crate::step::model::Model;
use crate::step::state::State;
use crate::step::stepper::{choose_step, stable_step, Stepper};
use crate::{EventSolve, Newmark, StaticSteps, Verlet};

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

/// What the models learn of the run's stepping ([`Model::prepare`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stepping {
    /// The scheme solves a linear system with the models' tangents.
    pub implicit: bool,
    /// The step (s).
    pub dt: f64,
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

/// A run's stepping, resolved: the scheme, the step and the stable bound it was chosen under.
#[derive(Clone, Debug, PartialEq)]
pub struct StepSettings {
    /// The scheme.
    pub scheme: Scheme,
    /// The step (s).
    pub dt: f64,
    /// The safety factor the step was chosen with.
    pub safety: f64,
    /// Local non-viscous damping fraction (Verlet).
    pub local_damping: f64,
    /// Adaptive Newmark steps.
    pub adaptive: bool,
    /// How an implicit Newmark step solves after events changed the tangent.
    pub event_solve: EventSolve,
    /// The rigorous explicit stable bound at the start (s; infinite when no model bounds it)
    /// and the model that sets it.
    pub stable_dt: (f64, String),
    /// The end of the run the request named ([`StepRequest::fit_to`]), where a static run's
    /// last load level lands exactly.
    pub end: Option<f64>,
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
            scheme: request.scheme,
            dt,
            safety: request.safety,
            local_damping: request.local_damping,
            adaptive: request.adaptive,
            event_solve: request.event_solve,
            stable_dt,
            end: request.fit_to,
        })
    }

    /// What the models learn of the stepping.
    pub fn stepping(&self) -> Stepping {
        Stepping {
            implicit: self.scheme.is_implicit(),
            dt: self.dt,
        }
    }

    /// The stepper these settings describe.
    pub fn stepper(&self) -> Result<Box<dyn Stepper>, CoreError> {
        Ok(match self.scheme {
            Scheme::Verlet => Box::new(Verlet::new(self.dt).with_local_damping(self.local_damping)),
            Scheme::Newmark { beta, gamma } => {
                let newmark = Newmark::new(beta, gamma, self.dt)?.with_adaptive(self.adaptive);
                Box::new(newmark.with_event_solve(self.event_solve))
            }
            Scheme::Static => Box::new(StaticSteps::new(self.dt).ending_at(self.end)),
        })
    }

    /// Number of steps to reach `t_end` (the last one may end slightly past it for a fixed
    /// step).
    pub fn steps_to(&self, t_end: f64) -> u64 {
        (t_end / self.dt - 1e-9).ceil().max(0.0) as u64
    }
}
