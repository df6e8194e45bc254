//! `vtu/bonds_NNNNN.vtu`: a `[bonded]` body's discs and beam bonds: the particles as points
//! with `radius` (m), `displacement` (m) and `velocity` (m/s), and every bond, broken ones
//! included, as a line between its two particles with `intact` (1, or 0 once broken),
//! `stress` (Pa, paper 001 Eq. 11, at the last committed step; a broken bond keeps the stress
//! it broke at) and `stress_ratio` (stress over the bond's strength, 1 at breaking).
//! ParaView: *Threshold* on `intact` shows the crack (the broken bonds), *Glyph* the discs.

use crate::output::{write_vtu_mesh_at, OutputError, VtuCells, VtuField, VtuMesh};
use qdem_contact::BondedParticles;
use qdem_core::step::State;
use std::path::Path;

/// Writes the discs and bonds of `bonded` at `state` to `path`.
pub(crate) fn write_bonds(
    bonded: &BondedParticles,
    state: &State,
    path: &Path,
) -> Result<(), OutputError> {
    let n = bonded.radii().len();
    let displacement: Vec<_> = (0..n).map(|i| state.displacement(i)).collect();
    let bonds = bonded.bonds();
    let lines: Vec<[u32; 2]> = bonds.iter().map(|b| [b.i, b.j]).collect();
    let intact: Vec<i64> = (0..bonds.len())
        .map(|k| i64::from(bonded.is_intact(k)))
        .collect();
    let stress = bonded.stresses();
    let ratio: Vec<f64> = bonds
        .iter()
        .zip(stress)
        .map(|(b, s)| s / b.strength)
        .collect();
    let mesh = VtuMesh {
        points: &state.position[..n],
        cells: VtuCells::Lines(&lines),
        point_data: vec![
            ("radius", VtuField::Scalars(bonded.radii())),
            ("displacement", VtuField::Vectors(&displacement)),
            ("velocity", VtuField::Vectors(&state.velocity[..n])),
        ],
        cell_data: vec![
            ("stress_ratio", VtuField::Scalars(&ratio)),
            ("stress", VtuField::Scalars(stress)),
            ("intact", VtuField::Integers(&intact)),
        ],
    };
    write_vtu_mesh_at(path, &mesh, Some(state.time))
}
