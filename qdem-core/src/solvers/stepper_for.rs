//! The stepper a run's resolved settings describe ([`stepper_for`]): the one place that maps
//! a [`Scheme`] and its options to a stepper of this area.

use crate::error::CoreError;
use crate::solvers::newmark::Newmark;
use crate::solvers::static_solve::StaticSteps;
use crate::solvers::verlet::Verlet;
use crate::step::step_settings::{Scheme, StepSettings};
use crate::step::stepper::Stepper;

/// The stepper `settings` describe: Verlet with its local damping, Newmark-β with its
/// adaptivity and event solve, or static solves ending at the request's end. Fails on
/// Newmark parameters out of range.
pub fn stepper_for(settings: &StepSettings) -> Result<Box<dyn Stepper>, CoreError> {
    let (request, dt) = (&settings.request, settings.dt);
    Ok(match request.scheme {
        Scheme::Verlet => Box::new(Verlet::new(dt).with_local_damping(request.local_damping)),
        Scheme::Newmark { beta, gamma } => {
            let newmark = Newmark::new(beta, gamma, dt)?.with_adaptive(request.adaptive);
            Box::new(newmark.with_event_solve(request.event_solve))
        }
        Scheme::Static => Box::new(StaticSteps::new(dt).ending_at(request.fit_to)),
    })
}
