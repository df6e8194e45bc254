//! Rigid or deformable, per `[[body]]`: the body's lowest natural frequency with its fixes
//! ([`super::body_modes`]) against what excites it ([`super::excitation`]).
//!
//! - A body whose fixes hold every rigid motion (a clamped beam) stays deformable: its
//!   deformation is all the motion it has, a rigid one would not move.
//! - Otherwise a body whose first mode the loads and impacts excite to at most
//!   [`super::NEGLIGIBLE_DYNAMICS`] of its quasi-static deflection can be rigid: the predicted
//!   error is that dynamic share; the step becomes the one the scene built again with the
//!   body rigid sets ([`super::changed_step`]: its contacts then act on its whole mass, not on
//!   its vertex particles), and its tetrahedra leave the step. Its
//!   Kelvin–Voigt damping at that frequency, ζ = π f₁ μ_D/G, goes with it: where ζ exceeds 1%
//!   and the contacts have no damping of their own, the advice says to give them some (the
//!   5 cm bed of docs/ballast.md failed with undamped rigid stones and held with ζ = 0.1).
//! - A body excited to 10% or more stays deformable; between the two the scene's choice
//!   stands, with the predicted error named.

use super::body_modes::BodyModes;
use super::excitation;
use super::{Advice, Topic, NEGLIGIBLE_DYNAMICS};
use crate::build::{BodyInfo, Simulation};

/// The dynamic share from which a body's vibration matters.
const DYNAMIC: f64 = 0.1;

/// The advice for `body` given its modes alone (or why they could not be had).
pub(super) fn advise(
    sim: &Simulation,
    body: &BodyInfo,
    modes: &Result<BodyModes, String>,
) -> Advice {
    let i = sim
        .scene
        .bodies
        .iter()
        .position(|b| b.name == body.name)
        .expect("a scene body");
    let scene_body = &sim.scene.bodies[i];
    let now = if scene_body.rigid {
        "rigid"
    } else {
        "deformable"
    };
    let mut advice = Advice {
        subject: format!("body `{}`", body.name),
        topic: Topic::Rigidity,
        now: now.to_string(),
        advised: now.to_string(),
        reasoning: String::new(),
        figures: Vec::new(),
    };
    let m = match modes {
        Ok(m) => m,
        Err(why) => {
            advice.reasoning = format!("no advice: the body alone has no modal solution ({why})");
            return advice;
        }
    };
    let material = &sim.scene.materials[sim.scene.refs().body_materials[i]];
    let mass = sim.body_mass(body);
    let exc = excitation::of_body(
        &sim.scene,
        scene_body,
        material,
        mass,
        (m.lowest_hz, m.damping_ratio),
    );
    let d = exc.dynamic_share;
    let run_dt = sim.world.settings().stable_dt.0;
    let turned = match m.held {
        true => f64::NAN,
        false => super::changed_step(sim, |scene| scene.bodies[i].rigid = !scene_body.rigid),
    };
    let (deformable_dt, rigid_dt) = match scene_body.rigid {
        true => (turned, run_dt),
        false => (run_dt, turned),
    };
    advice.figures = vec![
        ("lowest_frequency_hz".into(), m.lowest_hz),
        ("dynamic_share".into(), d),
        ("predicted_error".into(), if m.held { f64::NAN } else { d }),
        ("deformable_dt".into(), deformable_dt),
        ("rigid_dt".into(), rigid_dt),
        ("body_dt".into(), m.stable_dt),
        ("tets".into(), m.tets as f64),
        ("kelvin_voigt_damping_ratio".into(), m.damping_ratio),
    ];
    let modes = format!(
        "first mode {:.4} Hz with its fixes; {} excites it to {d:.2e} of its quasi-static \
         deflection",
        m.lowest_hz, exc.source
    );
    (advice.advised, advice.reasoning) = if m.held {
        let why = "its fixes hold every rigid motion, so its deformation is all the motion it \
                   has (rigid, it would not move)";
        ("deformable".into(), format!("{why}; {modes}"))
    } else if d <= NEGLIGIBLE_DYNAMICS {
        let steps = match (rigid_dt.is_nan(), rigid_dt.is_finite()) {
            (true, _) => "the scene with it rigid does not build".to_string(),
            (false, true) => format!("the run would step at {rigid_dt:.3e} s"),
            (false, false) => "the run would have no step bound".to_string(),
        };
        let mut text = format!(
            "{modes} (at most {NEGLIGIBLE_DYNAMICS}): rigid, it misses that much; {steps} \
             instead of {deformable_dt:.3e} s, without its {} tetrahedra",
            m.tets
        );
        text += &damping_note(sim, m.damping_ratio);
        ("rigid".into(), text)
    } else if d >= DYNAMIC {
        (
            "deformable".into(),
            format!("{modes} (at least {DYNAMIC}): its vibration matters"),
        )
    } else {
        let text =
            format!("{modes}: either kind; rigid, it would miss about {d:.2e} of its response");
        (now.to_string(), text)
    };
    advice
}

/// What a body loses with its Kelvin–Voigt damping ratio `zeta` when made rigid, if it
/// matters and the contacts do not damp.
fn damping_note(sim: &Simulation, zeta: f64) -> String {
    let damped = sim
        .scene
        .contact
        .as_ref()
        .is_some_and(|c| c.damping_ratio > 0.0 || c.restitution.is_some());
    if zeta <= 0.01 || damped {
        return String::new();
    }
    format!(
        "; it would lose its Kelvin-Voigt damping (zeta = {zeta:.3} at its first mode): give \
         [contact] a damping_ratio or restitution in its place"
    )
}
