//! The averaged-pressure tetrahedron (Bonet & Burton 1998): its forces against its tangent and
//! the standard kernel's under homogeneous strain, its determinism over threads and over
//! ranks. Its accuracy where the standard tetrahedron locks (Lamé's
//! cylinder, the clamped bar) is tested in qdem-bench (`tests/locking.rs`).

use qdem_core::{
    continuum::Formulation, continuum::Material, continuum::TetBody, loads::NodalLoad,
    loads::TimeFunction, solvers::Verlet, step::Dofs, step::Model, step::State, step::Stepper,
    Vec3,
};
use qdem_mesh::{structured_box, TetMesh};

/// An aluminium-like body of `mesh` in `formulation`, at rest, with lumped masses.
fn body(mesh: &TetMesh, poisson: f64, formulation: Formulation) -> (State, TetBody) {
    let reference: Vec<Vec3> = mesh.nodes.iter().map(|p| Vec3::from(*p)).collect();
    let tets = mesh.tets.clone();
    let material = Material::elastic(2700.0, 70e9, poisson);
    let body = TetBody::new("body", &reference, tets, material).unwrap();
    let body = body.with_formulation(formulation);
    let mut state = State::at_rest(reference);
    body.lump_mass(&mut state.mass);
    (state, body)
}

/// A small irregular body: the forces of a small displacement equal −K u from the tangent,
/// and a homogeneous deformation gives the standard kernel's forces.
#[test]
fn forces_match_the_tangent_and_the_standard_kernel_under_homogeneous_strain() {
    let mesh = structured_box([0.0; 3], [1.0, 0.7, 0.5], [3, 3, 2]).unwrap();
    let (mut state, averaged) = body(&mesh, 0.49, Formulation::AveragedPressure);
    let (_, standard) = body(&mesh, 0.49, Formulation::Standard);
    let forces = |model: &mut TetBody, state: &State| {
        let mut f = vec![Vec3::zeros(); state.len()];
        model.add_forces(state, &mut f, &mut []);
        f
    };
    // Homogeneous: x → G x.
    let g = qdem_core::Mat3::new(1.001, 2e-4, 0.0, -1e-4, 0.9995, 3e-4, 1e-4, 0.0, 1.002);
    for (x, r) in state.position.iter_mut().zip(&state.reference) {
        *x = g * r;
    }
    let (mut a, mut s) = (averaged.clone(), standard.clone());
    let (fa, fs) = (forces(&mut a, &state), forces(&mut s, &state));
    let scale = fs.iter().map(|f| f.norm()).fold(0.0, f64::max);
    for (x, y) in fa.iter().zip(&fs) {
        assert!((x - y).norm() < 1e-9 * scale, "{x} vs {y}");
    }
    // A small irregular displacement against −K u.
    let u = displace_irregularly(&mut state);
    let f = forces(&mut a, &state);
    let ku = tangent_times(&averaged, &state.reference, &u);
    let scale = ku.iter().map(|f| f.norm()).fold(0.0, f64::max);
    for (f, k) in f.iter().zip(&ku) {
        // Second order in u: the Green strain's quadratic term, ~|∇u| ≈ 1e-6 relative.
        assert!((f + k).norm() < 1e-4 * scale, "{f} vs {}", -k);
    }
}

/// A viscoelastic bar stepped by Verlet with 1 and 3 threads: bit-identical.
#[test]
fn explicit_steps_are_bit_identical_for_any_thread_count() {
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let (mut state, mut models) = loaded_bar(true);
            let dt = 0.5 * models[0].stable_dt(&state).unwrap();
            let mut verlet = Verlet::new(dt);
            verlet.initialize(&mut state, &mut models).unwrap();
            for _ in 0..40 {
                verlet.step(&mut state, &mut models).unwrap();
            }
            let bits = motion_bits(&state);
            (bits, state.displacement(state.len() - 1))
        })
    };
    let (one, moved) = run(1);
    let (three, _) = run(3);
    assert!(moved.norm() > 0.0, "the load moved the tip");
    assert!(one == three, "1 and 3 threads differ");
}

/// A nearly incompressible bar (ν = 0.499) clamped at x = 0 with a load on its tip, of
/// averaged-pressure tetrahedra, viscoelastic or elastic: its state and models.
fn loaded_bar(viscous: bool) -> (State, Vec<Box<dyn Model>>) {
    let mesh = structured_box([0.0; 3], [1.0, 0.06, 0.1], [60, 4, 6]).unwrap();
    let reference: Vec<Vec3> = mesh.nodes.iter().map(|p| Vec3::from(*p)).collect();
    let mut material = Material::elastic(1100.0, 5e6, 0.499);
    if viscous {
        material.shear_viscosity = 50.0;
        material.bulk_viscosity = 30.0;
    }
    let body = TetBody::new("bar", &reference, mesh.tets.clone(), material)
        .unwrap()
        .with_formulation(Formulation::AveragedPressure);
    let mut state = State::at_rest(reference);
    body.lump_mass(&mut state.mass);
    for &n in &mesh.group("xmin").unwrap().nodes {
        state.fix(n as usize, Dofs::ALL);
    }
    let tip = mesh.group("xmax").unwrap().nodes.clone();
    let load = NodalLoad::new(
        "tip",
        tip,
        Vec3::new(0.0, 3.0, -10.0),
        TimeFunction::constant(1.0),
    );
    (state, vec![Box::new(body), Box::new(load)])
}

/// The bits of every particle's position and velocity.
fn motion_bits(state: &State) -> Vec<u64> {
    state
        .position
        .iter()
        .chain(&state.velocity)
        .flat_map(|v| v.iter().map(|c| c.to_bits()).collect::<Vec<_>>())
        .collect()
}

/// A run of the loaded bar decomposed over 1, 2 and 3 ranks holds, after a gather, the bits
/// one process holds, viscoelastic and elastic (issue 62: a decomposed run refused the
/// averaged-pressure body, whose nodal averages sum over blocks that different ranks compute;
/// they now go through the reverse exchange to the particle's owner and back). The body is cut
/// between the ranks and each rank steps its own particles and its halo only.
#[test]
fn a_decomposed_run_is_bit_identical_to_one_process() {
    use qdem_core::parallel::thread_ranks::on_thread_ranks;
    use qdem_core::{step::Scheme, step::StepRequest, step::StepSettings, world::World};
    const STEPS: usize = 60;
    let world = |viscous: bool| {
        let (state, models) = loaded_bar(viscous);
        let request = StepRequest {
            scheme: Scheme::Verlet,
            dt: None,
            safety: 0.5,
            local_damping: 0.0,
            adaptive: false,
            event_solve: Default::default(),
            implicit_default: None,
            fit_to: None,
        };
        let settings = StepSettings::resolve(&request, &state, &models).unwrap();
        World::new(state, models, settings).unwrap()
    };
    for viscous in [true, false] {
        let mut one = world(viscous);
        one.initialize().unwrap();
        for _ in 0..STEPS {
            one.step().unwrap();
        }
        let tip = one.state.len() - 1;
        assert!(
            one.state.displacement(tip).norm() > 0.0,
            "the load moved the tip"
        );
        let reference = motion_bits(&one.state);
        for size in [1, 2, 3] {
            let runs = on_thread_ranks(size, move |comm| {
                let mut world = world(viscous);
                let figures = world.decompose(comm).unwrap();
                world.initialize().unwrap();
                for _ in 0..STEPS {
                    world.step().unwrap();
                }
                world.gather();
                (motion_bits(&world.state), figures)
            });
            for (rank, (bits, figures)) in runs.iter().enumerate() {
                assert!(
                    *bits == reference,
                    "rank {rank} of {size} differs from one process (viscous: {viscous})"
                );
                if size > 1 {
                    assert_eq!(figures.cut_bodies, 1, "{figures:?}");
                    assert!(figures.received.iter().sum::<usize>() > 0, "{figures:?}");
                }
            }
        }
    }
}

/// The reported stress of an averaged-pressure body is the formulation's own (issue 55: it
/// was Hooke's law on each element's strain, whose pressure checkerboards as ν → ½). Two
/// identities that hold to rounding for the formulation's stress and fail by the size of the
/// load for Hooke's: the finite-strain stress of [`TetBody::tet_fields`] applied to each
/// tetrahedron's current face areas (Eqs. 9–10) gives the body's forces, and the small-strain
/// stress of [`TetBody::small_strain_stresses`] assembled as Σ_e V_e σ_e ∇N_a gives K u, the
/// force of the formulation's tangent. The displacement is irregular, so the elements'
/// own volumetric strains differ from their corners' averages.
#[test]
fn reported_stress_gives_the_bodys_own_forces() {
    let mesh = structured_box([0.0; 3], [1.0, 0.7, 0.5], [4, 3, 3]).unwrap();
    let (mut state, body) = body(&mesh, 0.499, Formulation::AveragedPressure);
    let u = displace_irregularly(&mut state);
    let mut model = body.clone();
    let mut forces = vec![Vec3::zeros(); state.len()];
    model.add_forces(&state, &mut forces, &mut []);
    let scale = forces.iter().map(|f| f.norm()).fold(0.0, f64::max);

    let (stress, _) = body.tet_fields(&state);
    let from_stress = assemble(&mesh.tets, &state.position, &stress);
    for (f, g) in forces.iter().zip(&from_stress) {
        assert!((f + g).norm() < 1e-9 * scale, "{f} vs {}", -g);
    }

    let ku = tangent_times(&body, &state.reference, &u);
    let small = body.small_strain_stresses(&state);
    let from_small = assemble(&mesh.tets, &state.reference, &small);
    let scale = ku.iter().map(|f| f.norm()).fold(0.0, f64::max);
    for (k, g) in ku.iter().zip(&from_small) {
        assert!((k - g).norm() < 1e-9 * scale, "K u {k} vs Σ V σ ∇N {g}");
    }
}

/// Moves every particle of `state` by a small irregular displacement (about 1e-7 m) from its
/// reference position; returns the displacements.
fn displace_irregularly(state: &mut State) -> Vec<Vec3> {
    let u: Vec<Vec3> = (0..state.len())
        .map(|i| {
            let t = i as f64;
            Vec3::new((1.3 * t).sin(), (0.7 * t).cos(), (2.1 * t).sin()) * 1e-7
        })
        .collect();
    for ((x, r), d) in state.position.iter_mut().zip(&state.reference).zip(&u) {
        *x = r + d;
    }
    u
}

/// K u of `body`'s small-strain tangent at its reference positions `reference` (the
/// tangent's lower triangle, each off-diagonal entry acting both ways).
fn tangent_times(body: &TetBody, reference: &[Vec3], u: &[Vec3]) -> Vec<Vec3> {
    let mut tangent = qdem_core::step::Tangent::new();
    qdem_core::step::Linearized::add_tangent(
        body,
        &State::at_rest(reference.to_vec()),
        &mut tangent,
    );
    let mut ku = vec![Vec3::zeros(); u.len()];
    for e in tangent.stiffness_entries() {
        let (r, c) = (e.row, e.col);
        ku[r / 3][r % 3] += e.val * u[c / 3][c % 3];
        if r != c {
            ku[c / 3][c % 3] += e.val * u[r / 3][r % 3];
        }
    }
    ku
}

/// Σ_e V_e σ_e ∇N_a per particle a, the shape functions' gradients and volumes at `x`: the
/// internal force of the stresses `stress` (the negative of the force on the particles).
fn assemble(tets: &[[u32; 4]], x: &[Vec3], stress: &[qdem_core::Mat3]) -> Vec<Vec3> {
    let mut f = vec![Vec3::zeros(); x.len()];
    for (tet, sigma) in tets.iter().zip(stress) {
        let p = tet.map(|n| x[n as usize]);
        let dm = qdem_core::Mat3::from_columns(&[p[1] - p[0], p[2] - p[0], p[3] - p[0]]);
        let inv = dm.try_inverse().unwrap();
        let volume = dm.determinant().abs() / 6.0;
        let g: [Vec3; 3] = std::array::from_fn(|k| inv.row(k).transpose());
        let g0 = -(g[0] + g[1] + g[2]);
        for (n, ga) in tet.iter().zip([g0, g[0], g[1], g[2]]) {
            f[*n as usize] += sigma * ga * volume;
        }
    }
    f
}
