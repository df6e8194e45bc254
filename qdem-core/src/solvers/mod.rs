//! The steppers and their algebra: explicit [`verlet::Verlet`] (paper 000 §2.4), the
//! Newmark-β family ([`newmark::Newmark`], paper 001 §3), the linear static solve
//! ([`static_solve`]), local damping and the sparse factorisations behind them; the stepper a
//! run's settings describe ([`stepper_for::stepper_for`]).

pub(crate) mod conjugate_gradient;
pub mod local_damping;
pub mod newmark;
pub(crate) mod sparse;
pub mod static_solve;
pub mod stepper_for;
pub mod verlet;
pub(crate) mod verlet_sweeps;

pub use newmark::Newmark;
pub use newmark::TangentUpdate;
pub use static_solve::StaticSolver;
pub use static_solve::StaticSteps;
pub use verlet::Verlet;
