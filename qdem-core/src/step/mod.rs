//! The bottom layer of the crate, what every other area builds on: the [`state::State`] (with
//! its [`rigid_body`]s, held at points by [`rigid_constraints`], and the [`local_particles`] a rank steps), [`model::Model`] (a source
//! of forces) and its facets, the [`post_step`] hooks, [`stepper::Stepper`] (advances a state
//! under the models) with the [`seam`] it evaluates forces through and the [`solve_report`]
//! it gives, the [`tangent`] of implicit solves, the named, timed [`stages`] of a step and
//! the step settings resolved once ([`step_settings`]), and the persistent [`team`] of
//! threads whose phases the stages of a step may run as. It names no other area but the
//! split facets' `Reads` of [`crate::parallel`], until those facets move here.

pub mod frames;
pub(crate) mod instability;
pub mod local_particles;
pub mod model;
pub mod post_step;
pub mod rigid_body;
pub mod rigid_constraints;
pub mod seam;
pub mod solve_report;
pub mod split;
pub mod stages;
pub mod state;
pub mod step_settings;
pub mod stepper;
pub mod tangent;
pub mod team;

pub use frames::ParticleFrames;
pub use model::Deformable;
pub use model::Linearized;
pub use model::Model;
pub use model::Persistence;
pub use model::Persistent;
pub use model::StepEvents;
pub use post_step::Halt;
pub use post_step::PostStep;
pub use rigid_body::RigidBodies;
pub use rigid_constraints::{MemberHold, PointHolds};
pub use solve_report::FactorStats;
pub use solve_report::SolveReport;
pub use solve_report::StepCounts;
pub use split::Part;
pub use split::PartialSums;
pub use split::Reads;
pub use stages::Stage;
pub use stages::StageShare;
pub use stages::StageTimes;
pub use state::Dofs;
pub use state::ParticleSpin;
pub use state::State;
pub use step_settings::EventSolve;
pub use step_settings::Scheme;
pub use step_settings::StepRequest;
pub use step_settings::StepSettings;
pub use stepper::Stepper;
pub use tangent::Tangent;
