//! # qdem-io
//!
//! Scene files and outputs of qdem:
//!
//! - [`scene`]: the TOML scene format (a public contract), parsed with serde and validated with
//!   messages that name the file, line and key.
//! - [`build`]: turns a scene into a [`build::Simulation`]: one [`qdem_core::State`] for all
//!   bodies and only the models the scene needs.
//!   A `[bonded]` scene builds a 2D beam-bonded body instead (paper 001). `[granular]` adds a
//!   sample of rigid stones ([`granular_build`]), `[periodic]` a periodic cell and a
//!   time-delayed boundary (paper 003).
//! - [`runner`]: the run loop, sampling probes and writing snapshots.
//! - [`output`]: atomic writers for VTU/PVD, probe CSV and summary JSON.
//! - [`spectrum`]: dominant frequency of a probe record by FFT.
//! - [`plot`]: SVG line plots beside the CSVs.

mod bonded_build;
pub mod build;
pub mod checkpoint;
mod contact_build;
pub mod crack_svg;
pub mod granular_build;
pub mod output;
mod periodic_build;
pub mod plot;
mod run_record;
pub mod runner;
pub mod scene;
pub mod spectrum;
