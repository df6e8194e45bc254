//! [`Stones`]: `stones.csv` of a `[granular]` sample at the end of the run (each stone's
//! spheres where they ended, the format `[granular] sample` reads, so one run's settled sample
//! is the next run's start), and the sample's figures in `summary.json`.

use super::{Recorder, RunFigures};
use crate::build::Simulation;
use crate::granular_build::write_stones_csv;
use crate::output::OutputError;
use serde_json::json;
use std::path::{Path, PathBuf};

/// The sample's record.
pub(crate) struct Stones {
    path: PathBuf,
}

impl Stones {
    pub(crate) fn new(out_dir: &Path) -> Stones {
        Stones {
            path: out_dir.join("stones.csv"),
        }
    }
}

impl Recorder for Stones {
    fn name(&self) -> &'static str {
        "stones"
    }

    fn finish(&mut self, sim: &Simulation) -> Result<(), OutputError> {
        let info = sim
            .granular
            .as_ref()
            .expect("registered for a granular scene");
        write_stones_csv(&self.path, info, &sim.world.state)
    }

    fn summarize(&self, sim: &Simulation, run: &RunFigures, summary: &mut serde_json::Value) {
        let info = sim
            .granular
            .as_ref()
            .expect("registered for a granular scene");
        summary["granular"] = json!({
            "name": info.name,
            "stones": info.len(),
            "spheres": info.radii.len(),
            "sphere_steps_per_second": run.rate(info.radii.len()),
        });
    }
}
