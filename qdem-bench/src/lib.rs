//! # qdem-bench
//!
//! Speed measurements of qdem: [`implicit`] times the sparse Cholesky path against the number
//! of unknowns; [`throughput`] holds the structured-mesh kernel benchmark used
//! by the criterion benches (`cargo bench -p qdem-bench`) and by `qdem bench` (JSON output).

pub mod implicit;
pub mod throughput;
