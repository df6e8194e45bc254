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
//! The QDEM tetrahedron (Nishiura, Sakaguchi & Aikawa 2017, Eqs. 1–11) is in [`tet_kernel`],
//! with the literal 12-triangle subdomain construction kept as its oracle in
//! [`tet_subdomain`], and the rigorous explicit step bound in [`mod@stable_step`].

#![warn(missing_docs)]

pub mod checkpoint;
pub(crate) mod conjugate_gradient;
pub mod distributed;
pub mod error;
pub mod gravity;
pub mod instability;
pub mod lanczos;
pub mod linear_tet;
pub mod local_damping;
pub mod local_particles;
pub mod material;
mod mechanisms;
pub mod model;
pub mod newmark;
pub mod nodal_load;
pub mod rigid_body;
mod rigid_reduction;
pub(crate) mod sparse;
pub mod stable_step;
pub mod stages;
pub mod state;
mod state_share;
pub mod static_solve;
pub mod step_settings;
pub mod stepper;
pub mod tangent;
pub mod tet_blocks;
pub mod tet_body;
pub mod tet_kernel;
pub mod tet_subdomain;
pub mod thread_ranks;
pub mod time_function;
pub mod verlet;
pub mod world;

/// A 3-vector of f64.
pub type Vec3 = nalgebra::Vector3<f64>;
/// A 3×3 matrix of f64.
pub type Mat3 = nalgebra::Matrix3<f64>;

pub use checkpoint::{CheckpointError, Decoder, Encoder};
pub use distributed::{Communicator, Decomposition};
pub use error::CoreError;
pub use gravity::Gravity;
pub use material::Material;
pub use model::{
    find_model, Linearized, Model, Ownership, ParticleReads, Persistence, Persistent, SplitModel,
    StepEvents,
};
pub use newmark::{EventSolve, Newmark, StepCounts, TangentUpdate};
pub use nodal_load::NodalLoad;
pub use rigid_body::RigidBodies;
pub use sparse::FactorStats;
pub use stages::{Stage, StageShare, StageTimes};
pub use state::{Dofs, ParticleSpin, State};
pub use static_solve::{StaticSolver, StaticSteps};
pub use step_settings::{Scheme, StepRequest, StepSettings, Stepping};
pub use stepper::{choose_step, stable_step, Stepper};
pub use tangent::Tangent;
pub use tet_blocks::BlockLayout;
pub use tet_body::TetBody;
pub use time_function::{Cyclic, TimeFunction};
pub use verlet::Verlet;
pub use world::{Halt, PostStep, World};
