//! Single-DOF oscillator m ẍ = −k x through the Newmark stepper (paper 001 Eqs. 13–16, 26):
//! average acceleration conserves energy exactly and lengthens the period to
//! T̃/T = ω∆t / (2 atan(ω∆t/2)); central difference is stable for ω∆t ≤ 2 only.

use qdem_core::{
    error::CoreError, solvers::Newmark, solvers::StaticSolver, step::Linearized, step::Model,
    step::State, step::Stepper, step::Tangent, Vec3,
};

/// A linear spring of stiffness k from one particle to its reference position.
struct Spring {
    k: f64,
}

impl Model for Spring {
    fn name(&self) -> &str {
        "spring"
    }

    fn add_forces(&mut self, state: &State, force: &mut [Vec3], _torque: &mut [Vec3]) {
        force[0] -= self.k * state.displacement(0);
    }

    fn linearized(&self) -> Option<&dyn Linearized> {
        Some(self)
    }
}

impl Linearized for Spring {
    fn add_tangent(&self, _state: &State, tangent: &mut Tangent) {
        tangent.add_stiffness(0, 0, &(qdem_core::Mat3::identity() * self.k));
    }
}

/// Unit mass, ω = 1 rad/s, released from x = 1 at rest: the displacements (x only) of up to
/// `steps` steps, stopping once |x| exceeds `stop_above`, the final state and the stepper.
fn run(mut stepper: Newmark, steps: usize, stop_above: f64) -> (Vec<f64>, State, Newmark) {
    let mut state = State::at_rest(vec![Vec3::zeros()]);
    state.mass[0] = 1.0;
    state.position[0].x = 1.0;
    let mut models: Vec<Box<dyn Model>> = vec![Box::new(Spring { k: 1.0 })];
    stepper.initialize(&mut state, &mut models).unwrap();
    let mut record = vec![state.position[0].x];
    for _ in 0..steps {
        stepper.step(&mut state, &mut models).unwrap();
        record.push(state.position[0].x);
        if state.position[0].x.abs() > stop_above {
            break;
        }
    }
    (record, state, stepper)
}

/// The phase advance per step θ of a sampled sinusoid, from the exact three-point identity
/// x_{n+1} + x_{n−1} = 2 cos θ x_n, fitted by least squares over the record.
fn phase_per_step(x: &[f64]) -> f64 {
    let (num, den) = x.windows(3).fold((0.0, 0.0), |(n, d), w| {
        (n + w[1] * (w[0] + w[2]), d + 2.0 * w[1] * w[1])
    });
    (num / den).acos()
}

#[test]
fn average_acceleration_conserves_amplitude_and_lengthens_the_period() {
    for omega_dt in [0.1, 0.5] {
        let periods = 1000.0;
        let steps = (periods * std::f64::consts::TAU / omega_dt) as usize;
        let (record, state, stepper) = run(
            Newmark::average_acceleration(omega_dt),
            steps,
            f64::INFINITY,
        );
        // Energy (amplitude²) with ω = m = 1.
        let energy = state.position[0].x.powi(2) + state.velocity[0].x.powi(2);
        let drift = (energy.sqrt() - 1.0).abs();
        let elongation =
            std::f64::consts::TAU / phase_per_step(&record) / (std::f64::consts::TAU / omega_dt);
        let expected = omega_dt / (2.0 * (omega_dt / 2.0).atan());
        let error = (elongation / expected - 1.0).abs();
        println!(
            "ω∆t = {omega_dt}: {steps} steps, amplitude drift {drift:.2e}, T̃/T = {elongation:.9} \
             (theory {expected:.9}, relative error {error:.2e})"
        );
        assert!(drift < 1e-10, "amplitude drift {drift:e}");
        assert!(error < 1e-6, "period elongation error {error:e}");
        assert_eq!(
            stepper.report().factor.unwrap().factorizations,
            1,
            "a fixed tangent is factorised once"
        );
    }
}

#[test]
fn central_difference_is_stable_just_below_omega_dt_2_only() {
    let (stable, _, _) = run(Newmark::central_difference(1.99), 2000, 1e6);
    let peak = stable.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let (unstable, _, _) = run(Newmark::central_difference(2.01), 2000, 1e6);
    let growth = unstable.last().unwrap().abs();
    println!(
        "ω∆t = 1.99: peak |x| {peak:.3} over {} steps; ω∆t = 2.01: |x| = {growth:.3e} after {} steps",
        stable.len() - 1,
        unstable.len() - 1
    );
    assert_eq!(stable.len(), 2001);
    assert!(peak < 20.0, "peak {peak}");
    assert!(growth > 1e6, "growth {growth:e}");
}

/// A force without a tangent.
struct Opaque;

impl Model for Opaque {
    fn name(&self) -> &str {
        "opaque"
    }

    fn add_forces(&mut self, _state: &State, _force: &mut [Vec3], _torque: &mut [Vec3]) {}
}

#[test]
fn implicit_and_static_solves_refuse_bad_systems() {
    let mut state = State::at_rest(vec![Vec3::zeros()]);
    state.mass[0] = 1.0;
    let mut opaque: Vec<Box<dyn Model>> = vec![Box::new(Opaque)];
    let error = Newmark::average_acceleration(0.1)
        .initialize(&mut state, &mut opaque)
        .unwrap_err();
    assert!(matches!(error, CoreError::NoTangent { ref model } if model == "opaque"));
    // A spring of zero stiffness leaves the static system singular.
    let mut loose: Vec<Box<dyn Model>> = vec![Box::new(Spring { k: 0.0 })];
    let error = StaticSolver::new()
        .solve(&mut state, &mut loose, 0.0)
        .unwrap_err();
    println!("{error}");
    assert!(matches!(
        error,
        CoreError::NotPositiveDefinite { dofs: 3, .. }
    ));
    assert!(matches!(
        Newmark::new(0.6, 0.5, 0.1),
        Err(CoreError::NewmarkParameters { .. })
    ));
}

/// A one-sided contact: pushes the particle back up with k·(−x) while x < 0 (pressed in), under
/// its weight m g downwards (−x). Its tangent is the closed contact's k.
struct Contact {
    k: f64,
    weight: f64,
}

impl Model for Contact {
    fn name(&self) -> &str {
        "contact"
    }

    fn add_forces(&mut self, state: &State, force: &mut [Vec3], _torque: &mut [Vec3]) {
        let x = state.displacement(0).x;
        force[0].x += self.k * (-x).max(0.0) - self.weight;
    }

    fn linearized(&self) -> Option<&dyn Linearized> {
        Some(self)
    }
}

impl Linearized for Contact {
    fn add_tangent(&self, _state: &State, tangent: &mut Tangent) {
        tangent.add_stiffness(0, 0, &(qdem_core::Mat3::identity() * self.k));
    }
}

/// A mass resting on a stiff one-sided contact and rocking on it by half its static
/// compression never leaves it, so its motion is linear and average acceleration must
/// conserve the energy ½mv² + ½k x² + m g x exactly, even at ω∆t = 1000 (the beam-bonded
/// benchmark's ratio). This holds only because Eq. 26 is linearised at the step's start:
/// linearised at the predictor x_n + ∆t v_n + ¼∆t² a_n, which moves the stiff mode by
/// (ω∆t)²/4 = 2.5e5 times its amplitude, the contact would be evaluated wide open.
#[test]
fn implicit_step_linearises_a_one_sided_contact_where_the_body_is() {
    let (m, k, g) = (1.0, 1e6, 10.0);
    let (rest, amplitude) = (-m * g / k, 0.5 * m * g / k);
    let mut state = State::at_rest(vec![Vec3::zeros()]);
    state.mass[0] = m;
    state.position[0].x = rest + amplitude;
    let mut models: Vec<Box<dyn Model>> = vec![Box::new(Contact { k, weight: m * g })];
    let dt = 1000.0 / (k / m).sqrt();
    let mut stepper = Newmark::average_acceleration(dt);
    stepper.initialize(&mut state, &mut models).unwrap();
    let energy = |s: &State| {
        let (x, v) = (s.position[0].x, s.velocity[0].x);
        0.5 * m * v * v + 0.5 * k * x.min(0.0).powi(2) + m * g * x
    };
    let start = energy(&state);
    let scale = 0.5 * k * amplitude * amplitude;
    for step in 0..200 {
        stepper.step(&mut state, &mut models).unwrap();
        let x = state.position[0].x;
        assert!(
            (x - rest).abs() <= amplitude * (1.0 + 1e-9),
            "step {step}: x = {x:e} left the contact's range {rest:e} ± {amplitude:e}"
        );
        let drift = (energy(&state) - start).abs() / scale;
        assert!(drift < 1e-6, "step {step}: energy drift {drift:e}");
    }
}

/// A dashpot that only resists motion towards −x (as a contact's normal damping resists only
/// approach), and a constant push F towards −x.
struct OneSidedDashpot {
    c: f64,
    push: f64,
}

impl Model for OneSidedDashpot {
    fn name(&self) -> &str {
        "one-sided dashpot"
    }

    fn add_forces(&mut self, state: &State, force: &mut [Vec3], _torque: &mut [Vec3]) {
        force[0].x += self.c * (-state.velocity[0].x).max(0.0) - self.push;
    }

    fn linearized(&self) -> Option<&dyn Linearized> {
        Some(self)
    }
}

impl Linearized for OneSidedDashpot {
    fn add_tangent(&self, _state: &State, tangent: &mut Tangent) {
        tangent.add_damping(0, 0, &(qdem_core::Mat3::identity() * self.c));
    }
}

/// Pushed through the dashpot from rest near its terminal velocity −F/c, the mass always moves
/// towards −x, so the dashpot acts throughout and the motion is linear: average acceleration
/// must give the trapezoidal recurrence (m/∆t + c/2) v_{n+1} = (m/∆t − c/2) v_n − F, even at
/// c∆t/m = 1000. The implicit step linearises the force at v_n; at the held velocity of the
/// predictor form (−v_n for β = ¼, γ = ½) the dashpot would see the mass moving away.
#[test]
fn implicit_step_linearises_a_one_sided_dashpot_at_the_velocity_the_body_has() {
    let (m, c, push) = (1.0, 1e3, 1e3);
    let terminal = -push / c;
    let mut state = State::at_rest(vec![Vec3::zeros()]);
    state.mass[0] = m;
    state.velocity[0].x = 0.9 * terminal;
    let mut models: Vec<Box<dyn Model>> = vec![Box::new(OneSidedDashpot { c, push })];
    let dt = 1000.0 * m / c;
    let mut stepper = Newmark::average_acceleration(dt);
    stepper.initialize(&mut state, &mut models).unwrap();
    let mut expected = state.velocity[0].x;
    for step in 0..50 {
        stepper.step(&mut state, &mut models).unwrap();
        expected = ((m / dt - 0.5 * c) * expected - push) / (m / dt + 0.5 * c);
        let v = state.velocity[0].x;
        assert!(
            (v - expected).abs() <= 1e-9 * terminal.abs(),
            "step {step}: v = {v:e}, trapezoidal recurrence {expected:e}"
        );
    }
}
