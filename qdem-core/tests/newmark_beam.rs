//! Clamped beam under a tip load: the static solve equals the independent linear-tet oracle,
//! an implicit Newmark run settles at the static answer, and explicit central-difference
//! Newmark is the Verlet scheme (paper 001 Eqs. 13–16, 26; paper 000 §3.1).

use qdem_core::continuum::linear_tet::LinearTets;
use qdem_core::{
    continuum::Material, continuum::TetBody, loads::NodalLoad, loads::TimeFunction,
    solvers::Newmark, solvers::StaticSolver, solvers::Verlet, step::stepper::choose_step,
    step::Dofs, step::Model, step::State, step::Stepper, Vec3,
};
use qdem_mesh::structured_box;

const LENGTH: f64 = 2.4;
const LOAD: f64 = 200.0;

/// A clamped 2.4 × 0.25 × 0.22 m concrete beam (24×3×3 cells) with its tip load ramped by
/// `ramp`, as a state, the models and the tip particles.
fn beam(ramp: TimeFunction) -> (State, Vec<Box<dyn Model>>, Vec<u32>) {
    let mesh = structured_box([0.0; 3], [LENGTH, 0.25, 0.22], [24, 3, 3]).unwrap();
    let reference: Vec<Vec3> = mesh.nodes.iter().map(|p| Vec3::from(*p)).collect();
    let material = Material::elastic(2350.0, 45e9, 0.167);
    let body = TetBody::new("beam", &reference, mesh.tets, material).unwrap();
    let mut state = State::at_rest(reference);
    body.lump_mass(&mut state.mass);
    let tip: Vec<u32> = (0..state.len() as u32)
        .filter(|&i| state.reference[i as usize].x == LENGTH)
        .collect();
    for i in 0..state.len() {
        if state.reference[i].x == 0.0 {
            state.fix(i, Dofs::ALL);
        }
    }
    let load = NodalLoad::new("tip", tip.clone(), Vec3::new(0.0, 0.0, -LOAD), ramp);
    (state, vec![Box::new(body), Box::new(load)], tip)
}

/// Mean z-displacement of the tip particles (m).
fn tip_deflection(state: &State, tip: &[u32]) -> f64 {
    tip.iter()
        .map(|&i| state.displacement(i as usize).z)
        .sum::<f64>()
        / tip.len() as f64
}

/// The static tip deflection from [`StaticSolver`], and the solver.
fn static_deflection() -> (f64, StaticSolver) {
    let (mut state, mut models, tip) = beam(TimeFunction::constant(1.0));
    let mut solver = StaticSolver::new();
    solver.solve(&mut state, &mut models, 0.0).unwrap();
    (tip_deflection(&state, &tip), solver)
}

/// First bending angular frequency estimate (rad/s): the Rayleigh quotient of the static
/// deflection shape, P δ / Σ m u².
fn rayleigh_omega() -> f64 {
    let (mut state, mut models, tip) = beam(TimeFunction::constant(1.0));
    StaticSolver::new()
        .solve(&mut state, &mut models, 0.0)
        .unwrap();
    let work = -LOAD * tip_deflection(&state, &tip);
    let inertia: f64 = (0..state.len())
        .map(|i| state.mass[i] * state.displacement(i).norm_squared())
        .sum();
    (work / inertia).sqrt()
}

/// Runs `stepper` under a load ramped over `ramp_periods` first-mode periods and held for
/// `hold_periods`; returns the mean tip deflection over the hold window.
fn settle(mut stepper: impl Stepper, period: f64, ramp_periods: f64, hold_periods: f64) -> f64 {
    let ramp_end = ramp_periods * period;
    let ramp = TimeFunction::new(vec![(0.0, 0.0), (ramp_end, 1.0)]).unwrap();
    let (mut state, mut models, tip) = beam(ramp);
    stepper.initialize(&mut state, &mut models).unwrap();
    let hold_steps = (hold_periods * period / stepper.dt()).round() as usize;
    while state.time < ramp_end {
        stepper.step(&mut state, &mut models).unwrap();
    }
    let mut sum = 0.0;
    for _ in 0..hold_steps {
        stepper.step(&mut state, &mut models).unwrap();
        sum += tip_deflection(&state, &tip);
    }
    sum / hold_steps as f64
}

#[test]
fn static_solve_equals_the_linear_tet_oracle() {
    let (deflection, solver) = static_deflection();
    let (state, _, tip) = beam(TimeFunction::constant(1.0));
    let material = Material::elastic(2350.0, 45e9, 0.167);
    let tets = structured_box([0.0; 3], [LENGTH, 0.25, 0.22], [24, 3, 3])
        .unwrap()
        .tets;
    let oracle = LinearTets::new(&state.reference, &tets, material.elastic_lame());
    let mut f = vec![Vec3::zeros(); state.len()];
    for &i in &tip {
        f[i as usize].z = -LOAD / tip.len() as f64;
    }
    let solution = oracle.solve(&f, &state.fixed, 1e-14);
    let expected = tip
        .iter()
        .map(|&i| solution.displacement[i as usize].z)
        .sum::<f64>()
        / tip.len() as f64;
    let error = (deflection / expected - 1.0).abs();
    let stats = solver.factor_stats().unwrap();
    println!(
        "static tip deflection {deflection:.12e} m, oracle {expected:.12e} m (CG {} iterations), \
         relative difference {error:.2e}; K: {} DOFs, {} non-zeros, factor {} values, \
         symbolic {:.2e} s, numeric {:.2e} s",
        solution.iterations,
        stats.dofs,
        stats.nonzeros,
        stats.factor_nonzeros,
        stats.symbolic_seconds,
        stats.numeric_seconds
    );
    assert!(error < 1e-8, "relative difference {error:e}");
}

#[test]
fn implicit_newmark_settles_at_the_static_deflection() {
    let (reference, _) = static_deflection();
    let omega = rayleigh_omega();
    let period = std::f64::consts::TAU / omega;
    let start = std::time::Instant::now();
    let stepper = Newmark::average_acceleration(period / 40.0);
    let mean = settle(stepper, period, 20.0, 10.0);
    let error = (mean / reference - 1.0).abs();
    println!(
        "ω₁ ≈ {omega:.2} rad/s (T₁ = {period:.4e} s); implicit mean {mean:.9e} m vs static \
         {reference:.9e} m: relative {error:.2e} ({:.2} s)",
        start.elapsed().as_secs_f64()
    );
    assert!(error < 5e-4, "relative difference {error:e}");
}

#[test]
fn central_difference_newmark_is_verlet_and_settles_at_the_static_deflection() {
    let (reference, _) = static_deflection();
    let period = std::f64::consts::TAU / rayleigh_omega();
    let (state, models, _) = beam(TimeFunction::constant(1.0));
    let dt = choose_step(&state, &models, None, 0.9).unwrap();
    let start = std::time::Instant::now();
    let newmark = settle(Newmark::central_difference(dt), period, 6.0, 4.0);
    let newmark_seconds = start.elapsed().as_secs_f64();
    let verlet = settle(Verlet::new(dt), period, 6.0, 4.0);
    let same = (newmark / verlet - 1.0).abs();
    let error = (newmark / reference - 1.0).abs();
    println!(
        "explicit dt {dt:.3e} s: Newmark mean {newmark:.12e} m, Verlet {verlet:.12e} m \
         (relative {same:.2e}); vs static {error:.2e} ({newmark_seconds:.2} s per run)"
    );
    assert!(same < 1e-9, "Newmark and Verlet differ by {same:e}");
    assert!(error < 5e-4, "relative difference {error:e}");
}
