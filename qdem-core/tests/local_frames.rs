//! Fixes in a local frame ([`qdem_core::step::frames`]) are invariant under a rotation of the
//! whole problem: a block on three rollers (x = 0 held in x, y = 0 in y, z = 0 in z) under a
//! skew end load, solved once on the axes and once with the mesh, the load and the rollers
//! rotated by Q (30° about z after 20° about x), the rollers held in the rotated frame Q.
//! Elasticity is isotropic and the lumped mass a scalar per node, so the rotated problem's
//! answer is Q times the first's: the displacements u′ = Q u and the reactions, read in the
//! rollers' frame, Qᵀ r′ = r. Only rounding separates them: the rotated mesh's coordinates
//! are rounded (10⁻¹⁶ of each), which perturbs each element's stiffness by its condition
//! number times that, and the solve amplifies it by cond(K) (about 10⁵ for this block): the
//! static answers agree to a relative 10⁻⁹ (measured 7.5·10⁻¹¹); the explicit run's
//! perturbed frequencies shift its phase by a growing amount, 10⁻⁷ after 300 steps
//! (measured 6·10⁻⁹); the modal frequencies to 10⁻⁸ (Lanczos converges to 10⁻¹⁰).
//! An implicit Newmark run agrees as the explicit one does. On the axes (Q = I) the framed
//! fix is the axis fix, so the same test holds the new path to the old one. A run over ranks refuses a framed fix.

use qdem_core::modal::lanczos::natural_modes;
use qdem_core::parallel::thread_ranks::on_thread_ranks;
use qdem_core::{
    continuum::Material, continuum::TetBody, loads::NodalLoad, loads::TimeFunction,
    solvers::Newmark, solvers::StaticSolver, solvers::Verlet, step::stepper::choose_step,
    step::Dofs, step::Model, step::Scheme, step::State, step::StepRequest, step::StepSettings,
    step::Stepper, world::World, Mat3, Vec3,
};
use qdem_mesh::structured_box;

/// The block's size (m) and cells.
const SIZE: [f64; 3] = [0.6, 0.2, 0.3];
const CELLS: [usize; 3] = [6, 2, 3];

/// The rotation of the second problem: 30° about z after 20° about x.
fn rotation() -> Mat3 {
    let (s, c) = 30f64.to_radians().sin_cos();
    let z = Mat3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0);
    let (s, c) = 20f64.to_radians().sin_cos();
    let x = Mat3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c);
    z * x
}

/// The block rotated by `q` on its three rollers (held in the frame `q` when `framed`, else
/// on the axes, which needs `q = I`), with `rollers_only` the x = 0 roller alone; the end
/// load (x = L face) q·(2, −1, −3) kN.
fn block(q: Mat3, framed: bool, rollers_only: bool) -> (State, Vec<Box<dyn Model>>) {
    let mesh = structured_box([0.0; 3], SIZE, CELLS).unwrap();
    let local: Vec<Vec3> = mesh.nodes.iter().map(|p| Vec3::from(*p)).collect();
    let reference: Vec<Vec3> = local.iter().map(|x| q * x).collect();
    let body = TetBody::new(
        "block",
        &reference,
        mesh.tets.clone(),
        Material::elastic(2400.0, 30e9, 0.2),
    )
    .unwrap();
    let mut state = State::at_rest(reference);
    body.lump_mass(&mut state.mass);
    for (i, x) in local.iter().enumerate() {
        for axis in 0..3 {
            if x[axis] == 0.0 && (axis == 0 || !rollers_only) {
                let dofs = Dofs::from_mask(std::array::from_fn(|k| k == axis));
                match framed {
                    true => state.fix_in_frame(i, q, dofs).unwrap(),
                    false => state.fix(i, dofs),
                }
            }
        }
    }
    let end: Vec<u32> = mesh.group("xmax").unwrap().nodes.clone();
    let load = NodalLoad::new(
        "end",
        end,
        q * Vec3::new(2e3, -1e3, -3e3),
        TimeFunction::constant(1.0),
    );
    (state, vec![Box::new(body), Box::new(load)])
}

/// The largest |a_i − b_i| over the largest |b_i|.
fn relative(a: &[Vec3], b: &[Vec3]) -> f64 {
    let scale = b.iter().map(|v| v.amax()).fold(0.0, f64::max);
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).amax())
        .fold(0.0, f64::max)
        / scale
}

/// The displacements of `state`, rotated by `back`.
fn displacements(state: &State, back: Mat3) -> Vec<Vec3> {
    (0..state.len())
        .map(|i| back * state.displacement(i))
        .collect()
}

/// The static answer: the displacements and the force f − K u (minus the reactions), both
/// rotated by `back`.
fn static_answer(q: Mat3, framed: bool) -> (Vec<Vec3>, Vec<Vec3>) {
    let (mut state, mut models) = block(q, framed, false);
    let mut solver = StaticSolver::new();
    solver.solve(&mut state, &mut models, 0.0).unwrap();
    let force = solver.forces().iter().map(|f| back(q) * f).collect();
    (displacements(&state, back(q)), force)
}

/// The rotation back to the axes.
fn back(q: Mat3) -> Mat3 {
    q.transpose()
}

#[test]
fn a_rotated_static_problem_on_framed_rollers_gives_the_rotated_answer() {
    let (u, r) = static_answer(Mat3::identity(), false);
    // On the axes, the framed path is the axis path.
    let (u_id, r_id) = static_answer(Mat3::identity(), true);
    assert!(relative(&u_id, &u) < 1e-12, "{:e}", relative(&u_id, &u));
    assert!(relative(&r_id, &r) < 1e-12, "{:e}", relative(&r_id, &r));
    let (u_q, r_q) = static_answer(rotation(), true);
    let du = relative(&u_q, &u);
    let dr = relative(&r_q, &r);
    eprintln!("rotated static: displacements {du:.2e}, reactions {dr:.2e}");
    assert!(du < 1e-9, "displacements differ by {du:e}");
    assert!(
        dr < 1e-9,
        "reactions in the rollers' frame differ by {dr:e}"
    );
    // f − K u is minus the rollers' reactions, which carry the load: it sums to the load,
    // read in the rollers' frame.
    let total: Vec3 = r_q.iter().sum();
    assert!(
        (total - Vec3::new(2e3, -1e3, -3e3)).amax() < 1e-9 * 3e3,
        "{total}"
    );
}

/// The displacements, velocities and forces after `steps` Verlet steps, rotated back.
fn explicit_answer(q: Mat3, framed: bool, steps: usize) -> [Vec<Vec3>; 3] {
    let (mut state, mut models) = block(q, framed, false);
    // The step of the unrotated block, so that both runs take the same one.
    let (axes, axes_models) = block(Mat3::identity(), false, false);
    let dt = choose_step(&axes, &axes_models, None, 0.9).unwrap();
    let mut verlet = Verlet::new(dt);
    verlet.initialize(&mut state, &mut models).unwrap();
    for _ in 0..steps {
        verlet.step(&mut state, &mut models).unwrap();
    }
    let b = back(q);
    [
        displacements(&state, b),
        state.velocity.iter().map(|v| b * v).collect(),
        verlet.forces().iter().map(|f| b * f).collect(),
    ]
}

#[test]
fn a_rotated_explicit_run_on_framed_rollers_moves_as_the_rotated_one() {
    let [u, v, f] = explicit_answer(Mat3::identity(), false, 300);
    let [u_q, v_q, f_q] = explicit_answer(rotation(), true, 300);
    let (du, dv, df) = (relative(&u_q, &u), relative(&v_q, &v), relative(&f_q, &f));
    eprintln!("rotated explicit: u {du:.2e}, v {dv:.2e}, f {df:.2e}");
    assert!(du < 1e-7 && dv < 1e-7 && df < 1e-7, "{du:e} {dv:e} {df:e}");
    // The rollers' nodes never left their planes, beyond the rounding of the positions
    // (|x| < 0.7 m) that each of the 300 drifts adds.
    let (state, _) = block(rotation(), true, false);
    let normal_motion = state
        .frames
        .iter()
        .map(|(i, r, held)| {
            (0..3)
                .filter(|&k| held.contains(k))
                .map(|k| r.column(k).dot(&(rotation() * u_q[i])).abs())
                .fold(0.0, f64::max)
        })
        .fold(0.0, f64::max);
    let bound = 300.0 * f64::EPSILON * 0.7;
    assert!(normal_motion <= bound, "{normal_motion:e} m off the planes");
}

/// An implicit Newmark run (average acceleration, 10 times the explicit step) of the block
/// rotated by `q`: its displacements and velocities after `steps` steps, rotated back.
fn implicit_answer(q: Mat3, framed: bool, steps: usize) -> [Vec<Vec3>; 2] {
    let (mut state, mut models) = block(q, framed, false);
    let (axes, axes_models) = block(Mat3::identity(), false, false);
    let dt = 10.0 * choose_step(&axes, &axes_models, None, 0.9).unwrap();
    let mut newmark = Newmark::average_acceleration(dt);
    newmark.initialize(&mut state, &mut models).unwrap();
    for _ in 0..steps {
        newmark.step(&mut state, &mut models).unwrap();
    }
    let b = back(q);
    [
        displacements(&state, b),
        state.velocity.iter().map(|v| b * v).collect(),
    ]
}

/// Newmark solves the framed rollers' rows in their frame each step (the effective matrix
/// M + γhC + βh²K, the loads and the answer rotated as the static solve's): 50 implicit
/// steps agree with the axes' run to 10⁻⁷ as the explicit ones do (measured 4·10⁻¹⁰).
#[test]
fn a_rotated_implicit_run_on_framed_rollers_moves_as_the_rotated_one() {
    let [u, v] = implicit_answer(Mat3::identity(), false, 50);
    let [u_q, v_q] = implicit_answer(rotation(), true, 50);
    let (du, dv) = (relative(&u_q, &u), relative(&v_q, &v));
    eprintln!("rotated implicit: u {du:.2e}, v {dv:.2e}");
    assert!(du < 1e-7 && dv < 1e-7, "{du:e} {dv:e}");
}

#[test]
fn a_rotated_modal_problem_on_framed_rollers_has_the_same_frequencies() {
    for rollers_only in [false, true] {
        let (state, models) = block(Mat3::identity(), false, rollers_only);
        let axes = natural_modes(&state, &models, 8).unwrap();
        let (state, models) = block(rotation(), true, rollers_only);
        let rotated = natural_modes(&state, &models, 8).unwrap();
        assert_eq!(axes.dofs, rotated.dofs);
        let rigid =
            |m: &qdem_core::modal::lanczos::Modes| m.modes.iter().filter(|m| m.rigid).count();
        // The x = 0 roller alone leaves 3 rigid motions (y, z and the rotation about x).
        assert_eq!(rigid(&axes), if rollers_only { 3 } else { 0 });
        assert_eq!(rigid(&rotated), rigid(&axes));
        for (a, b) in axes
            .modes
            .iter()
            .zip(&rotated.modes)
            .filter(|(a, _)| !a.rigid)
        {
            let d = (b.frequency_hz / a.frequency_hz - 1.0).abs();
            assert!(d < 1e-8, "{} Hz vs {} Hz", a.frequency_hz, b.frequency_hz);
        }
        // The first elastic mode's shape, rotated back, is the axes' one (up to sign).
        let (a, b) = (
            axes.modes.iter().find(|m| !m.rigid).unwrap(),
            rotated.modes.iter().find(|m| !m.rigid).unwrap(),
        );
        let b: Vec<Vec3> = b.shape.iter().map(|x| back(rotation()) * x).collect();
        let dot: f64 = a.shape.iter().zip(&b).map(|(x, y)| x.dot(y)).sum();
        let sign = dot.signum();
        let b: Vec<Vec3> = b.iter().map(|x| sign * x).collect();
        assert!(
            relative(&b, &a.shape) < 1e-6,
            "{:e}",
            relative(&b, &a.shape)
        );
    }
}

#[test]
fn a_run_over_ranks_refuses_a_framed_fix() {
    let errors = on_thread_ranks(2, |comm| {
        let (state, models) = block(rotation(), true, false);
        let request = StepRequest {
            scheme: Scheme::Verlet,
            dt: None,
            safety: 0.9,
            local_damping: 0.0,
            adaptive: false,
            event_solve: Default::default(),
            implicit_default: None,
            fit_to: None,
        };
        let settings = StepSettings::resolve(&request, &state, &models).unwrap();
        let mut world = World::new(state, models, settings).unwrap();
        world.decompose(comm).err().map(|e| e.to_string())
    });
    for error in errors {
        let error = error.expect("refused");
        assert!(error.contains("local frame"), "{error}");
    }
}

#[test]
fn a_skewed_basis_is_refused() {
    let mut state = State::at_rest(vec![Vec3::zeros()]);
    let skewed = Mat3::new(1.0, 0.2, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
    let error = state.fix_in_frame(0, skewed, Dofs::ALL).unwrap_err();
    assert!(error.to_string().contains("not orthonormal"), "{error}");
    assert!(state.frames.is_empty() && state.fixed[0].is_empty());
}
