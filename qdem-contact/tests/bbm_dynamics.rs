//! The bonded beam in time (paper 001 §3): explicit and implicit Newmark agree, the implicit
//! average-acceleration scheme conserves energy, and explicit runs with breaking bonds are
//! bit-identical on 1 and 2 threads.

mod bbm;

use bbm::beam;
use qdem_core::{solvers::Newmark, step::Stepper};

/// Total energy of the undamped beam under its constant load: kinetic + bond energy − load × u.
fn energy(b: &bbm::Beam, q: f64) -> f64 {
    let s = &b.state;
    s.kinetic_energy() + b.models[0].potential_energy(s).unwrap() - b.load_work(q)
}

/// Average acceleration (β = ¼, γ = ½) conserves the energy of a linear undamped system
/// exactly (to round-off), whatever the step: 200 steps of 1 ms (a tenth of the beam's
/// fundamental period) after a suddenly applied load.
#[test]
fn implicit_newmark_conserves_energy_of_the_bonded_beam() {
    let q = 50e3;
    let mut b = beam(0.05, q, f64::INFINITY, 0.0, false);
    let mut stepper = Newmark::average_acceleration(1e-3);
    stepper.initialize(&mut b.state, &mut b.models).unwrap();
    let e0 = energy(&b, q);
    let mut scale = 0.0f64;
    for _ in 0..200 {
        stepper.step(&mut b.state, &mut b.models).unwrap();
        scale = scale.max(b.state.kinetic_energy());
    }
    let drift = (energy(&b, q) - e0).abs() / scale;
    println!("energy drift {drift:.3e} of the largest kinetic energy {scale:.4e} J");
    assert!(drift < 1e-9, "drift {drift}");
}

/// Explicit central difference at the rigorous bound's 0.9 and implicit average acceleration
/// at 1e-4 s (ω∆t ≈ 0.06 for the fundamental mode) give the same midspan deflection history
/// over 20 ms to 0.5% of its peak.
#[test]
fn explicit_and_implicit_newmark_agree_before_cracking() {
    let q = 50e3;
    let mut histories = Vec::new();
    for implicit in [false, true] {
        let mut b = beam(0.05, q, f64::INFINITY, 0.0, false);
        let dt = if implicit {
            1e-4
        } else {
            0.9 * b.models[0].stable_dt(&b.state).unwrap()
        };
        let mut stepper = if implicit {
            Newmark::average_acceleration(dt)
        } else {
            Newmark::central_difference(dt)
        };
        stepper.initialize(&mut b.state, &mut b.models).unwrap();
        let mut samples = Vec::new();
        let mut next = 0.0;
        while b.state.time < 0.02 - 1e-12 {
            stepper.step(&mut b.state, &mut b.models).unwrap();
            if b.state.time >= next - 1e-12 {
                samples.push(b.midspan_deflection());
                next += 1e-3;
            }
        }
        histories.push(samples);
    }
    let peak = histories[1].iter().fold(0.0f64, |m, w| m.max(w.abs()));
    let worst = histories[0]
        .iter()
        .zip(&histories[1])
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    println!("peak {peak:.4e} m, largest difference {worst:.3e} m");
    assert!(histories[0].len() >= 19 && histories[0].len() == histories[1].len());
    assert!(worst < 5e-3 * peak, "{worst} vs peak {peak}");
}

/// An explicit run in which bonds break (a load above the cracking load) is bit-identical on
/// 1 and 2 threads, and breaks bonds.
#[test]
fn explicit_cracking_is_identical_on_1_and_2_threads() {
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut b = beam(0.05, 600e3, 6e6, 0.05e6, false);
            let dt = 0.5 * b.models[0].stable_dt(&b.state).unwrap();
            let mut stepper = Newmark::central_difference(dt).with_adaptive(true);
            stepper.initialize(&mut b.state, &mut b.models).unwrap();
            for _ in 0..3000 {
                stepper.step(&mut b.state, &mut b.models).unwrap();
            }
            (
                b.state.position.clone(),
                b.bonds().broken(),
                stepper.counts(),
            )
        })
    };
    let (one, two) = (run(1), run(2));
    println!("broken {}, counts {:?}", one.1, one.2);
    assert!(one.1 > 0, "no bond broke");
    assert_eq!(one.1, two.1);
    assert!(one.0 == two.0, "positions differ between 1 and 2 threads");
}
