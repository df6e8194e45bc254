//! Kelvin–Voigt creep and recovery (paper 000 §3.2, Eq. 14) with the implicit Newmark stepper
//! (average acceleration, β = ¼, γ = ½) in the quasi-static regime of the paper
//! (E = 0.5 MPa, ρ = 2350 kg/m³, ν = 0, κ_D = 0).
//!
//! # The one-dimensional problem
//!
//! A 0.1 × 0.1 × 0.2 m bar along z (3 × 3 × 6 cells, 324 tetrahedra). Every particle is fixed in
//! x and y (uniaxial strain), the bottom face (z = 0) is fixed in z, and a uniform pressure σ
//! acts on the top face (z = L): the consistent nodal loads σ·A_a, A_a = Σ (area / 3) over the
//! top-face triangles that touch particle a, switched on as a step at t = 0 and off at t₀.
//!
//! With the displacement u_z = u(z, t) only, ε_zz = ε is the only strain and D_zz = ε̇ the only
//! strain rate, so the Kelvin–Voigt stress of paper 000 Eqs. 2, 7, 8 gives
//!
//!   σ_zz = (λ_E + 2μ_E) ε + (λ_D + 2μ_D) ε̇.
//!
//! With ν = 0, λ_E = 0 and 2μ_E = E, so λ_E + 2μ_E = E. With κ_D = λ_D + ⅔μ_D = 0,
//! λ_D = −⅔μ_D and λ_D + 2μ_D = κ_D + 4/3 μ_D = 4/3 μ_D. The bar is therefore a Kelvin–Voigt
//! element σ = E ε + η ε̇ with the **effective uniaxial viscosity η = 4/3 μ_D** (not μ_D), and
//! Eq. 14 holds with μ_D replaced by η:
//!
//!   ε(t) = (σ/E)(1 − e^{−tE/η})                        for 0 ≤ t ≤ t₀,
//!   ε(t) = (σ/E)(e^{−(t−t₀)E/η} − e^{−tE/η})
//!        = (σ/E) e^{−tE/η}(e^{t₀E/η} − 1)               for t ≥ t₀.
//!
//! (The recovery branch of Eq. 14 as printed, e^{−tE/μ_D}(e^{−t₀E/μ_D} − 1), is negative: the
//! sign of the exponent t₀E/μ_D is garbled; the form above is continuous at t₀ and decays to 0.)
//! The lateral stresses σ_xx = σ_yy = λ_E ε + λ_D ε̇ = −⅔μ_D ε̇ are carried by the x, y fixity.
//!
//! On this mesh the one-dimensional solution is exact without inertia: every tetrahedron spans
//! one z layer, so a displacement that is the same on every particle of a z level is linear in z
//! within each tetrahedron (uniform strain per layer); the z force of a layer on a particle of
//! the level z_k is then ∓σ_layer ∫N_a dA over the conforming triangulation of that plane, the
//! same tributary area A_a from the layers above and below, and so it balances for a uniform
//! stress, with the consistent top loads σ·A_a. Inertia (lumped masses, which are not
//! proportional to A_a at the edges) is the only departure, of relative order 1/(τω₁)².
//!
//! # The quasi-static regime
//!
//! μ_D = ¾ E τ with τ = η/E = 0.1 s; t₀ = 0.5 s; run to 1.0 s with ∆t = 1 ms (1000 implicit
//! steps). The first axial mode of the uniaxial-strain bar (P-wave modulus λ_E + 2μ_E = E) is
//! ω₁ = (π/2)√(E/ρ)/L ≈ 114.6 rad/s, so τω₁ ≈ 11.5 and the mode's damping ratio is
//! ζ₁ = τω₁/2 ≈ 5.7: heavily overdamped, with inertia corrections of order
//! 1/(τω₁)² ≈ 0.8 % of the plateau (measured: a largest error of 0.6 % of σ/E in the first
//! steps after the step load, 0.13 % RMS over the history).
//!
//! The test checks the static plateau σ/E with the static solver (the elastic half of the
//! derivation), then compares the implicit history with the η = 4/3 μ_D curve (RMS error within
//! 1 % of σ/E) and, as a control, with the curve for η = μ_D (which must miss by far more). It
//! also prints the explicit alternative: the stable explicit step of the same body
//! ([`Model::stable_dt`], viscosity included) and the number of explicit steps to 1.0 s.

use qdem_core::{
    continuum::Material, continuum::TetBody, loads::NodalLoad, loads::TimeFunction,
    solvers::Newmark, solvers::StaticSolver, step::Dofs, step::Model, step::State, step::Stepper,
    Vec3,
};
use qdem_mesh::structured_box;

/// Bar length along z (m).
const LENGTH: f64 = 0.2;
/// Cross-section side (m).
const SIDE: f64 = 0.1;
/// Young's modulus (Pa), the paper's quasi-static regime.
const YOUNG: f64 = 0.5e6;
/// Density (kg/m³).
const DENSITY: f64 = 2350.0;
/// Relaxation time τ = η/E (s).
const TAU: f64 = 0.1;
/// Shear viscosity μ_D = ¾ E τ (Pa s), so that η = 4/3 μ_D = E τ.
const SHEAR_VISCOSITY: f64 = 0.75 * YOUNG * TAU;
/// Unloading time t₀ (s).
const UNLOAD: f64 = 0.5;
/// End of the run (s).
const END: f64 = 1.0;
/// Implicit step (s).
const DT: f64 = 1e-3;
/// Applied compressive pressure σ (Pa): plateau strain σ/E = 1e-4.
const PRESSURE: f64 = 50.0;

/// The bar: state (masses lumped, x and y fixed everywhere, z fixed at the bottom), the body and
/// the consistent top loads scaled by `factor`, and the top particles.
fn bar(factor: TimeFunction) -> (State, Vec<Box<dyn Model>>, Vec<u32>) {
    let mesh = structured_box([0.0; 3], [SIDE, SIDE, LENGTH], [3, 3, 6]).unwrap();
    let reference: Vec<Vec3> = mesh.nodes.iter().map(|p| Vec3::from(*p)).collect();
    let material = Material {
        density: DENSITY,
        young: YOUNG,
        poisson: 0.0,
        shear_viscosity: SHEAR_VISCOSITY,
        bulk_viscosity: 0.0,
    };
    // Tributary areas of the top face: a third of every boundary triangle on z = L.
    let mut area = vec![0.0; reference.len()];
    for tet in &mesh.tets {
        for skip in 0..4 {
            let face: Vec<usize> = (0..4)
                .filter(|&c| c != skip)
                .map(|c| tet[c] as usize)
                .collect();
            if face.iter().all(|&n| reference[n].z == LENGTH) {
                let [a, b, c] = [face[0], face[1], face[2]].map(|n| reference[n]);
                let third = 0.5 * (b - a).cross(&(c - a)).norm() / 3.0;
                face.iter().for_each(|&n| area[n] += third);
            }
        }
    }
    let top: Vec<u32> = (0..reference.len() as u32)
        .filter(|&i| reference[i as usize].z == LENGTH)
        .collect();
    let total_area: f64 = top.iter().map(|&i| area[i as usize]).sum();
    assert!(
        (total_area / (SIDE * SIDE) - 1.0).abs() < 1e-12,
        "top area {total_area}"
    );

    let body = TetBody::new("bar", &reference, mesh.tets, material).unwrap();
    let mut state = State::at_rest(reference);
    body.lump_mass(&mut state.mass);
    for i in 0..state.len() {
        state.fix(i, Dofs::parse("xy").unwrap());
        if state.reference[i].z == 0.0 {
            state.fix(i, Dofs::ALL);
        }
    }
    let mut models: Vec<Box<dyn Model>> = vec![Box::new(body)];
    for &i in &top {
        let force = Vec3::new(0.0, 0.0, -PRESSURE * area[i as usize]);
        models.push(Box::new(NodalLoad::new(
            "top",
            vec![i],
            force,
            factor.clone(),
        )));
    }
    (state, models, top)
}

/// Compressive strain −ū_z/L from the mean top displacement, and the largest departure of a
/// top particle from the mean (m).
fn strain(state: &State, top: &[u32]) -> (f64, f64) {
    let u: Vec<f64> = top
        .iter()
        .map(|&i| state.displacement(i as usize).z)
        .collect();
    let mean = u.iter().sum::<f64>() / u.len() as f64;
    let spread = u.iter().map(|x| (x - mean).abs()).fold(0.0, f64::max);
    (-mean / LENGTH, spread)
}

/// Eq. 14 with relaxation time `tau` = η/E, in units of the plateau σ/E.
fn eq14(t: f64, tau: f64) -> f64 {
    if t <= UNLOAD {
        1.0 - (-t / tau).exp()
    } else {
        (-(t - UNLOAD) / tau).exp() - (-t / tau).exp()
    }
}

#[test]
fn static_plateau_is_sigma_over_e() {
    let (mut state, mut models, top) = bar(TimeFunction::constant(1.0));
    StaticSolver::new()
        .solve(&mut state, &mut models, 0.0)
        .unwrap();
    let (eps, spread) = strain(&state, &top);
    let plateau = PRESSURE / YOUNG;
    let error = (eps / plateau - 1.0).abs();
    eprintln!(
        "static strain {eps:.12e} vs σ/E = {plateau:.12e}: relative {error:.2e}; top spread \
         {:.2e} of the plateau",
        spread / LENGTH / plateau
    );
    assert!(error < 1e-9, "relative difference {error:e}");
    assert!(
        spread / LENGTH / plateau < 1e-9,
        "top not uniform: {spread:e} m"
    );
}

#[test]
fn implicit_newmark_follows_kelvin_voigt_creep_and_recovery() {
    let factor = TimeFunction::new(vec![(0.0, 1.0), (UNLOAD, 1.0), (UNLOAD, 0.0)]).unwrap();
    let (mut state, mut models, top) = bar(factor);
    let plateau = PRESSURE / YOUNG;
    let eta = 4.0 / 3.0 * SHEAR_VISCOSITY;
    let tau = eta / YOUNG;
    assert!((tau / TAU - 1.0).abs() < 1e-12);
    let omega1 = std::f64::consts::FRAC_PI_2 * (YOUNG / DENSITY).sqrt() / LENGTH;

    // The explicit alternative on the same body.
    let explicit_dt = models[0].stable_dt(&state).unwrap();
    let explicit_steps = (END / explicit_dt).ceil() as u64;

    let steps = (END / DT).round() as usize;
    let start = std::time::Instant::now();
    let mut stepper = Newmark::average_acceleration(DT);
    stepper.initialize(&mut state, &mut models).unwrap();
    let mut history = Vec::with_capacity(steps);
    let mut max_spread: f64 = 0.0;
    for _ in 0..steps {
        stepper.step(&mut state, &mut models).unwrap();
        let (eps, spread) = strain(&state, &top);
        max_spread = max_spread.max(spread / LENGTH);
        history.push((state.time, eps / plateau));
    }
    let wall = start.elapsed().as_secs_f64();

    // Errors in units of the plateau σ/E, against η = 4/3 μ_D and (control) η = μ_D.
    let errors = |tau: f64| {
        let (mut sum, mut max, mut at) = (0.0f64, 0.0f64, 0.0);
        for &(t, e) in &history {
            let d = (e - eq14(t, tau)).abs();
            sum += d * d;
            if d > max {
                (max, at) = (d, t);
            }
        }
        ((sum / history.len() as f64).sqrt(), max, at)
    };
    let (rms, max, at) = errors(tau);
    let (rms_mu, max_mu, _) = errors(SHEAR_VISCOSITY / YOUNG);
    let peak = history.iter().map(|h| h.1).fold(0.0, f64::max);
    let stats = stepper.report().factor.unwrap();

    eprintln!(
        "creep–recovery: E = {YOUNG:.1e} Pa, ρ = {DENSITY} kg/m³, μ_D = {SHEAR_VISCOSITY:.4e} Pa s, \
         η = 4/3 μ_D = {eta:.4e} Pa s, τ = η/E = {tau:.3} s; ω₁ = {omega1:.2} rad/s, \
         τω₁ = {:.2} (ζ₁ = {:.2}), 1/(τω₁)² = {:.2e}",
        tau * omega1,
        0.5 * tau * omega1,
        (tau * omega1).powi(-2)
    );
    eprintln!(
        "  vs η = 4/3 μ_D: RMS error {rms:.3e}, max {max:.3e} (at t = {at:.3} s) of σ/E; \
         peak strain {peak:.6} σ/E (Eq. 14: {:.6}); top spread ≤ {:.2e} of σ/E",
        eq14(UNLOAD, tau),
        max_spread / plateau
    );
    eprintln!("  control vs η = μ_D: RMS error {rms_mu:.3e}, max {max_mu:.3e} of σ/E");
    eprintln!(
        "  implicit: {steps} steps of {DT:e} s in {wall:.3} s ({} DOFs, factor {} values); \
         explicit: stable step {explicit_dt:.4e} s (viscosity included), {explicit_steps} steps \
         to {END} s ({:.0}× as many)",
        stats.dofs,
        stats.factor_nonzeros,
        explicit_steps as f64 / steps as f64
    );

    assert!(rms < 0.01, "RMS error {rms:e} of the plateau");
    assert!(max < 0.02, "max error {max:e} of the plateau at t = {at} s");
    assert!(
        rms_mu > 10.0 * rms,
        "η = μ_D fits too: {rms_mu:e} vs {rms:e}"
    );
}
