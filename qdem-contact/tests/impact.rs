//! Head-on impacts of two rigid spheres against the analytical solutions: Hertz's contact
//! duration and maximum overlap, and the linear spring–dashpot's restitution coefficient
//! e = exp(−ζπ/√(1 − ζ²)).

mod common;

use common::{contacts, rigid_spheres, stepper};
use qdem_contact::{ContactLaw, ContactSettings, HertzMindlin, LinearSpring};
use qdem_core::{step::Model, step::Stepper, Vec3};

const RADIUS: f64 = 0.01;
const DENSITY: f64 = 2700.0;

/// Two spheres just apart approaching at `speed` each; returns (contact duration, maximum
/// overlap, relative speed after) from a run with step `dt`.
fn collide(law: ContactLaw, speed: f64, dt: f64) -> (f64, f64, f64) {
    let gap = 1e-6;
    let centers = [
        Vec3::new(-RADIUS - gap, 0.0, 0.0),
        Vec3::new(RADIUS + gap, 0.0, 0.0),
    ];
    let (mut state, spheres) = rigid_spheres(&centers, RADIUS, DENSITY);
    state.velocity[0] = Vec3::new(speed, 0.0, 0.0);
    state.velocity[1] = Vec3::new(-speed, 0.0, 0.0);
    let settings = ContactSettings {
        law,
        friction: 0.5,
        skin: 0.1 * RADIUS,
    };
    let model = contacts(&state, &spheres, (7e10, 0.3), settings, vec![]);
    let mut models: Vec<Box<dyn Model>> = vec![Box::new(model)];
    let mut s = stepper(dt, &mut state, &mut models);
    let overlap =
        |st: &qdem_core::step::State| 2.0 * RADIUS - (st.position[1] - st.position[0]).norm();
    let (mut start, mut end, mut max) = (None, None, 0.0f64);
    for step in 1..2_000_000 {
        s.step(&mut state, &mut models).unwrap();
        let d = overlap(&state);
        if d > 0.0 && start.is_none() {
            start = Some(step);
        }
        max = max.max(d);
        if d <= 0.0 && start.is_some() {
            end = Some(step);
            break;
        }
    }
    let duration = (end.unwrap() - start.unwrap()) as f64 * dt;
    let after = (state.velocity[1] - state.velocity[0]).x;
    (duration, max, after)
}

/// ∫₀¹ dx/√(1 − x^{5/2}), with 1 − x = u² to remove the end-point singularity (Simpson).
fn hertz_integral() -> f64 {
    let f = |u: f64| {
        if u == 0.0 {
            2.0 / 2.5f64.sqrt()
        } else {
            2.0 * u / (1.0 - (1.0 - u * u).powf(2.5)).sqrt()
        }
    };
    let n = 20_000;
    let h = 1.0 / n as f64;
    let mut sum = f(0.0) + f(1.0);
    for i in 1..n {
        sum += f(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    sum * h / 3.0
}

#[test]
fn hertz_impact_matches_duration_and_maximum_overlap() {
    let speed = 0.5;
    let (young, poisson): (f64, f64) = (7e10, 0.3);
    let mass = DENSITY * 4.0 / 3.0 * std::f64::consts::PI * RADIUS.powi(3);
    let (m_star, r_star) = (0.5 * mass, 0.5 * RADIUS);
    let e_star = young / (2.0 * (1.0 - poisson * poisson));
    let v = 2.0 * speed;
    let delta_max = (15.0 * m_star * v * v / (16.0 * e_star * r_star.sqrt())).powf(0.4);
    let t_contact = 2.0 * delta_max / v * hertz_integral();
    let law = ContactLaw::HertzMindlin(HertzMindlin { damping_ratio: 0.0 });
    let (duration, max, after) = collide(law, speed, t_contact / 2000.0);
    let (err_t, err_d) = (duration / t_contact - 1.0, max / delta_max - 1.0);
    eprintln!(
        "Hertz: t_c = {duration:.6e} s vs {t_contact:.6e} ({err_t:+.2e}); δ_max = {max:.6e} m vs \
         {delta_max:.6e} ({err_d:+.2e}); rebound {after:.6} m/s vs {v}"
    );
    assert!(err_t.abs() < 0.01, "contact duration off by {err_t:e}");
    assert!(err_d.abs() < 0.01, "maximum overlap off by {err_d:e}");
    assert!(
        (after / v - 1.0).abs() < 1e-3,
        "an undamped impact is elastic"
    );
}

#[test]
fn linear_spring_dashpot_restitution_matches_the_damping_ratio() {
    let k = 1e6;
    let mass = DENSITY * 4.0 / 3.0 * std::f64::consts::PI * RADIUS.powi(3);
    let omega = (k / (0.5 * mass)).sqrt();
    for zeta in [0.05, 0.2, 0.5] {
        let law = ContactLaw::Linear(LinearSpring {
            normal_stiffness: k,
            tangential_stiffness: 0.5 * k,
            damping_ratio: zeta,
        });
        let (_, _, after) = collide(law, 0.2, 0.002 / omega);
        let e = after / 0.4;
        let expected = (-zeta * std::f64::consts::PI / (1.0 - zeta * zeta).sqrt()).exp();
        eprintln!("linear ζ = {zeta}: e = {e:.6} vs {expected:.6}");
        assert!(
            (e / expected - 1.0).abs() < 0.01,
            "ζ = {zeta}: e = {e} vs {expected}"
        );
    }
}
