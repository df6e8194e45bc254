//! # qdem-io
//!
//! Scene files and outputs of qdem:
//!
//! - [`scene`]: the TOML scene format (a public contract), parsed with serde and validated with
//!   messages that name the file, line and key.
//! - [`build`]: turns a scene into a [`build::Simulation`]: one [`qdem_core::State`] for all
//!   bodies and only the models the scene needs, from the validated scene and the references it
//!   resolved (one module per part of the scene under `build/`).
//!   A `[bonded]` scene builds a 2D beam-bonded body instead (paper 001). `[granular]` adds a
//!   sample of rigid stones ([`granular_build`]), `[periodic]` a periodic cell and a
//!   time-delayed boundary (paper 003).
//! - [`runner`]: the run loop: steps the [`qdem_core::World`] a build made and hands each
//!   step to the outputs' recorders (`record`: one file per output).
//! - [`output`]: atomic writers for VTU/PVD, probe CSV and summary JSON.
//! - [`spectrum`]: dominant frequency of a probe record by FFT.
//! - [`plot`]: SVG line plots beside the CSVs.
//! - `[ballast]` ([`ballast_build`]): deformable stones laid out for deposition (paper 000 §4);
//!   `[run] start_from` begins a run from another scene's checkpoint; a `[[load]]` may follow
//!   a CSV time series.
//! - [`analyze`]: Parzen-smoothed linear spectra and mobility of a run's sensors
//!   ([`linear_spectrum`], paper 000 §4.2).

#![warn(missing_docs)]

pub mod analyze;
pub mod build;
pub mod checkpoint;
pub mod crack_svg;
mod csv_rows;
pub mod inputs;
pub mod linear_spectrum;
pub mod output;
pub mod plot;
pub mod pose_from;
mod record;
mod run_record;
pub mod runner;
pub mod scene;
pub mod spectrum;
mod start_from;

/// `[ballast]` stones ([`build::ballast`], kept at its former path).
pub use build::ballast as ballast_build;
/// `[granular]` stones ([`build::granular`], kept at its former path).
pub use build::granular as granular_build;
pub(crate) use build::load_series;
