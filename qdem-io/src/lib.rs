//! # qdem-io
//!
//! Scene files and outputs of qdem, laid out by stage:
//!
//! - [`scene`]: the TOML scene format (a public contract), parsed with serde and validated with
//!   messages that name the file, line and key; validation resolves the references between
//!   tables into indices.
//! - [`build`]: turns a validated scene into a [`build::Simulation`]: the
//!   [`qdem_core::world::World`] (one [`qdem_core::step::State`] for all bodies, only the models the scene
//!   needs, the step settings, the post-step hooks) and what the outputs need to know of its
//!   bodies and probes; one module per part of the scene (contacts, `[granular]` stones,
//!   `[ballast]`, a `[bonded]` beam of paper 001, the `[periodic]` cell of paper 003,
//!   `pose_from`, `rest_on`, `[run] start_from`, load series).
//! - [`run`]: the run loop ([`runner`]) that steps the world and hands each step to one
//!   recorder per output, checkpoints ([`checkpoint`]) and the fingerprints of the files they
//!   depend on ([`inputs`]).
//! - [`output`]: atomic writers for VTU/PVD, probe CSV and summary JSON.
//! - [`post`]: post-processing: spectra and mobility of a run's sensors ([`analyze`],
//!   `qdem analyze`), dominant frequencies ([`spectrum`]), plots ([`plot`]) and the crack
//!   picture ([`crack_svg`]).
//!
//! The modules of each stage are also reachable at the crate root under their own names
//! ([`runner`], [`checkpoint`], [`analyze`], …), the paths the other crates use.

#![warn(missing_docs)]

pub mod advice;
pub mod build;
mod csv_rows;
pub mod output;
pub mod post;
pub mod run;
pub mod scene;

pub use build::pose_from;
pub use post::{analyze, crack_svg, linear_spectrum, mode_marks, modes, plot, spectrum};
pub use run::{checkpoint, inputs, runner};

/// `[ballast]` stones ([`build::ballast`], kept at its former path).
pub use build::ballast as ballast_build;
/// `[granular]` stones ([`build::granular`], kept at its former path).
pub use build::granular as granular_build;
pub(crate) use build::load_series;
