//! The step API: [`model::Model`] (a source of forces) and its facets, [`stepper::Stepper`]
//! (advances a state under the models), the named, timed [`stages`] of a step and the step
//! settings resolved once ([`step_settings`]).

pub(crate) mod instability;
pub mod local_particles;
pub mod model;
pub mod post_step;
pub mod rigid_body;
pub mod seam;
pub mod solve_report;
pub mod stages;
pub mod state;
pub mod step_settings;
pub mod stepper;
pub mod tangent;
