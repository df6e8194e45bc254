//! [`Grading`]: `grading.csv` and `grading.svg` of a `[granular]` sample at the start of the
//! run: per stone in order of sieve size, its size, its mass and the fractions of the
//! sample's mass and number passing (a sieve curve by mass; [`crate::post::sieve`] for how a
//! clump's sieve size is measured), with `[granular] grading` (by number or by mass, as its
//! `grading_basis` says) drawn beside.

use super::Recorder;
use crate::build::Simulation;
use crate::output::{write_atomic, OutputError};
use crate::plot::{line_plot_svg, Labels, Series};
use crate::post::sieve::{grading_by_mass, sieve_size};
use crate::scene::GradingBasisName;
use qdem_core::Vec3;
use std::path::{Path, PathBuf};

/// The sample's grading, measured when the recorder is made.
pub(crate) struct Grading {
    csv: PathBuf,
    svg: PathBuf,
    /// Per stone by size: size, mass, mass passing, number passing.
    rows: Vec<[f64; 4]>,
    /// `[granular] grading`, (size, fraction passing by number or by mass).
    requested: Vec<(f64, f64)>,
    /// The plot's label of `requested`, naming its `grading_basis`.
    requested_label: &'static str,
}

impl Grading {
    pub(crate) fn new(sim: &Simulation, out_dir: &Path) -> Option<Grading> {
        let info = sim.granular.as_ref()?;
        let state = &sim.world.state;
        let stones: Vec<(f64, f64)> = info
            .stones
            .iter()
            .map(|(center, members)| {
                let centers: Vec<Vec3> = members.clone().map(|p| state.position[p]).collect();
                let radii = &info.radii[members.start - info.first_member..][..members.len()];
                (sieve_size(&centers, radii), state.mass[*center])
            })
            .collect();
        let granular = sim.scene.granular.as_ref()?;
        let requested = granular.grading.as_ref();
        Some(Grading {
            csv: out_dir.join("grading.csv"),
            svg: out_dir.join("grading.svg"),
            rows: grading_by_mass(&stones),
            requested: requested.map_or(Vec::new(), |g| g.iter().map(|p| (p[0], p[1])).collect()),
            requested_label: match granular.grading_basis {
                GradingBasisName::Number => "[granular] grading (by number)",
                GradingBasisName::Mass => "[granular] grading (by mass)",
            },
        })
    }
}

impl Recorder for Grading {
    fn name(&self) -> &'static str {
        "grading"
    }

    fn start(&mut self, resumed: bool) -> Result<(), OutputError> {
        if resumed || self.rows.is_empty() {
            return Ok(());
        }
        write_atomic(&self.csv, |w| {
            writeln!(w, "sieve_size,mass,mass_passing,number_passing")?;
            for row in &self.rows {
                let cells: Vec<String> = row.iter().map(|v| format!("{v:.9e}")).collect();
                writeln!(w, "{}", cells.join(","))?;
            }
            Ok(())
        })?;
        let by_mass: Vec<(f64, f64)> = self.rows.iter().map(|r| (r[0], r[2])).collect();
        let by_number: Vec<(f64, f64)> = self.rows.iter().map(|r| (r[0], r[3])).collect();
        let mut series = vec![
            Series {
                label: "by mass",
                points: &by_mass,
            },
            Series {
                label: "by number",
                points: &by_number,
            },
        ];
        if !self.requested.is_empty() {
            series.push(Series {
                label: self.requested_label,
                points: &self.requested,
            });
        }
        let labels = Labels {
            title: "grading of the sample",
            x: "sieve size (m)",
            y: "fraction passing",
        };
        line_plot_svg(&self.svg, &labels, &series)
    }
}
