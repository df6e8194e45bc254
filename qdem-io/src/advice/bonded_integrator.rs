//! The integrator of a `[bonded]` body (paper 001's beam-bonded particles): implicit Newmark
//! (β = ¼, γ = ½) where its accurate step saves more than an implicit step costs, explicit
//! (β = 0) otherwise.
//!
//! - The body's lowest natural frequency f₁ with its supports: the Lanczos solve of `qdem
//!   modes` ([`qdem_core::modal::lanczos::natural_modes`]) on the stiffness the implicit
//!   stepper assembles (the intact bonds' linear Timoshenko stiffness, Eqs. 4 and 7, and the
//!   touching unbonded contacts' springs) and the particles' lumped masses and inertias.
//! - Newmark's average acceleration lengthens a mode's period by (ω∆t)²/12 (Hughes, *The Finite
//!   Element Method*, §9.3; exactly ω∆t/(2 atan(ω∆t/2)) − 1, which the scene's own step is
//!   told by), so ∆t = √(12 × 0.001)/ω₁ keeps the first mode within 0.1%. The
//!   explicit step is the paper's, [`EXPLICIT_FRACTION`] × Eq. 28's ∆t_crit (or the rigorous
//!   stable bound where that is shorter). Implicit is advised where its steps are fewer than
//!   the explicit ones by more than an implicit step costs ([`IMPLICIT_BBM_STEP_COST`]):
//!   predicted speed-up (explicit steps)/(implicit steps × cost). A short, deep body of few
//!   particles, whose first mode is near the lattice's highest, stays explicit.
//! - The top load's ramp excites the first mode to the dynamic share d
//!   ([`super::excitation::of_ramp`]), undamped, on the safe side: the bonds' dashpots (Eq. 8)
//!   are set by a ratio ξ_b of a bond's own frequency, not of f₁'s. d bounds what
//!   the period error can do to a deflection: the ringing on top of the quasi-static response
//!   has amplitude d, and a period error shifts only its phase, so a deflection deviates by at
//!   most 2d however long the step (docs/speed-vs-error.md, the BBM beam).
//! - A free body (`supports = "none"`) gets no advice, in words: its in-plane rotation turns
//!   the particles' spins too, which the modal analysis's rigid motions (translations and
//!   rotations of positions) leave out, so its lowest "elastic" mode would be that rotation.
//! - The figures hold until bonds break. The implicit stepper follows cracking (retakes and
//!   an active set of contacts, docs/bbm.md), at far more than [`IMPLICIT_BBM_STEP_COST`] per
//!   nominal step while a crack runs; the reasoning says so.

use super::integrator::{newmark_step, PERIOD_ERROR};
use super::{excitation, Advice, Topic};
use crate::build::Simulation;
use crate::scene::Supports;
use qdem_core::modal::lanczos::natural_modes;
use std::f64::consts::PI;

/// An implicit BBM step's cost over an explicit one before cracking, measured on the
/// benchmark beam at 0.025 m, one thread: 1.47e-3 s per step of
/// `fixtures/bbm/beam_implicit_0.025.toml` (∆t = 5 ms, the kept factor) against 2.28e-4 s of
/// `beam_explicit_0.025.toml` (∆t = 1.38e-6 s), docs/bbm.md's table (t_b). Instructions say
/// more, 10.9: 3.54e7 against 3.26e6 per step, counted by callgrind on the release build of
/// main ce02c2f as the difference of two run lengths (4 against 8 implicit steps, 726 against
/// 1,451 explicit ones) so that building and factorising cancel; the wall time is what a
/// speed-up is, and the two lie within the speed-up's stated factor of two.
pub const IMPLICIT_BBM_STEP_COST: f64 = 6.4;

/// The explicit step of paper 001's runs over its Eq. 28 ∆t_crit
/// (`fixtures/bbm/beam_explicit_*.toml`: `critical_fraction = 0.2`).
pub const EXPLICIT_FRACTION: f64 = 0.2;

/// Modes asked for: the lowest elastic one of a supported body, with room for the rigid
/// motions its supports might leave.
const MODES: usize = 4;

/// What `sim`'s scene runs now: `explicit` for β = 0, else `implicit`.
fn integrator_now(sim: &Simulation) -> &'static str {
    match sim.scene.run.beta == 0.0 {
        true => "explicit",
        false => "implicit",
    }
}

/// The advice on the integrator of `sim`'s `[bonded]` body; none without one.
pub(super) fn advise(sim: &Simulation) -> Option<Advice> {
    let bonded = sim.scene.bonded.as_ref()?;
    let model = sim.bonded()?;
    let now = integrator_now(sim);
    let subject = format!("bonded body `{}`", bonded.name);
    let modes = match bonded.supports {
        // The in-plane rotation of a free body turns its particles' spins too, which the
        // rigid motions of the modal analysis (translations) leave out.
        Supports::None => Err("it is free (supports = \"none\")".to_string()),
        _ => lowest_frequency(sim),
    };
    let f1 = match modes {
        Ok(f1) => f1,
        Err(why) => {
            return Some(Advice {
                subject,
                topic: Topic::Integrator,
                now: now.to_string(),
                advised: now.to_string(),
                reasoning: format!("no advice: its natural modes are not found ({why})"),
                figures: Vec::new(),
            })
        }
    };
    let omega = 2.0 * PI * f1;
    let implicit_dt = newmark_step(omega);
    let eq28 = EXPLICIT_FRACTION * model.initial_critical_step();
    let explicit_dt = eq28.min(sim.world.settings().stable_dt.0);
    let dynamic = excitation::of_ramp(bonded.load_ramp, (f1, 0.0));
    let ratio = implicit_dt / explicit_dt;
    let advised = match ratio > IMPLICIT_BBM_STEP_COST {
        true => "implicit",
        false => "explicit",
    };
    let t_end = sim.scene.run.t_end;
    let steps = |dt: f64| (t_end / dt).ceil().max(1.0);
    let speed_up = match advised {
        "implicit" => steps(explicit_dt) / (steps(implicit_dt) * IMPLICIT_BBM_STEP_COST),
        _ => 1.0,
    };
    let mut figures = vec![
        ("lowest_frequency_hz".into(), f1),
        ("dynamic_share".into(), dynamic.dynamic_share),
        ("advised_dt".into(), implicit_dt),
        ("explicit_dt".into(), explicit_dt),
        ("predicted_error".into(), PERIOD_ERROR),
        ("predicted_speed_up".into(), speed_up),
    ];
    let scene_dt = sim.world.settings().dt;
    let mut own = String::new();
    if now == "implicit" {
        let error = period_error(omega * scene_dt);
        figures.push(("scene_dt".into(), scene_dt));
        figures.push(("scene_period_error".into(), error));
        own = format!(
            "; the scene's dt = {scene_dt:.3e} s lengthens it by {:.3}%, which moves a \
             deflection by at most 2d = {:.2e} (the ringing's phase, not the quasi-static \
             response)",
            100.0 * error,
            2.0 * dynamic.dynamic_share
        );
    }
    let reasoning = format!(
        "its first mode with its supports is {f1:.4} Hz ({} excites it to d = {:.2e} of the \
         static deflection); implicit newmark (beta = 0.25) keeps that mode's period within \
         {PERIOD_ERROR} at dt = {implicit_dt:.3e} s, {ratio:.1}x the explicit step \
         {explicit_dt:.3e} s ({EXPLICIT_FRACTION} x Eq. 28's critical step), where an implicit \
         step costs about {IMPLICIT_BBM_STEP_COST}x an explicit one{own}; predicted speed-up \
         over explicit {speed_up:.3e}x until bonds break (an implicit step that cracks costs \
         far more: retakes and contact redos)",
        dynamic.source, dynamic.dynamic_share
    );
    Some(Advice {
        subject,
        topic: Topic::Integrator,
        now: now.to_string(),
        advised: advised.to_string(),
        reasoning,
        figures,
    })
}

/// The relative period error of Newmark's average acceleration at ω∆t = `omega_dt`: the
/// trapezoidal rule turns the mode's phase by 2 atan(ω∆t/2) a step instead of ω∆t, so the
/// period grows by ω∆t/(2 atan(ω∆t/2)) − 1, whose leading term is (ω∆t)²/12.
fn period_error(omega_dt: f64) -> f64 {
    omega_dt / (2.0 * (omega_dt / 2.0).atan()) - 1.0
}

/// The lowest elastic natural frequency (Hz) of `sim`'s bonded body with its supports, about
/// its starting state; an error in words where the solve is refused.
fn lowest_frequency(sim: &Simulation) -> Result<f64, String> {
    let world = &sim.world;
    let wanted = MODES.min(world.state.dofs());
    let modes = natural_modes(&world.state, &world.models, wanted).map_err(|e| e.to_string())?;
    modes
        .modes
        .iter()
        .find(|m| !m.rigid)
        .map(|m| m.frequency_hz)
        .ok_or_else(|| format!("its {wanted} lowest modes are all rigid-body motions"))
}
