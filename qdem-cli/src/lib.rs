//! # qdem-cli
//!
//! The `qdem` command: `run`, `check`, `verify` and `bench`. The binary is a thin shell over
//! [`command::dispatch`]; the verification fixtures ([`verify`]) and the throughput benchmark
//! ([`bench`]) are library code so that tests and the criterion benches use the same code.

pub mod bench;
pub mod command;
pub mod progress;
pub mod verify;
