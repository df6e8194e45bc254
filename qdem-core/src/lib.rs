//! # qdem-core
//!
//! The continuum kernel of qdem and the small API everything else builds on:
//!
//! - [`State`]: structure-of-arrays storage of particle positions, velocities, accelerations,
//!   lumped masses and fixity, plus the rotation of rigid bodies ([`rigid_body`]).
//! - [`Model`]: a source of forces (a [`TetBody`], [`Gravity`], a [`NodalLoad`], …) that also
//!   states the stable time step it allows.
//! - [`World`]: a state, its models, its stepper and its post-step hooks, stepped as named,
//!   timed stages ([`stages`]) with the step settings resolved once ([`StepSettings`]): what
//!   `qdem run` does, for whoever embeds the crate.
//! - [`Stepper`]: advances the state under a list of models; [`Verlet`] is the explicit
//!   velocity Verlet of the QDEM paper; [`Newmark`] the Newmark-β family of paper 001 §3,
//!   explicit (β = 0) or implicit (β > 0, a sparse Cholesky solve per step);
//!   [`StaticSolver`] the linear static solve K u = f.
//!
//! The crate is laid out by area, in layers that import only downwards (checked by
//! `tests/layers.rs`):
//!
//! 1. [`step`]: the state and the rigid bodies in it, the model and its facets, the post-step
//!    hooks, the stepper and the seam it evaluates forces through, the tangent, the stages,
//!    the step settings and the solve report (with [`error`] and [`checkpoint`]);
//! 2. the physics, [`continuum`] (the QDEM tetrahedron, its bodies, materials and step
//!    bounds) and [`loads`] (gravity, nodal loads, time functions), and the [`solvers`]
//!    (Verlet, Newmark-β, the static solve and their sparse algebra), each on its own;
//! 3. [`modal`] (Lanczos modes of the tangents);
//! 4. [`parallel`] (the decomposition over ranks, distributing what the models declare,
//!    behind one seam: the [`ParallelRuntime`]);
//! 5. [`world`]: the [`World`], which holds the parallel runtime.
//!
//! The flat re-exports below are for other crates and embedders; the crate itself names
//! everything by its area path.
//!
//! The QDEM tetrahedron (Nishiura, Sakaguchi & Aikawa 2017, Eqs. 1–11) is in [`tet_kernel`],
//! with the literal 12-triangle subdomain construction kept as its oracle in
//! [`tet_subdomain`], and the rigorous explicit step bound in [`mod@stable_step`].

#![warn(missing_docs)]

pub mod checkpoint;
pub mod continuum;
pub mod error;
pub mod loads;
pub mod modal;
pub mod parallel;
pub mod solvers;
pub mod step;
pub mod world;

/// A 3-vector of f64.
pub type Vec3 = nalgebra::Vector3<f64>;
/// A 3×3 matrix of f64.
pub type Mat3 = nalgebra::Matrix3<f64>;
