//! Periodic boundaries (paper 003 Eq. 1) and the time-delayed boundary (Eqs. 2–7) on a
//! compressed, spinning, frictional packing of rigid spheres periodic along x:
//! - shifting the packing by a fraction of the period gives the same trajectories and contact
//!   forces (translation invariance);
//! - a pair touching through the boundary feels the force of the same pair side by side;
//! - a section measures the Hertz force of the pair it cuts, and repeats every period;
//! - with shared faces the time-delayed boundary conserves momentum along the periodic axis,
//!   which Eqs. 6–7 do not;
//! - a zero-lag time-delayed boundary is the ordinary periodic boundary bit for bit, and a
//!   quarter-cycle lag is not.

mod common;

use common::packing::{model, packing, run, PERIOD, R, SPACING};
use common::{contacts, rigid_spheres, stepper};
use qdem_contact::{
    ContactLaw, ContactSettings, DemContacts, HertzMindlin, LoadCycle, TimeDelayedBoundary,
};
use qdem_core::{step::Model, step::State, step::Stepper, Vec3};

#[test]
fn shifting_a_periodic_packing_changes_nothing_but_the_shift() {
    let steps = 600;
    let (a, sa) = packing(0.0);
    let reference = run(a.clone(), model(&a, &sa, Vec::new()), steps).0;
    for fraction in [0.37, -1.61] {
        let shift = fraction * PERIOD;
        let (b, sb) = packing(shift);
        let shifted = run(b.clone(), model(&b, &sb, Vec::new()), steps).0;
        let scale_x = PERIOD;
        let scale_v = reference
            .velocity
            .iter()
            .map(|v| v.norm())
            .fold(0.0, f64::max);
        for i in 0..reference.len() {
            let dx = shifted.position[i] - Vec3::new(shift, 0.0, 0.0) - reference.position[i];
            let dv = shifted.velocity[i] - reference.velocity[i];
            assert!(dx.norm() <= 1e-9 * scale_x, "particle {i}: {dx:?}");
            assert!(dv.norm() <= 1e-9 * scale_v, "particle {i}: {dv:?}");
        }
        for b in 0..reference.rigid.len() {
            let dw = shifted.rigid.angular_velocity[b] - reference.rigid.angular_velocity[b];
            assert!(dw.norm() <= 1e-9 * 1e3, "body {b}: {dw:?}");
        }
    }
    // The packing did interact: the rows are no longer evenly spaced.
    let moved = (0..reference.len())
        .map(|i| (reference.position[i] - a.position[i]).norm())
        .fold(0.0, f64::max);
    assert!(moved > 0.01 * R, "{moved}");
}

#[test]
fn a_pair_through_the_boundary_feels_the_force_of_the_pair_side_by_side() {
    // Spheres at x = 0.2R and L − 1.7R touch through the boundary at a separation of 1.9R;
    // the same pair side by side without periodicity gives the reference force.
    let gap = 1.9 * R;
    let through = [
        Vec3::new(0.2 * R, 0.0, 0.0),
        Vec3::new(PERIOD - 1.7 * R, 0.0, 0.0),
    ];
    let side = [
        Vec3::new(0.2 * R, 0.0, 0.0),
        Vec3::new(0.2 * R - gap, 0.0, 0.0),
    ];
    let forces = |centers: &[Vec3], periodic: bool| {
        let (state, spheres) = rigid_spheres(centers, R, 2700.0);
        let mut m = model(&state, &spheres, Vec::new());
        if !periodic {
            let settings = ContactSettings {
                law: ContactLaw::HertzMindlin(HertzMindlin { damping_ratio: 0.1 }),
                friction: 0.5,
                skin: 0.2 * R,
            };
            m = contacts(&state, &spheres, (5e7, 0.25), settings, Vec::new());
        }
        let mut f = vec![Vec3::zeros(); state.len()];
        let mut t = vec![Vec3::zeros(); state.rigid.len()];
        m.add_forces(&state, &mut f, &mut t);
        f
    };
    let a = forces(&through, true);
    let b = forces(&side, false);
    assert!(b[0].x > 0.0, "the left sphere is pushed right: {:?}", b[0]);
    for i in 0..2 {
        assert!(
            (a[i] - b[i]).norm() <= 1e-12 * b[0].norm(),
            "{:?} {:?}",
            a[i],
            b[i]
        );
    }
}

#[test]
fn a_section_measures_the_hertz_force_of_the_pair_it_cuts() {
    // Three spheres in a row along x at rest, overlapping by 0.1R and 0.04R: a section between
    // two of them measures (4/3) E* √R* δ^{3/2} of their overlap (E* = E/2(1 − ν²), R* = R/2),
    // a section beside the row nothing.
    let (young, poisson) = (5e7, 0.25);
    let centers = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.9 * R, 0.0, 0.0),
        Vec3::new(3.86 * R, 0.0, 0.0),
    ];
    let (state, spheres) = rigid_spheres(&centers, R, 2700.0);
    let settings = ContactSettings {
        law: ContactLaw::HertzMindlin(HertzMindlin { damping_ratio: 0.1 }),
        friction: 0.5,
        skin: 0.2 * R,
    };
    let mut m = contacts(&state, &spheres, (young, poisson), settings, Vec::new());
    let mut f = vec![Vec3::zeros(); state.len()];
    let mut t = vec![Vec3::zeros(); state.rigid.len()];
    m.add_forces(&state, &mut f, &mut t);
    let e_star = young / (2.0 * (1.0 - poisson * poisson));
    let hertz = |overlap: f64| 4.0 / 3.0 * e_star * (0.5 * R).sqrt() * overlap.powf(1.5);
    for (at, expected) in [(R, hertz(0.1 * R)), (2.9 * R, hertz(0.04 * R))] {
        let measured = m.section_force(0, at);
        assert!(
            (measured - expected).abs() <= 1e-9 * expected,
            "{at}: {measured} {expected}"
        );
    }
    assert_eq!(m.section_force(0, -R), 0.0);
    assert_eq!(m.section_force(1, 0.5 * R), 0.0);

    // In the periodic packing a section repeats every period, and the one at the cell face
    // cuts the nine rows' pairs through the boundary.
    let (a, sa) = packing(0.0);
    let mut p = model(&a, &sa, Vec::new());
    let mut f = vec![Vec3::zeros(); a.len()];
    let mut t = vec![Vec3::zeros(); a.rigid.len()];
    p.add_forces(&a, &mut f, &mut t);
    let face = p.section_force(0, 0.0);
    assert!(face > 0.0);
    assert_eq!(p.section_force(0, PERIOD), face);
    assert_eq!(p.section_force(0, -2.0 * PERIOD), face);
    assert_ne!(p.section_force(0, SPACING), face);
}

/// The packing run with a time-delayed boundary of lag `lag` (a 100 Hz cycle from t = 0),
/// with shared faces or not; also the largest boundary force measured and the largest
/// |left − right| ghost scale difference over the run.
fn delayed(lag: f64, shared: bool, steps: usize) -> (State, f64, f64) {
    let (mut state, sa) = packing(0.0);
    let cycle = LoadCycle {
        frequency: 100.0,
        phase: 0.0,
        start: 0.0,
    };
    let mut boundary = TimeDelayedBoundary::new(cycle, lag);
    if shared {
        boundary = boundary.with_shared_faces();
    }
    let m = model(&state, &sa, Vec::new())
        .with_time_delay(0, boundary)
        .unwrap();
    let dt = 0.5 * m.stable_dt(&state).unwrap();
    let mut models: Vec<Box<dyn Model>> = vec![Box::new(m)];
    let mut s = stepper(dt, &mut state, &mut models);
    let (mut force, mut spread) = (0.0f64, 0.0f64);
    for _ in 0..steps {
        s.step(&mut state, &mut models).unwrap();
        let contacts: &dyn std::any::Any = models[0].as_ref();
        let (scales, f) = contacts
            .downcast_ref::<DemContacts>()
            .unwrap()
            .time_delay_state()
            .unwrap();
        force = force.max(f);
        spread = spread.max((scales.left - scales.right).abs());
    }
    (state, force, spread)
}

#[test]
fn a_zero_lag_time_delay_is_the_ordinary_periodic_boundary_bit_for_bit() {
    let steps = 2000;
    let (a, sa) = packing(0.0);
    let (ordinary, _) = run(a.clone(), model(&a, &sa, Vec::new()), steps);
    let (zero, force, spread) = delayed(0.0, false, steps);
    assert_eq!(zero.position, ordinary.position);
    assert_eq!(zero.velocity, ordinary.velocity);
    assert_eq!(zero.rigid.angular_velocity, ordinary.rigid.angular_velocity);
    // The controller was live: it measured boundary forces, and its scales stayed exactly 1.
    assert!(force > 0.0, "{force}");
    assert_eq!(spread, 0.0);
    // A quarter-cycle lag scales the ghost forces (left ≠ right) and changes the motion.
    let (quarter, _, spread) = delayed(std::f64::consts::FRAC_PI_2, false, steps);
    assert!(spread > 1e-3, "{spread}");
    assert_ne!(quarter.position, ordinary.position);
}

/// Σ m v along the periodic axis x, and Σ m |v| for scale.
fn momentum(state: &State) -> (f64, f64) {
    state
        .mass
        .iter()
        .zip(&state.velocity)
        .fold((0.0, 0.0), |(p, q), (m, v)| (p + m * v.x, q + m * v.norm()))
}

#[test]
fn shared_faces_conserve_momentum_where_eqs_6_7_do_not() {
    // No walls, no gravity: only contact forces act, so the packing's momentum along the
    // periodic axis stays what it was exactly when every pair's action equals its reaction.
    // Eqs. 6-7 scale the two ends of a pair through the boundary differently.
    let steps = 2000;
    let (start, _) = packing(0.0);
    let (p0, scale) = momentum(&start);
    let lag = std::f64::consts::FRAC_PI_2;
    let (shared, force, spread) = delayed(lag, true, steps);
    assert!(force > 0.0, "{force}");
    assert_eq!(spread, 0.0);
    let drift = (momentum(&shared).0 - p0).abs() / scale;
    assert!(drift < 1e-12, "shared faces: momentum drift {drift:e}");
    let (paper, _, spread) = delayed(lag, false, steps);
    assert!(spread > 1e-3, "{spread}");
    let drift = (momentum(&paper).0 - p0).abs() / scale;
    assert!(drift > 1e-3, "Eqs. 6-7: momentum drift {drift:e}");
    assert_ne!(shared.position, paper.position);
}
