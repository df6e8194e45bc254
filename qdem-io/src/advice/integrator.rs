//! The integrator of a contact-free scene of deformable bodies: implicit where the scene is
//! quasi-static, with the step it would allow.
//!
//! The loads' and impacts' dynamic share of each body's first mode ([`super::excitation`])
//! tells whether inertia matters:
//! - at most [`super::NEGLIGIBLE_DYNAMICS`] on every body: quasi-static. Elastic bodies need
//!   only `static` (one solve per load level); viscous ones creep, and `newmark` follows the
//!   creep at ∆t = τ/20, τ = μ_D/G the slowest shear relaxation time (the trapezoidal rule's
//!   error on e^(−t/τ) is (∆t/τ)²/12 per unit time, 2e-4 there), or at the loads'
//!   resolution (their shortest segment over 20), whichever is shorter;
//! - otherwise dynamic: `newmark` (β = ¼, γ = ½) lengthens the period of a mode by
//!   (ω∆t)²/12, so ∆t = √(12 × 0.001)/ω₁ keeps the first mode within 0.1% (the cantilever's
//!   measured 0.270% at ω₁∆t = 0.18 against 0.271% predicted, docs/speed-vs-error.md); it is
//!   advised where its steps are fewer than the explicit ones by more than an implicit step
//!   costs ([`IMPLICIT_STEP_COST`]).
//!
//! A scene with contacts stays explicit: the implicit steppers do not take them. A `[bonded]`
//! body's integrator is advised by [`super::bonded_integrator`].

use super::body_modes::BodyModes;
use super::{excitation, Advice, Topic, NEGLIGIBLE_DYNAMICS};
use crate::build::Simulation;
use crate::scene::Integrator;

/// An implicit Newmark step's cost over an explicit one, measured on the 5,681-tet cantilever
/// (docs/speed-vs-error.md: 4.3 s for 3,000 Newmark steps, 422.2 s for 1,809,869 Verlet).
pub const IMPLICIT_STEP_COST: f64 = 6.2;

/// Relative period error of the first mode the dynamic step is chosen for.
pub(super) const PERIOD_ERROR: f64 = 1e-3;

/// The Newmark (β = ¼, γ = ½) step that lengthens the period of a mode of angular frequency
/// `omega` by [`PERIOD_ERROR`]: (ω∆t)²/12 = PERIOD_ERROR.
pub(super) fn newmark_step(omega: f64) -> f64 {
    (12.0 * PERIOD_ERROR).sqrt() / omega
}

/// Steps per relaxation time or load segment of a quasi-static implicit run.
const RESOLUTION: f64 = 20.0;

/// The advice for `sim`'s run, given the deformable bodies' modes alone (`lowest`); none for
/// a scene with contacts, a bonded body (advised apart) or no deformable `[[body]]`.
pub(super) fn advise(sim: &Simulation, lowest: &[(String, BodyModes)]) -> Option<Advice> {
    let scene = &sim.scene;
    if sim.contacts().is_some() || scene.bonded.is_some() || scene.granular.is_some() {
        return None;
    }
    let mut dynamic: f64 = 0.0;
    let (mut f1, mut tau, mut explicit_dt) = (f64::INFINITY, 0.0f64, f64::INFINITY);
    for (i, body) in scene.bodies.iter().enumerate().filter(|(_, b)| !b.rigid) {
        let Some((_, m)) = lowest.iter().find(|(n, _)| *n == body.name) else {
            continue;
        };
        let material = &scene.materials[scene.refs().body_materials[i]];
        let info = sim.bodies.iter().find(|b| b.name == body.name)?;
        let exc = excitation::of_body(
            scene,
            body,
            material,
            sim.body_mass(info),
            (m.lowest_hz, m.damping_ratio),
        );
        dynamic = dynamic.max(exc.dynamic_share);
        f1 = f1.min(m.lowest_hz);
        explicit_dt = explicit_dt.min(m.stable_dt);
        let shear = material.young / (2.0 * (1.0 + material.poisson));
        tau = tau.max(material.shear_viscosity / shear);
    }
    if !f1.is_finite() {
        return None;
    }
    let t_end = scene.run.t_end;
    let load_dt = excitation::shortest_load_segment(&sim.scene) / RESOLUTION;
    let now = match scene.run.integrator {
        Integrator::Verlet => "verlet",
        Integrator::Newmark => "newmark",
        Integrator::Static => "static",
    };
    let omega = 2.0 * std::f64::consts::PI * f1;
    let (advised, dt, predicted, why) = if dynamic <= NEGLIGIBLE_DYNAMICS {
        if tau > 0.0 {
            let dt = (tau / RESOLUTION).min(load_dt);
            let error = (dt / tau).powi(2) / 12.0;
            let why = format!(
                "quasi-static (its loads excite the first mode, {f1:.4} Hz, to at most \
                 {dynamic:.2e} of the static deflection) and viscous (shear relaxation time \
                 {tau:.3e} s): newmark follows the creep at dt = {dt:.3e} s"
            );
            ("newmark", dt, error, why)
        } else {
            let why = format!(
                "quasi-static (its loads excite the first mode, {f1:.4} Hz, to at most \
                 {dynamic:.2e} of the static deflection) and elastic: a static solve per load \
                 level gives the response without inertia"
            );
            ("static", load_dt.min(t_end), dynamic, why)
        }
    } else {
        let dt = newmark_step(omega);
        let gain = dt / explicit_dt / IMPLICIT_STEP_COST;
        let advised = if gain > 1.0 { "newmark" } else { "verlet" };
        let why = format!(
            "dynamic (its loads excite the first mode, {f1:.4} Hz, to {dynamic:.2e} of the \
             static deflection): newmark keeps that mode's period within {PERIOD_ERROR} at dt = \
             {dt:.3e} s, {:.1}x the explicit step {explicit_dt:.3e} s, where an implicit step \
             costs about {IMPLICIT_STEP_COST}x an explicit one",
            dt / explicit_dt
        );
        (advised, dt, PERIOD_ERROR, why)
    };
    let steps = |dt: f64| (t_end / dt).ceil().max(1.0);
    let speed_up = match advised {
        "verlet" => 1.0,
        _ => steps(explicit_dt) / (steps(dt) * IMPLICIT_STEP_COST),
    };
    Some(Advice {
        subject: "run".to_string(),
        topic: Topic::Integrator,
        now: now.to_string(),
        advised: advised.to_string(),
        reasoning: format!("{why}; predicted speed-up over verlet {speed_up:.3e}x"),
        figures: vec![
            ("lowest_frequency_hz".into(), f1),
            ("dynamic_share".into(), dynamic),
            ("advised_dt".into(), dt),
            ("explicit_dt".into(), explicit_dt),
            ("predicted_error".into(), predicted),
            ("predicted_speed_up".into(), speed_up),
        ],
    })
}
