//! [`Snapshots`]: every `vtu_every`, `vtu/state_NNNNN.vtu` of all bodies (reference points
//! with displacement and velocity per particle, von Mises stress and volumetric strain per
//! tetrahedron; rigid bodies' tetrahedra at zero) and `results.pvd`, their ParaView time
//! index, rewritten after each (the run creates `vtu/`).

use super::schedule::Schedule;
use super::{Recorder, RunFigures, StepInfo};
use crate::build::{BodyKind, Simulation};
use crate::output::{write_vtu, OutputError, PvdIndex, VtuGrid};
use qdem_core::{CheckpointError, Decoder, Encoder, Vec3};
use std::path::{Path, PathBuf};

/// The VTU series.
pub(crate) struct Snapshots {
    schedule: Schedule,
    out_dir: PathBuf,
    pvd: PvdIndex,
}

impl Snapshots {
    pub(crate) fn new(sim: &Simulation, out_dir: &Path) -> Snapshots {
        Snapshots {
            schedule: Schedule::new(sim.scene.output.vtu_every),
            out_dir: out_dir.to_path_buf(),
            pvd: PvdIndex::new(),
        }
    }
}

impl Recorder for Snapshots {
    fn name(&self) -> &'static str {
        "snapshots"
    }

    fn record(&mut self, sim: &Simulation, step: &StepInfo<'_>) -> Result<(), OutputError> {
        let time = sim.world.state.time;
        if !self.schedule.due(time, step.dt) {
            return Ok(());
        }
        let file = format!("vtu/state_{:05}.vtu", self.pvd.len());
        write_snapshot(sim, &self.out_dir.join(&file))?;
        self.pvd.push(time, file);
        self.pvd.write(&self.out_dir.join("results.pvd"))
    }

    fn summarize(&self, _sim: &Simulation, _run: &RunFigures, summary: &mut serde_json::Value) {
        summary["vtu_files"] = self.pvd.len().into();
    }

    fn save(&self, out: &mut Encoder) {
        out.f64(self.schedule.next);
        out.u64(self.pvd.len() as u64);
        for (time, file) in self.pvd.entries() {
            out.f64(*time);
            out.str(file);
        }
    }

    fn restore(&mut self, input: &mut Decoder<'_>) -> Result<(), CheckpointError> {
        self.schedule.next = input.f64("the VTU schedule")?;
        for _ in 0..input.u64("the VTU count")? {
            let time = input.f64("a VTU time")?;
            self.pvd.push(time, input.str("a VTU file name")?);
        }
        Ok(())
    }
}

/// One VTU of all bodies.
fn write_snapshot(sim: &Simulation, path: &Path) -> Result<(), OutputError> {
    let s = &sim.world.state;
    let displacement: Vec<Vec3> = (0..s.len()).map(|i| s.displacement(i)).collect();
    let mut tets = Vec::new();
    let (mut von_mises, mut volumetric) = (Vec::new(), Vec::new());
    for body in &sim.bodies {
        match (&body.kind, sim.tet_body(body)) {
            (_, Some(tet_body)) => {
                tets.extend_from_slice(tet_body.tets());
                let (vm, vol) = tet_body.tet_fields(s);
                von_mises.extend(vm);
                volumetric.extend(vol);
            }
            (BodyKind::Rigid { tets: rigid, .. }, None) => {
                tets.extend_from_slice(rigid);
                von_mises.extend(std::iter::repeat_n(0.0, rigid.len()));
                volumetric.extend(std::iter::repeat_n(0.0, rigid.len()));
            }
            (BodyKind::Deformable { .. }, None) => unreachable!("a deformable body has a TetBody"),
        }
    }
    let grid = VtuGrid {
        points: &s.reference,
        tets: &tets,
        point_vectors: vec![("displacement", &displacement), ("velocity", &s.velocity)],
        cell_scalars: vec![
            ("von_mises", &von_mises),
            ("volumetric_strain", &volumetric),
        ],
    };
    write_vtu(path, &grid)
}
