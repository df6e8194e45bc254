//! # qdem-bench
//!
//! Speed and accuracy measurements of qdem: [`implicit`] times the sparse Cholesky path against
//! the number of unknowns (`qdem bench --implicit`); [`throughput`] holds the structured-mesh
//! kernel benchmark used by the criterion benches (`cargo bench -p qdem-bench`) and by
//! `qdem bench` (table or JSON), with its peers the triad and the [`vector_peak`]; [`verify`] holds the analytical fixtures of `qdem verify`;
//! [`granular`] is the settled sphere packing compared with LIGGGHTS; [`cantilever`] runs the
//! paper's cantilever and measures it; [`speed_vs_error`] is the study behind
//! `docs/speed-vs-error.md` (binary `study`).

#![warn(missing_docs)]

pub mod cantilever;
pub mod granular;
pub mod implicit;
pub mod locking_cases;
pub mod speed_vs_error;
pub mod throughput;
pub mod vector_peak;
pub mod verify;
pub mod verify_locking;
