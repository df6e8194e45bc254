//! Cost per tet-step of the averaged-pressure tetrahedron against the standard kernel
//! (issue 43): the force evaluation of one body, alternated A B A B in one process so that
//! only the ratio counts on a shared machine; one JSON object per line, then the median ratio.
//!
//! `cargo run --release -p qdem-core --example averaged_pressure_cost [-- CELLS_X [THREADS]]`

use qdem_core::{
    continuum::Formulation, continuum::Material, continuum::TetBody, step::Model, step::State, Vec3,
};
use qdem_mesh::structured_box;
use std::time::Instant;

/// Seconds per force evaluation of `body` at `state`, over `steps` evaluations.
fn seconds_per_step(body: &mut TetBody, state: &State, force: &mut [Vec3], steps: usize) -> f64 {
    let start = Instant::now();
    for _ in 0..steps {
        force.fill(Vec3::zeros());
        body.add_forces(state, force, &mut []);
    }
    start.elapsed().as_secs_f64() / steps as f64
}

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let cells = args.first().copied().unwrap_or(200);
    let threads = args.get(1).copied().unwrap_or(1);
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build_global()
        .unwrap();
    let mesh = structured_box([0.0; 3], [1.0, 0.06, 0.1], [cells, 6, 10]).unwrap();
    let reference: Vec<Vec3> = mesh.nodes.iter().map(|p| Vec3::from(*p)).collect();
    let tets = mesh.tets.len();
    for viscous in [false, true] {
        let material = Material {
            shear_viscosity: if viscous { 50.0 } else { 0.0 },
            bulk_viscosity: if viscous { 30.0 } else { 0.0 },
            ..Material::elastic(1100.0, 5e6, 0.4999)
        };
        let make = |f| {
            TetBody::new("bar", &reference, mesh.tets.clone(), material.clone())
                .unwrap()
                .with_formulation(f)
        };
        let (mut standard, mut averaged) = (
            make(Formulation::Standard),
            make(Formulation::AveragedPressure),
        );
        let mut state = State::at_rest(reference.clone());
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
        let steps = (2_000_000 / tets).max(5);
        seconds_per_step(&mut standard, &state, &mut force, steps);
        seconds_per_step(&mut averaged, &state, &mut force, steps);
        let mut ratios = Vec::new();
        for round in 0..4 {
            let a = seconds_per_step(&mut standard, &state, &mut force, steps);
            let b = seconds_per_step(&mut averaged, &state, &mut force, steps);
            ratios.push(b / a);
            println!(
                "{{\"viscous\": {viscous}, \"round\": {round}, \"tets\": {tets}, \"threads\": {threads}, \"standard_ns_per_tet_step\": {:.2}, \"averaged_ns_per_tet_step\": {:.2}, \"ratio\": {:.3}}}",
                a * 1e9 / tets as f64,
                b * 1e9 / tets as f64,
                b / a
            );
        }
        ratios.sort_by(f64::total_cmp);
        println!(
            "{{\"viscous\": {viscous}, \"median_ratio\": {:.3}}}",
            0.5 * (ratios[1] + ratios[2])
        );
    }
}
