//! Warnings for inputs that are valid but almost certainly not meant, each naming the value,
//! what it leads to and the likely intent (`qdem check` and `qdem run` print them before the
//! run): a fixed time step far below the stable bound (a run of absurdly many steps), or above
//! the contacts' estimate (accepted, not shown stable), a probe
//! far from every particle (a point in the wrong units or frame), a Young's modulus whose
//! wave speed √(E/ρ) is below that of any solid (a modulus in the wrong unit). A cyclic load
//! with `min` above `max` is refused at validation instead (`scene/validate/fix_load.rs`).

use super::Simulation;
use crate::scene::TimeStep;
use qdem_core::step::stepper::unstable_step;
use qdem_core::Vec3;

/// A fixed `dt` below this fraction of the explicit stable bound is warned of.
pub const TINY_STEP_FRACTION: f64 = 1e-3;

/// A probe farther than this fraction of the scene's extent (the diagonal of the box around
/// its particles) from its particle is warned of.
pub const FAR_PROBE_FRACTION: f64 = 0.1;

/// A material whose wave speed √(E/ρ) is below this (m/s) is warned of: soft gels have about
/// 1 m/s, rubbers tens, rocks and metals thousands.
pub const SLOWEST_WAVE: f64 = 1.0;

/// The warnings for `sim`, one line each, naming the scene file.
pub(crate) fn warnings(sim: &Simulation) -> Vec<String> {
    let mut out = Vec::new();
    out.extend(tiny_step(sim));
    out.extend(above_estimate(sim));
    out.extend(far_probes(sim));
    out.extend(soft_materials(sim));
    let file = sim.scene.path.display();
    out.into_iter().map(|w| format!("{file}: {w}")).collect()
}

/// A fixed explicit step far below the stable bound: the step count and the likely intent
/// (an implicit or static step has no such bound to compare with).
fn tiny_step(sim: &Simulation) -> Option<String> {
    let TimeStep::Fixed(dt) = sim.scene.run.dt else {
        return None;
    };
    let settings = sim.world.settings();
    let (bound, limiter) = &settings.stable_dt;
    let explicit = !settings.is_implicit();
    if !(explicit && bound.is_finite() && dt < TINY_STEP_FRACTION * bound) {
        return None;
    }
    Some(format!(
        "[run] dt = {dt:e} s is {:.1e} of the stable step {bound:.3e} s (set by `{limiter}`): \
         the run takes {:.2e} steps to reach t_end = {} s; did you mean dt = \"auto\" (or a \
         step near {:.1e} s)?",
        dt / bound,
        sim.scene.run.t_end / dt,
        sim.scene.run.t_end,
        bound * sim.scene.run.dt_safety
    ))
}

/// A fixed explicit step above the estimate of the contacts present, accepted because no
/// contact alone is unstable at it (a requested step above a rigorous bound is refused
/// before): what the run does if the contacts come to need a shorter one.
fn above_estimate(sim: &Simulation) -> Option<String> {
    let TimeStep::Fixed(dt) = sim.scene.run.dt else {
        return None;
    };
    let settings = sim.world.settings();
    let (bound, limiter) = &settings.stable_dt;
    if settings.is_implicit() || dt <= *bound {
        return None;
    }
    let alone = unstable_step(&sim.world.state, &sim.world.models)
        .map_or(String::new(), |(u, _)| {
            format!(" (one of them alone is unstable above {u:.3e} s)")
        });
    Some(format!(
        "[run] dt = {dt:e} s is above the step {bound:.3e} s `{limiter}` estimates from the \
         contacts present{alone}: accepted, but not shown stable; the run stops, naming the \
         contact and the step it needs, if at a rebuild of the contact lists a contact needs a \
         shorter step than dt; dt = \"auto\" takes {:.3e} s",
        bound * sim.scene.run.dt_safety
    ))
}

/// Probes whose nearest particle is far from the point asked for, compared with the scene.
fn far_probes(sim: &Simulation) -> Vec<String> {
    let positions = &sim.world.state.reference;
    let Some(first) = positions.first() else {
        return Vec::new();
    };
    let (lo, hi) = positions
        .iter()
        .fold((*first, *first), |(lo, hi), p| (lo.inf(p), hi.sup(p)));
    let extent = (hi - lo).norm();
    sim.probes
        .iter()
        .filter(|p| p.distance > FAR_PROBE_FRACTION * extent)
        .map(|p| {
            let at: Vec3 = positions[p.particle];
            format!(
                "[[probe]] {:?}: the particle nearest its point is {:.3} m away, at ({:.4}, \
                 {:.4}, {:.4}), in a scene {extent:.3} m across; is the point in metres and in \
                 the frame of the placed bodies (after translate)?",
                p.name, p.distance, at.x, at.y, at.z
            )
        })
        .collect()
}

/// Materials whose Young's modulus is absurdly low for their density.
fn soft_materials(sim: &Simulation) -> Vec<String> {
    sim.scene
        .materials
        .iter()
        .filter_map(|m| {
            let speed = (m.young / m.density).sqrt();
            (speed < SLOWEST_WAVE).then(|| {
                format!(
                    "[[material]] {:?}: young = {:e} Pa with density = {:e} kg/m^3 has a wave \
                     speed sqrt(young / density) = {speed:.2e} m/s, slower than any solid's \
                     (a soft gel's is about 1 m/s); young is in pascals: did you mean \
                     {:e} Pa (GPa) or {:e} Pa (MPa)?",
                    m.name,
                    m.young,
                    m.density,
                    m.young * 1e9,
                    m.young * 1e6
                )
            })
        })
        .collect()
}
