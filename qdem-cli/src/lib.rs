//! # qdem-cli
//!
//! The `qdem` command: `run`, `check`, `analyze`, `verify` and `bench`. The binary is a thin
//! shell over [`command::dispatch`]; this crate parses the command line, dispatches, shows
//! progress and renders errors. The verification fixtures (`qdem_bench::verify`) and the
//! throughput measurements (`qdem_bench::throughput`, `qdem_bench::implicit`) live in
//! `qdem-bench`, so that its tests and benches run exactly what `qdem verify` and `qdem bench`
//! print.

#![warn(missing_docs)]

pub mod check;
pub mod command;
pub mod huge_pages;
#[cfg(feature = "mpi")]
pub mod mpi_ranks;
pub mod progress;
pub mod run_length;
