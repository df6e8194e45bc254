//! # qdem-bench
//!
//! Speed measurements of qdem: [`throughput`] holds the structured-mesh kernel benchmark used
//! by the criterion benches (`cargo bench -p qdem-bench`) and by `qdem bench` (JSON output).

pub mod throughput;
