//! # qdem-cli
//!
//! The `qdem` command: `run`, `check`, `verify` and `bench`. The binary is a thin shell over
//! [`command::dispatch`]; the verification fixtures ([`verify`]) are library code so that the
//! tests run exactly what `qdem verify` prints, and the throughput measurement lives in
//! `qdem-bench` beside the criterion benches that share it.

#![warn(missing_docs)]

pub mod bench;
pub mod command;
pub mod progress;
pub mod verify;
