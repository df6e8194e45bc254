//! A fixed number of force evaluations of one body, for counting instructions with
//! `valgrind --tool=callgrind` (load-independent, unlike the wall clock of
//! `averaged_pressure_cost`): the difference of two counts over the difference of their
//! evaluations is the cost of one (docs/verification.md, averaged pressure, "Cost").
//!
//! `cargo build --release -p qdem-core --example averaged_pressure_instructions`, then
//! `valgrind --tool=callgrind target/release/examples/averaged_pressure_instructions
//! CELLS_X EVALUATIONS standard|averaged elastic|viscous` (one thread; the bar of
//! CELLS_X × 6 × 10 cells of 6 tetrahedra, 278 for 100,080).

use qdem_core::{
    continuum::Formulation, continuum::Material, continuum::TetBody, step::Model, step::State, Vec3,
};
use qdem_mesh::structured_box;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let cells: usize = args.first().and_then(|a| a.parse().ok()).unwrap_or(278);
    let evaluations: usize = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(2);
    let formulation = match args.get(2).map(String::as_str) {
        Some("averaged") => Formulation::AveragedPressure,
        _ => Formulation::Standard,
    };
    let viscous = args.get(3).map(String::as_str) == Some("viscous");
    rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build_global()
        .expect("one thread");
    let mesh = structured_box([0.0; 3], [1.0, 0.06, 0.1], [cells, 6, 10]).expect("a bar");
    let reference: Vec<Vec3> = mesh.nodes.iter().map(|p| Vec3::from(*p)).collect();
    let material = Material {
        shear_viscosity: if viscous { 50.0 } else { 0.0 },
        bulk_viscosity: if viscous { 30.0 } else { 0.0 },
        ..Material::elastic(1100.0, 5e6, 0.4999)
    };
    let mut body = TetBody::new("bar", &reference, mesh.tets.clone(), material)
        .expect("a body")
        .with_formulation(formulation);
    let mut state = State::at_rest(reference);
    for (i, (x, v)) in state
        .position
        .iter_mut()
        .zip(&mut state.velocity)
        .enumerate()
    {
        let t = i as f64;
        *x += Vec3::new(t.sin(), t.cos(), (2.0 * t).sin()) * 1e-5;
        *v = Vec3::new(t.cos(), t.sin(), 0.5) * 1e-3;
    }
    let mut force = vec![Vec3::zeros(); state.len()];
    for _ in 0..evaluations {
        force.fill(Vec3::zeros());
        body.add_forces(&state, &mut force, &mut []);
    }
    let sum: f64 = force.iter().map(|f| f.norm()).sum();
    println!(
        "{} tets, {evaluations} evaluations, sum |f| {sum:e}",
        mesh.tets.len()
    );
}
