//! Modal analysis: the [`lanczos`] modes of a state's tangent, with the rigid-body and
//! mechanism reductions it needs.

pub mod lanczos;
mod mechanisms;
mod partly_fixed;
mod rigid_reduction;
