//! [`Poses`]: `poses.csv` at the end of the run: where each rigid `[[body]]` ended, the file
//! `[[body]] pose_from` reads ([`crate::pose_from`]).

use super::Recorder;
use crate::build::Simulation;
use crate::output::OutputError;
use crate::pose_from::{poses, write_poses_csv};
use std::path::{Path, PathBuf};

/// The rigid bodies' record.
pub(crate) struct Poses {
    path: PathBuf,
}

impl Poses {
    pub(crate) fn new(out_dir: &Path) -> Poses {
        Poses {
            path: out_dir.join("poses.csv"),
        }
    }
}

impl Recorder for Poses {
    fn name(&self) -> &'static str {
        "poses"
    }

    fn finish(&mut self, sim: &Simulation) -> Result<(), OutputError> {
        write_poses_csv(&self.path, &poses(sim))
    }
}
