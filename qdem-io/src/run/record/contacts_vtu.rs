//! `vtu/contacts_NNNNN.vtu`: the touching contacts of the step as lines, the force chains:
//! two points per contact (the first sphere's centre; the second sphere's at the periodic
//! image it touches, or the wall's nearest point) and per line `normal_force`,
//! `tangential_force` (N, vectors on the first sphere; the second feels their opposite) with
//! their magnitudes `normal_force_magnitude`, `tangential_force_magnitude`, and the partners
//! `first`, `second` (sphere indices of `spheres_NNNNN.vtu`, −1 for a wall) and `wall` (the
//! `[[wall]]`'s index, −1 for a pair). With a time-delayed boundary, `scale_first` and
//! `scale_second` are the ghost scales the model applied to the force on each partner.
//! ParaView: *Extract Surface*, then *Tube*, coloured by `normal_force_magnitude`.

use crate::output::{write_vtu_mesh_at, OutputError, VtuCells, VtuField, VtuMesh};
use qdem_contact::{DemContacts, Partner};
use qdem_core::Vec3;
use std::path::Path;

/// The per-line arrays of the contacts file.
#[derive(Default)]
struct Lines {
    ends: Vec<Vec3>,
    normal: Vec<Vec3>,
    tangential: Vec<Vec3>,
    normal_magnitude: Vec<f64>,
    tangential_magnitude: Vec<f64>,
    first: Vec<i64>,
    second: Vec<i64>,
    wall: Vec<i64>,
    scale_first: Vec<f64>,
    scale_second: Vec<f64>,
}

/// Writes the touching contacts of `contacts`' last evaluation, at `time` (s), to `path`.
pub(crate) fn write_contacts(
    contacts: &DemContacts,
    time: f64,
    path: &Path,
) -> Result<(), OutputError> {
    let mut l = Lines::default();
    for c in contacts.touching() {
        l.ends.extend([c.from, c.to]);
        l.normal.push(c.normal_force);
        l.tangential.push(c.tangential_force);
        l.normal_magnitude.push(c.normal_force.norm());
        l.tangential_magnitude.push(c.tangential_force.norm());
        l.first.push(c.first as i64);
        let (second, wall) = match c.second {
            Partner::Sphere(b) => (b as i64, -1),
            Partner::Wall(w) => (-1, w as i64),
        };
        l.second.push(second);
        l.wall.push(wall);
        l.scale_first.push(c.scales.0);
        l.scale_second.push(c.scales.1);
    }
    let segments: Vec<[u32; 2]> = (0..l.first.len() as u32)
        .map(|k| [2 * k, 2 * k + 1])
        .collect();
    let mut cell_data = vec![
        (
            "normal_force_magnitude",
            VtuField::Scalars(&l.normal_magnitude),
        ),
        (
            "tangential_force_magnitude",
            VtuField::Scalars(&l.tangential_magnitude),
        ),
        ("normal_force", VtuField::Vectors(&l.normal)),
        ("tangential_force", VtuField::Vectors(&l.tangential)),
        ("first", VtuField::Integers(&l.first)),
        ("second", VtuField::Integers(&l.second)),
        ("wall", VtuField::Integers(&l.wall)),
    ];
    if contacts.time_delay_state().is_some() {
        cell_data.push(("scale_first", VtuField::Scalars(&l.scale_first)));
        cell_data.push(("scale_second", VtuField::Scalars(&l.scale_second)));
    }
    let mesh = VtuMesh {
        points: &l.ends,
        cells: VtuCells::Lines(&segments),
        point_data: Vec::new(),
        cell_data,
    };
    write_vtu_mesh_at(path, &mesh, Some(time))
}
