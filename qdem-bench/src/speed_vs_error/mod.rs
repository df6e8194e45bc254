//! Speed versus error for every kind of scene, the study behind `docs/speed-vs-error.md`
//! (`study speed-vs-error`, binary `study`): one module per family of scenes, each running a
//! small sweep of the modelling choices that family offers, measuring each run's CPU seconds
//! ([`cpu_seconds`]) and its error against the family's named reference, and writing its
//! section of the page with a table and an SVG ([`page`] keeps the sections not run and the
//! hand-written part). The families: [`cantilever`] (mesh, integrator), [`bbm`] (element
//! size, ∆t, explicit or implicit), [`boxtest`] (contact stiffness), [`packing`] (∆t as a
//! fraction of the Rayleigh time), [`track`] (the reduced ballasted track: stone kind and
//! contact stiffness).

pub mod bbm;
pub mod boxtest;
pub mod cantilever;
mod cpu;
pub mod packing;
pub mod page;
pub mod track;

pub use crate::cantilever::StudyError;
pub use cantilever::{run_study, StudyRow};
pub use cpu::{cpu_seconds, timed};
pub use page::{write_page, KEPT_FROM};

use std::path::Path;

/// How large a sweep: `Quick` runs in seconds (the tests), `Full` is the page's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Size {
    /// A few seconds a family in a debug build.
    Quick,
    /// The sizes of the page.
    Full,
}

/// A family of scenes with its own section of the page.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    /// The paper's cantilever: mesh and integrator (`cantilever`).
    Cantilever,
    /// The paper 001 benchmark beam: element size, ∆t, explicit or implicit (`bbm`).
    Bbm,
    /// The box test's periodic cell: contact stiffness against settlement (`boxtest`).
    Boxtest,
    /// An elastic sphere packing: ∆t against energy drift and contact force (`packing`).
    Packing,
    /// The reduced ballasted track: stone kind and contact stiffness (`track`).
    Track,
}

impl Family {
    /// Every family, in the page's order.
    pub const ALL: [Family; 5] = [
        Family::Cantilever,
        Family::Bbm,
        Family::Boxtest,
        Family::Packing,
        Family::Track,
    ];

    /// The name on the command line and in the page's markers.
    pub fn name(self) -> &'static str {
        match self {
            Family::Cantilever => "cantilever",
            Family::Bbm => "bbm",
            Family::Boxtest => "boxtest",
            Family::Packing => "packing",
            Family::Track => "track",
        }
    }

    /// The family named `name`, or a message listing the names.
    ///
    /// ```
    /// use qdem_bench::speed_vs_error::Family;
    /// assert_eq!(Family::parse("bbm"), Ok(Family::Bbm));
    /// assert_eq!(Family::parse("track"), Ok(Family::Track));
    /// assert!(Family::parse("beam")
    ///     .unwrap_err()
    ///     .contains("cantilever, bbm, boxtest, packing, track"));
    /// ```
    pub fn parse(name: &str) -> Result<Family, String> {
        Family::ALL
            .into_iter()
            .find(|f| f.name() == name)
            .ok_or_else(|| {
                let names: Vec<&str> = Family::ALL.iter().map(|f| f.name()).collect();
                format!("no family `{name}`: {}", names.join(", "))
            })
    }
}

/// What a sweep runs on: its size, where runs write their outputs, the figures' folder and
/// the machine line each section states.
pub struct Setting<'a> {
    /// Size of the sweeps.
    pub size: Size,
    /// Folder of the runs' outputs.
    pub work: &'a Path,
    /// Folder of the SVGs (`docs/figures`).
    pub figures: &'a Path,
    /// The machine and its load, stated in each section.
    pub machine: &'a str,
    /// The cantilever's meshes ("100" = lc 0.100 m) and Newmark steps (s).
    pub cantilever: (&'a [&'a str], &'a [f64]),
}

/// Runs the sweep of `family` and returns its section of the page, its figure written (the
/// cantilever's sweep is [`Setting::cantilever`]'s whatever the size).
pub fn run_family(family: Family, setting: &Setting<'_>) -> Result<String, StudyError> {
    std::fs::create_dir_all(setting.figures).map_err(|e| StudyError::Probes {
        path: setting.figures.to_path_buf(),
        message: e.to_string(),
    })?;
    match family {
        Family::Cantilever => {
            let (meshes, dts) = setting.cantilever;
            let rows = run_study(meshes, dts, setting.work)?;
            cantilever::section(&rows, setting.machine, setting.figures)
        }
        Family::Bbm => {
            let sweep = bbm::Sweep::of(setting.size);
            let rows = bbm::run(&sweep, &setting.work.join("bbm"))?;
            bbm::section(&rows, setting.machine, setting.figures)
        }
        Family::Boxtest => {
            let sweep = boxtest::Sweep::of(setting.size);
            let rows = boxtest::run(&sweep, &setting.work.join("boxtest"))?;
            boxtest::section(&sweep, &rows, setting.machine, setting.figures)
        }
        Family::Packing => {
            let sweep = packing::Sweep::of(setting.size);
            let rows = packing::run(&sweep)?;
            packing::section(&sweep, &rows, setting.machine, setting.figures)
        }
        Family::Track => {
            let sweep = track::Sweep::of(setting.size);
            let (stones, rows) = track::run(&sweep, &setting.work.join("track"))?;
            track::section(&sweep, &stones, &rows, setting.machine, setting.figures)
        }
    }
}
