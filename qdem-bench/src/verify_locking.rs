//! `qdem verify` rows of volumetric locking (issue 43): Lamé's thick-walled cylinder in plane
//! strain (a = 0.1 m, b = 0.2 m, 1 MPa inside, a quarter of 8 × 16 cells one cell thick,
//! u_z = 0) at ν = 0.3, 0.49 and 0.4999, the averaged-pressure tetrahedron (Bonet & Burton
//! 1998) against Lamé's bore displacement (tolerance 2%) with the standard kernel beside it
//! (informational: it locks, 26% short at ν = 0.4999). The full study is the
//! `locking_study` example of qdem-core (docs/verification.md).

use crate::verify::Row;
use qdem_core::{
    Dofs, Formulation, Material, Model, NodalLoad, State, StaticSolver, TetBody, TimeFunction, Vec3,
};
use qdem_mesh::{structured_box, TetMesh};
use std::f64::consts::FRAC_PI_2;
use std::time::Instant;

const YOUNG: f64 = 70e9;

/// A body of `mesh` in `formulation`, with the state at rest and lumped masses.
fn body(mesh: &TetMesh, poisson: f64, formulation: Formulation) -> (State, TetBody) {
    let reference: Vec<Vec3> = mesh.nodes.iter().map(|p| Vec3::from(*p)).collect();
    let material = Material::elastic(2700.0, YOUNG, poisson);
    let body = TetBody::new("body", &reference, mesh.tets.clone(), material)
        .unwrap()
        .with_formulation(formulation);
    let mut state = State::at_rest(reference);
    body.lump_mass(&mut state.mass);
    (state, body)
}

/// A quarter of a thick-walled cylinder (radii `A`, `B`), one cell thick: the structured box
/// (r, θ, z) mapped to (r cos θ, r sin θ, z), which keeps every tetrahedron's orientation.
const A: f64 = 0.1;
const B: f64 = 0.2;
const PRESSURE: f64 = 1e6;

fn quarter_ring(radial: usize, around: usize) -> TetMesh {
    let mut mesh = structured_box([A, 0.0, 0.0], [B, FRAC_PI_2, 0.01], [radial, around, 1]);
    for p in &mut mesh.nodes {
        let (r, t) = (p[0], p[1]);
        *p = [r * t.cos(), r * t.sin(), p[2]];
    }
    mesh
}

/// Lamé's radial displacement at the bore of the cylinder in plane strain (m).
fn lame_bore(poisson: f64) -> f64 {
    let (a2, b2) = (A * A, B * B);
    (1.0 + poisson) * PRESSURE * a2 / (YOUNG * (b2 - a2)) * ((1.0 - 2.0 * poisson) * A + b2 / A)
}

/// The mean radial displacement of the bore of the quarter ring in plane strain (uz = 0
/// everywhere, symmetry on the cut planes) under the internal pressure, and Lamé's.
fn ring_bore(poisson: f64, formulation: Formulation, cells: (usize, usize)) -> (f64, f64) {
    let mesh = quarter_ring(cells.0, cells.1);
    let (mut state, body) = body(&mesh, poisson, formulation);
    let group = |name: &str| mesh.group(name).unwrap().nodes.clone();
    for n in 0..state.len() {
        state.fix(n, Dofs::parse("z").unwrap());
    }
    for n in group("ymin") {
        state.fix(n as usize, Dofs::parse("y").unwrap());
    }
    for n in group("ymax") {
        state.fix(n as usize, Dofs::parse("x").unwrap());
    }
    // Consistent nodal forces of the pressure on the bore's triangles: p A / 3 per corner,
    // along the face's normal into the wall.
    let bore = group("xmin");
    let on_bore = |n: &u32| bore.contains(n);
    let mut force = vec![Vec3::zeros(); state.len()];
    for tet in &mesh.tets {
        for skip in 0..4 {
            let face: Vec<u32> = (0..4).filter(|&k| k != skip).map(|k| tet[k]).collect();
            if !face.iter().all(on_bore) {
                continue;
            }
            let x = |n: u32| state.reference[n as usize];
            let mut area = (x(face[1]) - x(face[0])).cross(&(x(face[2]) - x(face[0]))) * 0.5;
            if area.dot(&(x(tet[skip]) - x(face[0]))) < 0.0 {
                area = -area; // now pointing into the wall
            }
            for &n in &face {
                force[n as usize] += area * (PRESSURE / 3.0);
            }
        }
    }
    let mut models: Vec<Box<dyn Model>> = vec![Box::new(body)];
    for &n in &bore {
        let f = force[n as usize];
        models.push(Box::new(NodalLoad::new(
            "p",
            vec![n],
            f,
            TimeFunction::constant(1.0),
        )));
    }
    StaticSolver::new()
        .solve(&mut state, &mut models, 0.0)
        .unwrap();
    let radial: f64 = bore
        .iter()
        .map(|&n| {
            let (x, u) = (state.reference[n as usize], state.displacement(n as usize));
            u.dot(&x) / x.norm()
        })
        .sum();
    (radial / bore.len() as f64, lame_bore(poisson))
}

/// The rows: per ν, the standard kernel (informational) and the averaged-pressure one (2%).
pub fn lame_rows() -> Vec<Row> {
    let mut rows = Vec::new();
    for poisson in [0.3, 0.49, 0.4999] {
        for (formulation, tolerance) in [
            (Formulation::Standard, None),
            (Formulation::AveragedPressure, Some(0.02)),
        ] {
            let start = Instant::now();
            let (computed, exact) = ring_bore(poisson, formulation, (8, 16));
            rows.push(Row::relative(
                &format!(
                    "Lame cylinder, plane strain, nu = {poisson}, {}: bore u_r (m)",
                    formulation.name()
                ),
                exact,
                computed,
                tolerance,
                start.elapsed().as_secs_f64(),
            ));
        }
    }
    rows
}
