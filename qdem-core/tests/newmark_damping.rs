//! Stiffness-proportional (Rayleigh) damping: with viscous Lamé parameters r times the elastic
//! ones the damping matrix is C = r K, so the first bending mode of a clamped beam decays at
//! σ = r ω₁²/2 (paper 000 §3.2, Fig. 4a). Measured on free vibrations released from the static
//! deflection, explicit and implicit (paper 001 Eqs. 13–16, 26), for ζ₁ ≈ 0.5%, 1%, 2%.

use qdem_core::{
    continuum::Material, continuum::TetBody, loads::NodalLoad, loads::TimeFunction,
    solvers::Newmark, solvers::StaticSolver, step::stepper::choose_step, step::Dofs, step::Model,
    step::State, step::Stepper, Vec3,
};
use qdem_mesh::structured_box;

const LENGTH: f64 = 2.4;
const CELLS: [usize; 3] = [12, 2, 2];
const LOAD: f64 = 200.0;

/// The elastic material; the damped one has viscous Lamé parameters r (λ_E, μ_E).
fn material(r: f64) -> Material {
    let mut m = Material::elastic(2350.0, 45e9, 0.167);
    let lame = m.elastic_lame();
    m.shear_viscosity = r * lame.mu;
    m.bulk_viscosity = r * (lame.lambda + 2.0 / 3.0 * lame.mu);
    m
}

/// A clamped coarse beam of material `r` at rest and its tip particles. Every particle is held
/// in y: the tetrahedra of a structured mesh couple vertical and lateral bending, whose
/// frequencies are close for this section, and the beating would hide the decay of one mode.
fn beam(r: f64) -> (State, TetBody, Vec<u32>) {
    let mesh = structured_box([0.0; 3], [LENGTH, 0.25, 0.22], CELLS).unwrap();
    let reference: Vec<Vec3> = mesh.nodes.iter().map(|p| Vec3::from(*p)).collect();
    let body = TetBody::new("beam", &reference, mesh.tets, material(r)).unwrap();
    let mut state = State::at_rest(reference);
    body.lump_mass(&mut state.mass);
    for i in 0..state.len() {
        let clamped = state.reference[i].x == 0.0;
        state.fix(
            i,
            if clamped {
                Dofs::ALL
            } else {
                Dofs::parse("y").unwrap()
            },
        );
    }
    let tip = (0..state.len() as u32)
        .filter(|&i| state.reference[i as usize].x == LENGTH)
        .collect();
    (state, body, tip)
}

/// Mean z-displacement of the tip particles (m).
fn tip_deflection(state: &State, tip: &[u32]) -> f64 {
    tip.iter()
        .map(|&i| state.displacement(i as usize).z)
        .sum::<f64>()
        / tip.len() as f64
}

/// The static deflection under the tip load (positions) and the Rayleigh quotient
/// P δ / Σ m u² of its shape, an estimate of ω₁² (1/s²).
fn static_shape() -> (Vec<Vec3>, f64) {
    let (mut state, body, tip) = beam(0.0);
    let load = NodalLoad::new(
        "tip",
        tip.clone(),
        Vec3::new(0.0, 0.0, -LOAD),
        TimeFunction::constant(1.0),
    );
    let mut models: Vec<Box<dyn Model>> = vec![Box::new(body), Box::new(load)];
    StaticSolver::new()
        .solve(&mut state, &mut models, 0.0)
        .unwrap();
    let work = -LOAD * tip_deflection(&state, &tip);
    let inertia: f64 = (0..state.len())
        .map(|i| state.mass[i] * state.displacement(i).norm_squared())
        .sum();
    (state.position, work / inertia)
}

/// The extrema (time, value) of a sampled signal, refined by a parabola through three samples.
fn extrema(dt: f64, x: &[f64]) -> Vec<(f64, f64)> {
    x.windows(3)
        .enumerate()
        .filter(|(_, w)| (w[1] - w[0]) * (w[2] - w[1]) < 0.0)
        .map(|(i, w)| {
            let curvature = w[0] - 2.0 * w[1] + w[2];
            let shift = 0.5 * (w[0] - w[2]) / curvature;
            let value = w[1] - 0.25 * (w[0] - w[2]) * shift;
            ((i as f64 + 1.0 + shift) * dt, value)
        })
        .collect()
}

/// Least-squares slope of y against x.
fn slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), p| (a + p.0 / n, b + p.1 / n));
    let (sxy, sxx) = points.iter().fold((0.0, 0.0), |(a, b), p| {
        (a + (p.0 - mx) * (p.1 - my), b + (p.0 - mx).powi(2))
    });
    sxy / sxx
}

/// Measured decay rate σ (1/s) and angular frequency ω₁ = √(ω_d² + σ²) (rad/s) of the tip
/// record, skipping the extrema of the first `skip` seconds (higher modes die out there).
fn decay_and_frequency(dt: f64, record: &[f64], skip: f64) -> (f64, f64) {
    let peaks: Vec<(f64, f64)> = extrema(dt, record)
        .into_iter()
        .filter(|p| p.0 > skip)
        .collect();
    let sigma = -slope(
        &peaks
            .iter()
            .map(|p| (p.0, p.1.abs().ln()))
            .collect::<Vec<_>>(),
    );
    let half_period = slope(
        &peaks
            .iter()
            .enumerate()
            .map(|(k, p)| (k as f64, p.0))
            .collect::<Vec<_>>(),
    );
    let omega_d = std::f64::consts::PI / half_period;
    (sigma, (omega_d * omega_d + sigma * sigma).sqrt())
}

/// Releases the damped beam (ζ₁ ≈ `zeta`) from the static deflection and returns the measured
/// decay rate, the analytical one r ω₁²/2 (ω₁ measured from the same record) and that ω₁.
fn measure(zeta: f64, implicit: bool) -> (f64, f64, f64) {
    let (deflected, omega_squared) = static_shape();
    let r = 2.0 * zeta / omega_squared.sqrt();
    let (mut state, body, tip) = beam(r);
    state.position = deflected;
    let mut models: Vec<Box<dyn Model>> = vec![Box::new(body)];
    let period = std::f64::consts::TAU / omega_squared.sqrt();
    let mut stepper = if implicit {
        Newmark::average_acceleration(period / 64.0)
    } else {
        Newmark::central_difference(choose_step(&state, &models, None, 0.9).unwrap())
    };
    let periods = 0.04 / zeta + 2.0;
    let steps = (periods * period / stepper.dt()) as usize;
    stepper.initialize(&mut state, &mut models).unwrap();
    let mut record = Vec::with_capacity(steps + 1);
    record.push(tip_deflection(&state, &tip));
    for _ in 0..steps {
        stepper.step(&mut state, &mut models).unwrap();
        record.push(tip_deflection(&state, &tip));
    }
    let (sigma, omega) = decay_and_frequency(stepper.dt(), &record, 2.0 * period);
    (sigma, 0.5 * r * omega * omega, omega)
}

fn check(implicit: bool) {
    for zeta in [0.005, 0.01, 0.02] {
        let start = std::time::Instant::now();
        let (measured, expected, omega) = measure(zeta, implicit);
        let error = (measured / expected - 1.0).abs();
        println!(
            "{}: ω₁ = {omega:.3} rad/s, ζ₁ = {:.5}: decay {measured:.5} 1/s, r ω₁²/2 = \
             {expected:.5} 1/s, relative {error:.2e} ({:.2} s)",
            if implicit { "implicit" } else { "explicit" },
            measured / omega,
            start.elapsed().as_secs_f64()
        );
        assert!(error < 0.02, "ζ₁ ≈ {zeta}: relative error {error:e}");
    }
}

#[test]
fn implicit_decay_rate_is_r_omega_squared_over_two() {
    check(true);
}

#[test]
fn explicit_decay_rate_is_r_omega_squared_over_two() {
    check(false);
}
