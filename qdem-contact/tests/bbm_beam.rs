//! The bonded beam of paper 001 §5 against Timoshenko beam theory and the elementary bending
//! stress: static deflection without breakage, and where and at what load the first bond
//! breaks.

mod bbm;

use bbm::{beam, cracking_load, timoshenko_deflection};
use qdem_core::{solvers::StaticSolver, step::Model, step::StepEvents};

/// Static midspan deflection of the bonded beam at three element sizes against Timoshenko's
/// (bending plus shear): the error shrinks with refinement and is within 2% at 0.01 m. The
/// lattice's E and ν are matched to the continuum exactly (`lattice_section`); what remains
/// is discretisation (the supports and load act on discrete rows).
#[test]
fn static_deflection_converges_to_timoshenko() {
    let q = 10e3;
    let mut errors = Vec::new();
    for h in [0.05, 0.025, 0.01] {
        let mut b = beam(h, q, f64::INFINITY, 0.0, false);
        StaticSolver::new()
            .solve(&mut b.state, &mut b.models, 0.0)
            .unwrap();
        let w = -b.midspan_deflection();
        let expected = timoshenko_deflection(q, b.span);
        let error = w / expected - 1.0;
        println!(
            "h = {h}: {} particles, span {:.4} m, w = {w:.6e} m, Timoshenko {expected:.6e} m, \
             error {:+.3}%",
            b.state.len(),
            b.span,
            100.0 * error
        );
        errors.push(error);
    }
    assert!(errors[2].abs() < 0.02, "finest error {:.4}", errors[2]);
    assert!(
        errors[2].abs() < errors[0].abs(),
        "no convergence: {errors:?}"
    );
}

/// With every strength at the mean, a static load 3% below the one at which the elementary
/// midspan bending stress reaches that strength breaks no bond; 3% above, bonds break, the
/// first (largest stress) at the bottom fibre within one spacing of midspan.
#[test]
fn first_crack_is_at_bottom_midspan_between_the_bracketing_loads() {
    let strength = 6e6;
    let h = 0.01;
    let probe = beam(h, 1.0, strength, 0.0, false);
    let q_crit = cracking_load(strength, probe.span);
    for (factor, breaks) in [(0.97, false), (1.03, true)] {
        let mut b = beam(h, factor * q_crit, strength, 0.0, false);
        StaticSolver::new()
            .solve(&mut b.state, &mut b.models, 0.0)
            .unwrap();
        let state = b.state.clone();
        let model = b.bonds_mut();
        model.check_step(&state, false);
        let (worst, stress) = model
            .trial_stresses()
            .iter()
            .enumerate()
            .max_by(|a, c| a.1.total_cmp(c.1))
            .map(|(k, s)| (k, *s))
            .unwrap();
        model.commit_step(&state);
        let broken = model.broken();
        let bond = model.bonds()[worst];
        let (xi, xj) = (
            b.packing.centers[bond.i as usize],
            b.packing.centers[bond.j as usize],
        );
        println!(
            "load {factor} × {q_crit:.1} N/m: largest bond stress {stress:.4e} Pa at \
             ({:.4}, {:.4})–({:.4}, {:.4}), {broken} bonds broken",
            xi[0], xi[1], xj[0], xj[1]
        );
        assert_eq!(broken > 0, breaks, "factor {factor}: {broken} broken");
        let bottom = b
            .packing
            .centers
            .iter()
            .map(|c| c[1])
            .fold(f64::MAX, f64::min);
        assert!((xi[1] - bottom).abs() < 1e-9 && (xj[1] - bottom).abs() < 1e-9);
        let centre = 0.5 * (xi[0] + xj[0]);
        assert!((centre - 1.5).abs() <= b.packing.spacing, "at x = {centre}");
    }
}

/// The bonded model's potential energy is ½ uᵀKu: at the static answer it equals half the
/// work of the load (Clapeyron), a check of the force–tangent consistency.
#[test]
fn clapeyron_holds_at_the_static_answer() {
    let q = 50e3;
    let mut b = beam(0.05, q, f64::INFINITY, 0.0, false);
    StaticSolver::new()
        .solve(&mut b.state, &mut b.models, 0.0)
        .unwrap();
    let energy = b.models[0].potential_energy(&b.state).unwrap();
    let work = b.load_work(q);
    assert!(
        (energy / (0.5 * work) - 1.0).abs() < 1e-9,
        "{energy} {work}"
    );
}

/// A bonded block under uniaxial tension has the continuum's E and ν (the λ, ϕ of
/// `lattice_section`), measured away from the loaded edges.
#[test]
fn lattice_has_the_continuum_modulus_and_poisson_ratio() {
    use qdem_contact::{BondedParticles, Packing, PackingKind};
    use qdem_core::{loads::NodalLoad, loads::TimeFunction, step::Dofs, Vec3};
    let (w, hgt) = (2.0, 0.5);
    let packing = Packing::rectangle([0.0, 0.0], [w, hgt], 0.025, PackingKind::Regular).unwrap();
    let (mut state, mut model) = BondedParticles::from_packing(
        "block",
        &packing,
        &bbm::material(f64::INFINITY, 0.0),
        bbm::settings(),
    )
    .unwrap();
    // Solved statically: the bonds' contacts push only when active, as in an implicit run.
    let request = qdem_core::step::StepRequest {
        scheme: qdem_core::step::Scheme::Static,
        dt: Some(1.0),
        safety: 0.5,
        local_damping: 0.0,
        adaptive: false,
        event_solve: Default::default(),
        implicit_default: None,
        fit_to: None,
    };
    model.prepare(&qdem_core::step::StepSettings::resolve(&request, &state, &[]).unwrap());
    let h = packing.spacing;
    let c = &packing.centers;
    let left: Vec<usize> = (0..c.len()).filter(|&p| c[p][0] < 0.51 * h).collect();
    let right: Vec<u32> = (0..c.len())
        .filter(|&p| c[p][0] > w - 0.51 * h)
        .map(|p| p as u32)
        .collect();
    for &p in &left {
        state.fix(p, Dofs::parse("x").unwrap());
    }
    state.fix(left[0], Dofs::parse("y").unwrap());
    let sigma = 1e6;
    let load = NodalLoad::new(
        "pull",
        right,
        Vec3::new(sigma * hgt, 0.0, 0.0),
        TimeFunction::constant(1.0),
    );
    let mut models: Vec<Box<dyn qdem_core::step::Model>> = vec![Box::new(model), Box::new(load)];
    StaticSolver::new()
        .solve(&mut state, &mut models, 0.0)
        .unwrap();
    // Strain from two sections at x = 0.5 and 1.5, lateral from the top and bottom rows there.
    let section = |x0: f64| -> Vec<usize> {
        (0..c.len())
            .filter(|&p| (c[p][0] - x0).abs() < 0.3 * h)
            .collect()
    };
    let mean = |ids: &[usize], axis: usize| {
        ids.iter()
            .map(|&p| state.displacement(p)[axis])
            .sum::<f64>()
            / ids.len() as f64
    };
    let (a, b) = (section(0.75), section(1.25));
    let exx = (mean(&b, 0) - mean(&a, 0)) / (c[b[0]][0] - c[a[0]][0]);
    let ys: Vec<f64> = b.iter().map(|&p| c[p][1]).collect();
    let (ymin, ymax) = (
        ys.iter().cloned().fold(f64::MAX, f64::min),
        ys.iter().cloned().fold(f64::MIN, f64::max),
    );
    let top: Vec<usize> = b.iter().copied().filter(|&p| c[p][1] == ymax).collect();
    let bottom: Vec<usize> = b.iter().copied().filter(|&p| c[p][1] == ymin).collect();
    let eyy = (mean(&top, 1) - mean(&bottom, 1)) / (ymax - ymin);
    let (e, nu) = (sigma / exx, -eyy / exx);
    println!("lattice E = {e:.4e} Pa, nu = {nu:.4}");
    assert!((e / 30e9 - 1.0).abs() < 0.02, "E = {e}");
    assert!((nu - 0.25).abs() < 0.01, "nu = {nu}");
}
