//! The volumetric-locking cases of issue 43, shared by `qdem verify` ([`crate::verify_locking`]),
//! the `locking_study` example and the tests: Lamé's thick-walled cylinder in plane strain (a
//! quarter ring, u_z = 0, 1 MPa inside) and the clamped bar (1.0 × 0.06 × 0.10 m, 500 N at the
//! tip) against Timoshenko beam theory, each solved statically with either tetrahedron
//! formulation (the standard QDEM kernel or the averaged-pressure one of Bonet & Burton 1998).
//!
//! ```
//! use qdem_bench::locking_cases::ring_bore;
//! use qdem_core::continuum::Formulation;
//! let (computed, lame) = ring_bore(0.3, Formulation::AveragedPressure, (4, 8));
//! assert!((computed / lame - 1.0).abs() < 0.05);
//! ```

use qdem_core::{
    continuum::Formulation, continuum::Material, continuum::TetBody, loads::NodalLoad,
    loads::TimeFunction, solvers::StaticSolver, step::Dofs, step::Model, step::State, Vec3,
};
use qdem_mesh::{structured_box, TetMesh};
use std::f64::consts::FRAC_PI_2;

/// Young's modulus of every case (aluminium), Pa.
pub const YOUNG: f64 = 70e9;

/// A body of `mesh` in `formulation`, with the state at rest and lumped masses.
pub fn body(mesh: &TetMesh, poisson: f64, formulation: Formulation) -> (State, TetBody) {
    let reference: Vec<Vec3> = mesh.nodes.iter().map(|p| Vec3::from(*p)).collect();
    let material = Material::elastic(2700.0, YOUNG, poisson);
    let body = TetBody::new("body", &reference, mesh.tets.clone(), material)
        .unwrap()
        .with_formulation(formulation);
    let mut state = State::at_rest(reference);
    body.lump_mass(&mut state.mass);
    (state, body)
}

/// The cylinder's inner radius (m).
pub const A: f64 = 0.1;
/// The cylinder's outer radius (m).
pub const B: f64 = 0.2;
/// The internal pressure (Pa).
pub const PRESSURE: f64 = 1e6;

/// A quarter of a thick-walled cylinder (radii `A`, `B`), one cell thick: the structured box
/// (r, θ, z) mapped to (r cos θ, r sin θ, z), which keeps every tetrahedron's orientation.
pub fn quarter_ring(radial: usize, around: usize) -> TetMesh {
    irregular_ring(radial, around, 1, 0.0)
}

/// The quarter ring of `layers` cells in z whose interior nodes (off the bore, the outer
/// surface and the cut planes) are moved in r and θ by up to ±`jitter`/2 of a cell, by a fixed
/// pseudo-random sequence: an irregular mesh, on which linear tetrahedra lock harder.
pub fn irregular_ring(radial: usize, around: usize, layers: usize, jitter: f64) -> TetMesh {
    let mut mesh = structured_box(
        [A, 0.0, 0.0],
        [B, FRAC_PI_2, 0.01],
        [radial, around, layers],
    )
    .expect("a valid box");
    let (dr, dt) = ((B - A) / radial as f64, FRAC_PI_2 / around as f64);
    let mut seed: u64 = 0x2545_F491_4F6C_DD1D;
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    for p in &mut mesh.nodes {
        let (mut r, mut t) = (p[0], p[1]);
        let (u, v) = (next(), next());
        if r > A && r < B && t > 0.0 && t < FRAC_PI_2 {
            r += jitter * dr * u;
            t += jitter * dt * v;
        }
        *p = [r * t.cos(), r * t.sin(), p[2]];
    }
    mesh
}

/// Lamé's radial displacement at the bore of the cylinder in plane strain (m).
pub fn lame_bore(poisson: f64) -> f64 {
    let (a2, b2) = (A * A, B * B);
    (1.0 + poisson) * PRESSURE * a2 / (YOUNG * (b2 - a2)) * ((1.0 - 2.0 * poisson) * A + b2 / A)
}

/// The mean radial displacement of the bore of the quarter ring in plane strain (uz = 0
/// everywhere, symmetry on the cut planes) under the internal pressure, and Lamé's.
pub fn ring_bore(poisson: f64, formulation: Formulation, cells: (usize, usize)) -> (f64, f64) {
    let mesh = quarter_ring(cells.0, cells.1);
    (
        ring_bore_on(&mesh, poisson, formulation),
        lame_bore(poisson),
    )
}

/// The mean radial displacement of the bore of a quarter ring `mesh` (see [`ring_bore`]).
pub fn ring_bore_on(mesh: &TetMesh, poisson: f64, formulation: Formulation) -> f64 {
    let (mut state, body) = body(mesh, poisson, formulation);
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
    radial / bore.len() as f64
}

/// The issue's clamped bar, 1.0 × 0.06 × 0.10 m, 500 N down at the tip.
pub const LOAD: f64 = 500.0;

/// The mean tip deflection of the clamped bar (m, downward positive) and Timoshenko's.
pub fn bar_tip(poisson: f64, formulation: Formulation, cells: [usize; 3]) -> (f64, f64) {
    let (length, width, height) = (1.0, 0.06, 0.10);
    let mesh = structured_box([0.0; 3], [length, width, height], cells).expect("a valid box");
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
