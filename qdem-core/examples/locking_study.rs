//! Volumetric locking study (issue 43): the standard QDEM tetrahedron and the
//! averaged-pressure one (Bonet & Burton 1998) against Lamé's thick-walled cylinder in plane
//! strain and a clamped bar against Timoshenko beam theory, over Poisson's ratios and mesh
//! refinements; one JSON object per line, the table of docs/verification.md.
//!
//! `cargo run --release -p qdem-core --example locking_study`

use qdem_core::{
    Dofs, Formulation, Material, Model, NodalLoad, State, StaticSolver, TetBody, TimeFunction, Vec3,
};
use qdem_mesh::{structured_box, TetMesh};
use std::f64::consts::FRAC_PI_2;

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

/// The clamped bar, 1.0 × 0.06 × 0.10 m, 500 N down at the tip.
const LOAD: f64 = 500.0;

/// The mean tip deflection of the clamped bar (m, downward positive) and Timoshenko's.
fn bar_tip(poisson: f64, formulation: Formulation, cells: [usize; 3]) -> (f64, f64) {
    let (length, width, height) = (1.0, 0.06, 0.10);
    let mesh = structured_box([0.0; 3], [length, width, height], cells);
    let (mut state, body) = body(&mesh, poisson, formulation);
    for &n in &mesh.group("xmin").unwrap().nodes {
        state.fix(n as usize, Dofs::ALL);
    }
    let tip = mesh.group("xmax").unwrap().nodes.clone();
    let down = Vec3::new(0.0, 0.0, -LOAD);
    let load = NodalLoad::new("tip", tip.clone(), down, TimeFunction::constant(1.0));
    let mut models: Vec<Box<dyn Model>> = vec![Box::new(body), Box::new(load)];
    StaticSolver::new()
        .solve(&mut state, &mut models, 0.0)
        .unwrap();
    let deflection = -tip
        .iter()
        .map(|&n| state.displacement(n as usize).z)
        .sum::<f64>()
        / tip.len() as f64;
    let inertia = width * height.powi(3) / 12.0;
    let shear = YOUNG / (2.0 * (1.0 + poisson));
    // Cowper's shear coefficient of a rectangle.
    let k = 10.0 * (1.0 + poisson) / (12.0 + 11.0 * poisson);
    let timoshenko = LOAD * length.powi(3) / (3.0 * YOUNG * inertia)
        + LOAD * length / (k * shear * width * height);
    (deflection, timoshenko)
}

fn main() {
    for poisson in [0.3, 0.49, 0.4999] {
        for cells in [(4, 8), (6, 12), (8, 16), (12, 24)] {
            let (standard, exact) = ring_bore(poisson, Formulation::Standard, cells);
            let (averaged, _) = ring_bore(poisson, Formulation::AveragedPressure, cells);
            println!(
                "{{\"case\": \"lame\", \"poisson\": {poisson}, \"cells\": [{}, {}], \"tets\": {}, \"exact_m\": {exact:.6e}, \"standard_ratio\": {:.4}, \"averaged_ratio\": {:.4}}}",
                cells.0, cells.1, 6 * cells.0 * cells.1, standard / exact, averaged / exact
            );
        }
    }
    for poisson in [0.33, 0.45, 0.49, 0.499, 0.4999] {
        for cells in [[20, 2, 3], [40, 3, 5], [80, 5, 8], [120, 7, 12]] {
            let (standard, beam) = bar_tip(poisson, Formulation::Standard, cells);
            let (averaged, _) = bar_tip(poisson, Formulation::AveragedPressure, cells);
            println!(
                "{{\"case\": \"bar\", \"poisson\": {poisson}, \"cells\": {cells:?}, \"tets\": {}, \"timoshenko_m\": {beam:.6e}, \"standard_ratio\": {:.4}, \"averaged_ratio\": {:.4}}}",
                6 * cells[0] * cells[1] * cells[2], standard / beam, averaged / beam
            );
        }
    }
}
