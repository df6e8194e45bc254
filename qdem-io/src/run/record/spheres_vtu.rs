//! `vtu/spheres_NNNNN.vtu`: the contact spheres as points, one `VTK_VERTEX` each, with
//! `radius` (m), `velocity` (m/s), `body` (the body's index in scene order) and
//! `contact_force` (N, what the contact model applied at the step), and `spin` (rad/s, zero
//! for spheres that do not turn) when some sphere turns: ParaView's Glyph filter draws them
//! as spheres scaled by `radius`.

use crate::output::{write_vtu_mesh_at, OutputError, VtuCells, VtuField, VtuMesh};
use qdem_contact::DemContacts;
use qdem_core::{step::State, Vec3};
use std::path::Path;

/// Writes the spheres of `contacts` at `state` to `path`.
pub(crate) fn write_spheres(
    contacts: &DemContacts,
    state: &State,
    path: &Path,
) -> Result<(), OutputError> {
    let n = contacts.spheres();
    let (mut center, mut velocity, mut spin, mut force) = (
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
    );
    let (mut radius, mut body) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let mut turns = false;
    for s in contacts.sphere_records(state) {
        center.push(s.center);
        velocity.push(s.velocity);
        turns |= s.spin.is_some();
        spin.push(s.spin.unwrap_or_else(Vec3::zeros));
        force.push(s.force);
        radius.push(s.radius);
        body.push(s.body as i64);
    }
    let mut point_data = vec![
        ("radius", VtuField::Scalars(&radius)),
        ("velocity", VtuField::Vectors(&velocity)),
        ("body", VtuField::Integers(&body)),
        ("contact_force", VtuField::Vectors(&force)),
    ];
    if turns {
        point_data.push(("spin", VtuField::Vectors(&spin)));
    }
    let mesh = VtuMesh {
        points: &center,
        cells: VtuCells::Vertices,
        point_data,
        cell_data: Vec::new(),
    };
    write_vtu_mesh_at(path, &mesh, Some(state.time))
}
